// Parts (c) and (d) by stochastic VRL Lightcuts (--method vrl-stochastic,
// stochastic_lightcuts_estimator.h): per camera sample, a cut of
// cut.stochasticCutSize nodes through the VRL tree chosen by importance, one VRL
// drawn under each node; unbiased against plain VRLs over the same set. Both
// parts share one estimator (its node importances, VrlImportance).
#pragma once

#include "render/integrators/medium_gatherer.h"
#include "render/integrators/surface_gatherer.h"
#include "render/lightcuts/cuts/stochastic_lightcuts_estimator.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/vrl_estimator.h"
#include "render/vrl/vrl_surface_estimator.h"

#include <memory>

namespace vrl {

// The one-VRL estimators and the stochastic cut over them, shared by (c) and (d).
struct StochasticVrlCuts {
    StochasticVrlCuts(const Scene& scene, const LightTree& tree, int vrlSamples, const CutSettings& cut);
    VrlEstimator estimator;
    VrlSurfaceEstimator surfaceEstimator;
    StochasticLightcutsEstimator cuts;
};

// (d): the stochastic cut's estimate along the segment, its draws from vrlStream(streamKey, ~0u).
class StochasticVrlMediumGatherer final : public MediumGatherer {
public:
    explicit StochasticVrlMediumGatherer(std::shared_ptr<const StochasticVrlCuts> cuts) : cuts_(std::move(cuts)) {}
    Rgb gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;

private:
    std::shared_ptr<const StochasticVrlCuts> cuts_;
};

// (c): the stochastic cut's estimate at the one point of `points` (per camera
// sample, at the sample's own surface point: no interleaving).
class StochasticVrlSurfaceGatherer final : public SurfaceGatherer {
public:
    explicit StochasticVrlSurfaceGatherer(std::shared_ptr<const StochasticVrlCuts> cuts) : cuts_(std::move(cuts)) {}
    Rgb gather(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;
    bool interleaves() const override { return false; }

private:
    std::shared_ptr<const StochasticVrlCuts> cuts_;
};

}  // namespace vrl
