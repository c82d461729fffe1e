// The Lightcuts refinement shared by VRL and VPL cuts (Walter et al. 2005):
// start at the root, estimate every node of the cut, and replace the node with
// the largest bound by its children while that bound exceeds
// errorThreshold x (luminance of the running total) and the cut is below
// maxCutSize. A node the query passes through (infinite bound) is refined
// without being estimated; leaves are estimated exactly. The caller supplies
// what differs, through a visitor:
//   Rgb  leaf(int32_t node)                       exact estimate of a leaf
//   bool bound(int32_t node, Rgb& bound)          false: the query crosses the node
//   Rgb  estimate(int32_t node)                   the node's representative estimate
#pragma once

#include "render/core/rgb.h"
#include "render/lightcuts/cut_settings.h"
#include "render/lightcuts/light_tree.h"

#include <algorithm>
#include <limits>
#include <queue>
#include <vector>

namespace vrl {

// `otherLuminance`: the luminance of what the pixel receives besides this cut
// (0: the cut's own total is the reference, as in the paper's part (d)); the
// threshold then applies to the pixel's total, as Lightcuts' relative error
// does (Walter et al. 2005: a fraction of the pixel's value).
template <class Visitor>
Rgb walkCut(const LightTree& tree, const CutSettings& settings, CutStatistics& statistics, Visitor&& visitor,
            float otherLuminance = 0.0f) {
    struct CutNode {
        float bound;  // luminance of the node's bound
        int32_t node;
        Rgb estimate;
        bool operator<(const CutNode& o) const { return bound != o.bound ? bound < o.bound : node > o.node; }
    };
    std::priority_queue<CutNode> heap;
    Rgb total(0.0f);
    uint32_t leavesInCut = 0;
    const auto& nodes = tree.nodes();
    std::vector<int32_t> pending;  // nodes to add to the cut (children of refined nodes)
    const auto addToCut = [&](int32_t first) {
        pending.push_back(first);
        while (!pending.empty()) {
            const int32_t i = pending.back();
            pending.pop_back();
            const LightTreeNode& node = nodes[i];
            if (node.isLeaf()) {
                total += visitor.leaf(i);
                ++statistics.evaluated;
                ++leavesInCut;
                continue;
            }
            Rgb b;
            if (!visitor.bound(i, b)) {  // infinite bound: refine without estimating
                ++statistics.intersected;
                pending.push_back(node.left);
                pending.push_back(node.right);
                continue;
            }
            const Rgb e = visitor.estimate(i);
            ++statistics.evaluated;
            ++statistics.boundedEstimates;
            if (e.x > b.x || e.y > b.y || e.z > b.z) ++statistics.boundExceeded;
            total += e;
            const float key = luminance(b);
            heap.push({key >= 0.0f ? key : std::numeric_limits<float>::infinity(), i, e});  // NaN: refine
        }
    };
    addToCut(tree.root());
    while (!heap.empty()) {
        const CutNode& top = heap.top();
        if (top.bound <= settings.errorThreshold * (std::max(0.0f, luminance(total)) + otherLuminance)) break;
        if (heap.size() + leavesInCut >= settings.maxCutSize) break;
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
