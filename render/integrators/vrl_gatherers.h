// Parts (c) and (d) from VRLs without a stochastic choice: every VRL (--method
// vrl) or a Lightcut through the VRL light tree (--method vrl-lightcuts,
// Vibert et al. 2019 §4-5). VRL k draws from vrlStream(streamKey, k) in both,
// so a cut differs from plain shading by its approximation alone.
#pragma once

#include "render/integrators/medium_gatherer.h"
#include "render/integrators/surface_gatherer.h"
#include "render/lightcuts/bounds/direction_cone.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"
#include "render/lightcuts/cuts/surface_lightcuts_estimator.h"
#include "render/lightcuts/tree/leaf_segments.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/vrl.h"
#include "render/vrl/vrl_estimator.h"
#include "render/vrl/vrl_lanes.h"
#include "render/vrl/vrl_surface_estimator.h"

#include <memory>
#include <vector>

namespace vrl {

// (d): every VRL against the segment, evaluated in SIMD lanes (a copy of the VRLs
// as structure of arrays, VrlLanes::kBytesPerVrl each).
class PlainVrlMediumGatherer final : public MediumGatherer {
public:
    PlainVrlMediumGatherer(const Scene& scene, const std::vector<Vrl>& vrls, int vrlSamples);
    Rgb gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;

private:
    VrlEstimator estimator_;
    VrlLanes lanes_;
};

// (c): every VRL k at points.at(k).
class PlainVrlSurfaceGatherer final : public SurfaceGatherer {
public:
    PlainVrlSurfaceGatherer(const Scene& scene, const std::vector<Vrl>& vrls, int vrlSamples);
    Rgb gather(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;
    bool interleaves() const override { return true; }

private:
    VrlSurfaceEstimator estimator_;
    const std::vector<Vrl>& vrls_;
};

// What both VRL cuts' bounds read from the tree: direction cones (built only where
// a medium is anisotropic) and the exact segments of small nodes (LeafSegments).
struct VrlCutBoundData {
    explicit VrlCutBoundData(const Scene& scene, const LightTree& tree);
    std::unique_ptr<DirectionCones> cones;
    LeafSegments leaves;
    // Their bytes per VRL, for memory estimates (cones counted always: the scene is not read there).
    static constexpr size_t kBytesPerVrl = DirectionCones::kBytesPerVrl + LeafSegments::kBytesPerVrl;
};

// (d): a Lightcut through the VRL tree (LightcutsEstimator).
class VrlCutMediumGatherer final : public MediumGatherer {
public:
    VrlCutMediumGatherer(const Scene& scene, const LightTree& tree, int vrlSamples, const CutSettings& cut,
                         std::shared_ptr<const VrlCutBoundData> bounds);
    Rgb gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;

private:
    std::shared_ptr<const VrlCutBoundData> bounds_;
    VrlEstimator estimator_;
    LightcutsEstimator cut_;
};

// (c): a Lightcut through the same tree (SurfaceLightcutsEstimator), bounded at every point present.
class VrlCutSurfaceGatherer final : public SurfaceGatherer {
public:
    VrlCutSurfaceGatherer(const Scene& scene, const LightTree& tree, int vrlSamples, const CutSettings& cut,
                          std::shared_ptr<const VrlCutBoundData> bounds);
    Rgb gather(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
               float otherLuminance) const override;
    bool interleaves() const override { return true; }

private:
    std::shared_ptr<const VrlCutBoundData> bounds_;
    VrlSurfaceEstimator estimator_;
    SurfaceLightcutsEstimator cut_;
};

}  // namespace vrl
