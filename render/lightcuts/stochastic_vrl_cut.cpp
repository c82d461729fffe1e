#include "render/lightcuts/stochastic_vrl_cut.h"

#include "render/lightcuts/stochastic_cut.h"

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
        [&](int32_t node) { return importance_.segment(node, segment); },
        [&](int32_t leaf, Rng& r) { return estimator_.contribution(tree_.vrls()[size_t(leaf)], segment, r); });
}

Rgb StochasticLightcutsEstimator::estimate(const CameraPathSurface& x, Rng& rng, CutStatistics& statistics) const {
    if (tree_.empty()) return Rgb(0.0f);
    return stochasticCutEstimate(
        tree_, settings_.stochasticCutSize, rng, statistics,
        [&](int32_t node) { return importance_.surface(node, x); },
        [&](int32_t leaf, Rng& r) { return surfaceEstimator_.contribution(tree_.vrls()[size_t(leaf)], x, r); });
}

}  // namespace vrl
