#include "render/integrators/vrl_gatherers.h"

#include "render/scene/scene.h"

namespace vrl {

PlainVrlMediumGatherer::PlainVrlMediumGatherer(const Scene& scene, const std::vector<Vrl>& vrls, int vrlSamples)
    : estimator_(scene, vrlSamples), lanes_(vrls, scene) {}

Rgb PlainVrlMediumGatherer::gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics&, float) const {
    return estimator_.sumOverVrls(lanes_, segment, streamKey);
}

PlainVrlSurfaceGatherer::PlainVrlSurfaceGatherer(const Scene& scene, const std::vector<Vrl>& vrls, int vrlSamples)
    : estimator_(scene, vrlSamples), vrls_(vrls) {}

Rgb PlainVrlSurfaceGatherer::gather(const InterleavedPoints& points, uint64_t streamKey, CutStatistics&, float) const {
    Rgb sum(0.0f);
    for (uint32_t k = 0; k < vrls_.size(); ++k) {
        const CameraPathSurface* x = points.at(k);
        if (!x) continue;
        Rng vrlRng = vrlStream(streamKey, k);
        sum += estimator_.contribution(vrls_[k], *x, vrlRng);
    }
    return sum;
}

VrlCutBoundData::VrlCutBoundData(const Scene& scene, const LightTree& tree)
    : cones(DirectionCones::neededFor(scene.media()) ? std::make_unique<DirectionCones>(tree) : nullptr),
      leaves(tree) {}

VrlCutMediumGatherer::VrlCutMediumGatherer(const Scene& scene, const LightTree& tree, int vrlSamples,
                                           const CutSettings& cut, std::shared_ptr<const VrlCutBoundData> bounds)
    : bounds_(std::move(bounds)),
      estimator_(scene, vrlSamples),
      cut_(scene, tree, estimator_, cut, bounds_->cones.get(), &bounds_->leaves) {}

Rgb VrlCutMediumGatherer::gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                                 float otherLuminance) const {
    return cut_.estimate(segment, streamKey, statistics, otherLuminance);
}

VrlCutSurfaceGatherer::VrlCutSurfaceGatherer(const Scene& scene, const LightTree& tree, int vrlSamples,
                                             const CutSettings& cut, std::shared_ptr<const VrlCutBoundData> bounds)
    : bounds_(std::move(bounds)),
      estimator_(scene, vrlSamples),
      cut_(scene, tree, estimator_, cut, bounds_->cones.get(), &bounds_->leaves) {}

Rgb VrlCutSurfaceGatherer::gather(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                                  float otherLuminance) const {
    return cut_.estimate(points, streamKey, statistics, otherLuminance);
}

}  // namespace vrl
