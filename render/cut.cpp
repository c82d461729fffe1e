#include "render/cut.h"

#include "render/scene.h"

#include <limits>
#include <queue>
#include <vector>

namespace vrl {

LightcutsEstimator::LightcutsEstimator(const Scene& scene, const LightTree& tree, const VrlEstimator& estimator,
                                       CutSettings settings)
    : tree_(tree), estimator_(estimator), settings_(settings), bound_(scene, tree, settings.bound) {}

Rgb LightcutsEstimator::estimate(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics) const {
    if (tree_.empty() || !(segment.length > 0.0f)) return Rgb(0.0f);
    struct CutNode {
        float bound;  // luminance of the node's bound
        int32_t node;
        Rgb estimate;
        bool operator<(const CutNode& o) const { return bound != o.bound ? bound < o.bound : node > o.node; }
    };
    std::priority_queue<CutNode> heap;
    Rgb total(0.0f);
    uint32_t leavesInCut = 0;
    const auto& nodes = tree_.nodes();
    std::vector<int32_t> pending;  // nodes to add to the cut (children of refined nodes)

    const auto addToCut = [&](int32_t index) {
        pending.push_back(index);
        while (!pending.empty()) {
            const int32_t i = pending.back();
            pending.pop_back();
            const LightTreeNode& node = nodes[i];
            if (node.isLeaf()) {
                Rng rng = vrlStream(streamKey, node.representative);
                total += estimator_.contribution(tree_.vrls()[node.representative], segment, rng);
                ++statistics.evaluated;
                ++leavesInCut;
                continue;
            }
            bool crosses = false;
            const Rgb b = bound_.bound(i, segment, &crosses);
            if (crosses) {  // infinite bound: refine without estimating
                ++statistics.intersected;
                pending.push_back(node.left);
                pending.push_back(node.right);
                continue;
            }
            Vrl representative = tree_.vrls()[node.representative];
            representative.flux = node.clusterFlux;
            Rng rng = vrlStream(streamKey, node.representative);
            const Rgb e = estimator_.contribution(representative, segment, rng);
            ++statistics.evaluated;
            ++statistics.boundedEstimates;
            if (e.x > b.x || e.y > b.y || e.z > b.z) ++statistics.boundExceeded;
            total += e;
            const float key = luminance(b);
            heap.push({key >= 0.0f ? key : std::numeric_limits<float>::infinity(), i, e});  // NaN: refine
        }
    };

    addToCut(tree_.root());
    while (!heap.empty()) {
        const CutNode& top = heap.top();
        const float threshold = settings_.errorThreshold * std::max(0.0f, luminance(total));
        if (top.bound <= threshold) break;
        if (heap.size() + leavesInCut >= settings_.maxCutSize) break;
        const CutNode refined = top;
        heap.pop();
        total -= refined.estimate;
        addToCut(nodes[refined.node].left);
        addToCut(nodes[refined.node].right);
    }
    statistics.cutSize += uint32_t(heap.size()) + leavesInCut;
    // Subtracting refined estimates can leave float dust below zero.
    return Rgb(std::max(0.0f, total.x), std::max(0.0f, total.y), std::max(0.0f, total.z));
}

}  // namespace vrl
