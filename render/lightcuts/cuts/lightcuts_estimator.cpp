#include "render/lightcuts/cuts/lightcuts_estimator.h"

#include "render/lightcuts/cuts/cut_walk.h"
#include "render/scene/scene.h"

#include <algorithm>

namespace vrl {

LightcutsEstimator::LightcutsEstimator(const Scene& scene, const LightTree& tree, const VrlEstimator& estimator,
                                       CutSettings settings, const DirectionCones* cones, const LeafSegments* leaves)
    : tree_(tree), estimator_(estimator), settings_(settings), bound_(scene, tree, settings.bound, cones, leaves) {}

Rgb LightcutsEstimator::estimate(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                                 float otherLuminance) const {
    if (tree_.empty() || !(segment.length > 0.0f)) return Rgb(0.0f);
    struct Visitor {
        const LightcutsEstimator& self;
        const CameraSegment& segment;
        uint64_t streamKey;
        Rgb leaf(int32_t i) const {
            const uint32_t k = self.tree_.nodes()[i].representative;
            Rng rng = vrlStream(streamKey, k);
            return self.estimator_.contribution(self.tree_.vrls()[k], segment, rng);
        }
        bool bound(int32_t i, Rgb& b) const {
            bool crosses = false;
            b = self.bound_.bound(i, segment, &crosses);
            return !crosses;
        }
        Rgb estimate(int32_t i) const {
            const LightTreeNode& node = self.tree_.nodes()[i];
            Vrl representative = self.tree_.vrls()[node.representative];
            representative.flux = node.clusterFlux;
            Rng rng = vrlStream(streamKey, node.representative);
            return self.estimator_.contribution(representative, segment, rng);
        }
        // leaf() and estimate() of several nodes in the kernel's lanes.
        void evaluate(const int32_t* ids, Rgb* out, size_t count) const {
            VrlEstimator::Query queries[kKernelPadding];
            for (size_t first = 0; first < count; first += kKernelPadding) {
                const size_t n = std::min(kKernelPadding, count - first);
                for (size_t j = 0; j < n; ++j) {
                    const LightTreeNode& node = self.tree_.nodes()[ids[first + j]];
                    const Vrl& vrl = self.tree_.vrls()[node.representative];
                    queries[j] = {&vrl, node.isLeaf() ? vrl.flux : node.clusterFlux, node.representative};
                }
                self.estimator_.contributions(queries, n, segment, streamKey, out + first);
            }
        }
    };
    return walkCut(tree_, settings_, statistics, Visitor{*this, segment, streamKey}, otherLuminance);
}

}  // namespace vrl
