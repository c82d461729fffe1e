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
#include <vector>

namespace vrl {

// Scratch space of walkCut, one per thread and reused (no allocation per pixel
// once it has grown); a nested walk on the same thread takes a fresh one.
struct CutScratch {
    struct CutNode {
        float bound;  // luminance of the node's bound
        int32_t node;
        Rgb estimate;
        bool operator<(const CutNode& o) const { return bound != o.bound ? bound < o.bound : node > o.node; }
    };
    std::vector<CutNode> heap;      // a max-heap (std::push_heap) on bound
    std::vector<int32_t> pending;   // nodes to add to the cut (children of refined nodes)
    std::vector<int32_t> queued;    // nodes to estimate, in one batch
    std::vector<Rgb> bounds, estimates;
    bool inUse = false;
};

// `otherLuminance`: the luminance of what the pixel receives besides this cut
// (0: the cut's own total is the reference, as in the paper's part (d)); the
// threshold then applies to the pixel's total, as Lightcuts' relative error
// does (Walter et al. 2005: a fraction of the pixel's value).
// A visitor may also offer
//   void evaluate(const int32_t* nodes, Rgb* estimates, size_t count)
// (leaf() for leaves, estimate() for the others, of `count` nodes at once): the
// walk then estimates the nodes a refinement adds (both children, and the
// children of crossed nodes) in one call, so that the VRL kernel fills lanes.
template <class Visitor>
Rgb walkCut(const LightTree& tree, const CutSettings& settings, CutStatistics& statistics, Visitor&& visitor,
            float otherLuminance = 0.0f) {
    thread_local CutScratch threadScratch;
    CutScratch localScratch;
    CutScratch& scratch = threadScratch.inUse ? localScratch : threadScratch;
    scratch.inUse = true;
    struct Release {
        CutScratch& s;
        ~Release() { s.inUse = false; }
    } release{scratch};
    auto& heap = scratch.heap;
    auto& pending = scratch.pending;
    auto& queued = scratch.queued;
    heap.clear(), pending.clear(), queued.clear(), scratch.bounds.clear();
    Rgb total(0.0f);
    uint32_t leavesInCut = 0;
    const auto& nodes = tree.nodes();
    // Adds the nodes in `pending` (and, for crossed nodes, their children) to the cut.
    const auto addPending = [&] {
        queued.clear(), scratch.bounds.clear();
        while (!pending.empty()) {
            const int32_t i = pending.back();
            pending.pop_back();
            const LightTreeNode& node = nodes[i];
            Rgb b(0.0f);
            if (!node.isLeaf() && !visitor.bound(i, b)) {  // infinite bound: refine without estimating
                ++statistics.intersected;
                pending.push_back(node.left);
                pending.push_back(node.right);
                continue;
            }
            queued.push_back(i);
            scratch.bounds.push_back(b);
        }
        scratch.estimates.resize(queued.size());
        if constexpr (requires { visitor.evaluate(queued.data(), scratch.estimates.data(), queued.size()); }) {
            visitor.evaluate(queued.data(), scratch.estimates.data(), queued.size());
        } else {
            for (size_t k = 0; k < queued.size(); ++k)
                scratch.estimates[k] = nodes[queued[k]].isLeaf() ? visitor.leaf(queued[k]) : visitor.estimate(queued[k]);
        }
        for (size_t k = 0; k < queued.size(); ++k) {
            const int32_t i = queued[k];
            const Rgb& e = scratch.estimates[k];
            total += e;
            ++statistics.evaluated;
            if (nodes[i].isLeaf()) {
                ++leavesInCut;
                continue;
            }
            const Rgb& b = scratch.bounds[k];
            ++statistics.boundedEstimates;
            if (e.x > b.x || e.y > b.y || e.z > b.z) ++statistics.boundExceeded;
            const float key = luminance(b);
            heap.push_back({key >= 0.0f ? key : std::numeric_limits<float>::infinity(), i, e});  // NaN: refine
            std::push_heap(heap.begin(), heap.end());
        }
    };
    pending.push_back(tree.root());
    addPending();
    while (!heap.empty()) {
        const CutScratch::CutNode top = heap.front();
        if (top.bound <= settings.errorThreshold * (std::max(0.0f, luminance(total)) + otherLuminance)) break;
        if (heap.size() + leavesInCut >= settings.maxCutSize) break;
        std::pop_heap(heap.begin(), heap.end());
        heap.pop_back();
        total -= top.estimate;
        pending.push_back(nodes[top.node].right);
        pending.push_back(nodes[top.node].left);
        addPending();
    }
    statistics.cutSize += uint32_t(heap.size()) + leavesInCut;
    // Subtracting refined estimates can leave float dust below zero.
    return Rgb(std::max(0.0f, total.x), std::max(0.0f, total.y), std::max(0.0f, total.z));
}

}  // namespace vrl
