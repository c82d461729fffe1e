#include "render/lightcuts/cuts/stochastic_lightcuts_estimator.h"

#include "render/lightcuts/cuts/stochastic_cut.h"

namespace vrl {

StochasticLightcutsEstimator::StochasticLightcutsEstimator(const Scene& scene, const LightTree& tree,
                                                           const VrlEstimator& estimator,
                                                           const VrlSurfaceEstimator& surfaceEstimator,
                                                           CutSettings settings)
    : tree_(tree), estimator_(estimator), surfaceEstimator_(surfaceEstimator), settings_(settings),
      importance_(scene, tree) {}

Rgb StochasticLightcutsEstimator::estimate(const CameraSegment& segment, Rng& rng, CutStatistics& statistics) const {
    if (tree_.empty() || !(segment.length > 0.0f)) return Rgb(0.0f);
    return stochasticCutEstimate(
        tree_, settings_.stochasticCutSize, rng, statistics,
        [&, query = importance_.prepare(segment)](int32_t node) { return importance_.children(node, query); },
        [&](const int32_t* leaves, size_t count, Rng& r, Rgb* out) {
            estimator_.contributions(tree_.vrls().data(), leaves, count, segment, r, out);
        });
}

Rgb StochasticLightcutsEstimator::estimate(const CameraPathSurface& x, Rng& rng, CutStatistics& statistics) const {
    if (tree_.empty()) return Rgb(0.0f);
    return stochasticCutEstimate(
        tree_, settings_.stochasticCutSize, rng, statistics,
        [&, query = importance_.prepare(x)](int32_t node) { return importance_.children(node, query); },
        [&](const int32_t* leaves, size_t count, Rng& r, Rgb* out) {
            for (size_t k = 0; k < count; ++k) out[k] = surfaceEstimator_.contribution(tree_.vrls()[size_t(leaves[k])], x, r);
        });
}

}  // namespace vrl
