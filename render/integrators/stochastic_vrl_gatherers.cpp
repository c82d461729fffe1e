#include "render/integrators/stochastic_vrl_gatherers.h"

#include <stdexcept>

namespace vrl {

StochasticVrlCuts::StochasticVrlCuts(const Scene& scene, const LightTree& tree, int vrlSamples, const CutSettings& cut)
    : estimator(scene, vrlSamples), surfaceEstimator(scene, vrlSamples),
      cuts(scene, tree, estimator, surfaceEstimator, cut) {}

Rgb StochasticVrlMediumGatherer::gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                                        float) const {
    Rng rng = vrlStream(streamKey, ~0u);
    return cuts_->cuts.estimate(segment, rng, statistics);
}

Rgb StochasticVrlSurfaceGatherer::gather(const InterleavedPoints& points, uint64_t streamKey,
                                         CutStatistics& statistics, float) const {
    if (points.count != 1) throw std::logic_error("StochasticVrlSurfaceGatherer: one point per camera sample");
    if (!points.points[0]) return Rgb(0.0f);
    Rng rng = vrlStream(streamKey, ~0u);
    return cuts_->cuts.estimate(*points.points[0], rng, statistics);
}

}  // namespace vrl
