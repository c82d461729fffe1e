// Stochastic VRL Lightcuts (--method vrl-stochastic): parts (c) and (d) from a
// stochastic cut through the VRL light tree (stochastic_cut.h), the node
// importance of VrlImportance. Per camera segment (d) or surface point (c),
// a cut of at most cutSize nodes is chosen by importance and one VRL is drawn
// under each cut node; its one-sample estimate (VrlEstimator,
// VrlSurfaceEstimator, which draw their sample points from the same stream)
// is divided by its path probability. The result is an unbiased estimate of
// plain VRL shading over the same VRL set, with cutSize VRL estimates instead
// of N; the noise falls as samples per pixel grow (each sample draws a new cut
// descent).
#pragma once

#include "render/core/rng.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/cuts/vrl_importance.h"
#include "render/vrl/vrl_estimator.h"
#include "render/vrl/vrl_surface_estimator.h"

namespace vrl {

class StochasticLightcutsEstimator {
public:
    StochasticLightcutsEstimator(const Scene& scene, const LightTree& tree, const VrlEstimator& estimator,
                                 const VrlSurfaceEstimator& surfaceEstimator, CutSettings settings);

    // Part (d) along `segment` (already multiplied by its throughputBefore).
    Rgb estimate(const CameraSegment& segment, Rng& rng, CutStatistics& statistics) const;
    // Part (c) at the surface point x.
    Rgb estimate(const CameraPathSurface& x, Rng& rng, CutStatistics& statistics) const;

    const VrlImportance& importance() const { return importance_; }

private:
    const LightTree& tree_;
    const VrlEstimator& estimator_;
    const VrlSurfaceEstimator& surfaceEstimator_;
    CutSettings settings_;
    VrlImportance importance_;
};

}  // namespace vrl
