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
//
// Contract the walk relies on (true of every visitor in render/lightcuts/): a
// node's estimate is its representative's estimate with the representative's
// flux replaced by the node's flux Phi(node) (clusterFlux; a leaf: its VRL's
// flux), drawn from the representative's own random stream, and it is linear in
// that flux channel by channel. A refined node's representative is one of its
// children's (LightTree validates it), so that child's estimate is the parent's
// times Phi(child) / Phi(parent), channel by channel: the walk inherits it
// instead of evaluating it again (Walter et al. 2005, Sec. 4.1). Only the other
// child is evaluated, up to float rounding the same value it had before.
//
// Batched refinement: the node with the largest bound is refined, and with it
// the next ones of the heap whose bounds also exceed the threshold of the total
// before this step (kRefineBatch at most), so that one kernel call estimates
// several new representatives in its lanes. The sequential walk would mostly
// refine those nodes too, so the cut usually ends the same or a few nodes finer;
// it is not guaranteed to be finer (estimates do not add up exactly, so the
// total after a batch may differ from the sequential walk's and a later step
// may stop earlier), and at maxCutSize a batch may take the heap's next nodes
// where the sequential walk would take a just-created child. Both walks keep
// the error test; the cut never exceeds maxCutSize by more than the crossed
// nodes' children (as before, but found after a whole batch).
//
// A crossed node (refined without an estimate) that shares its parent's
// representative passes the inherited estimate on to its children, so a walk to
// the leaves evaluates every VRL exactly once.
//
// Deferred bounds. A visitor whose bound has expensive parts may offer
//   bool bound(int32_t node, const Rgb* inherited, Rgb& bound, Rgb& factor, bool& tight)
//   void tighten(int32_t node, Rgb& bound, Rgb& factor)
// instead of bound(node, bound). The first may return a cheap bound (tight = false),
// built for instance on `inherited`, the factor its parent's tight bound used (null
// for the root and below crossed nodes that had none); it decides whether the query
// crosses the node exactly, as bound(node, bound) does. tighten gives the full bound
// of a node that is not crossed. Both return the factor they used.
// The walk makes a node's bound tight only when that node reaches the top of the heap
// above the threshold, that is, only before it would be refined: nodes that stay in
// the cut below the threshold on their cheap bound never pay for the full one.
// Where the cheap bound is at least the tight one the cut is the same as with tight
// bounds everywhere; where it is not (a heuristic factor), the cut relies on the
// cheap bound, and boundExceeded counts each node against the bound it last had.
#pragma once

#include "render/core/rgb.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"

#include <algorithm>
#include <concepts>
#include <limits>
#include <type_traits>
#include <vector>

namespace vrl {

// Scratch space of walkCut, one per thread and kind of walk and reused (no
// allocation per pixel once it has grown); a nested walk on the same thread takes a
// fresh one. `Deferred`: the walk's visitor has deferred bounds (below); only then do
// heap entries carry their state (a walk's heap operations move its entries, and the
// other walks keep theirs at 20 bytes).
template <bool Deferred>
struct CutScratch {
    struct NoState {};
    struct DeferredState {
        Rgb factor{0.0f};       // the factor the bound used (passed to the children)
        bool tight = true;      // false while the bound is the cheap one
        bool exceeded = false;  // the estimate exceeds the bound (counted in CutStatistics::boundExceeded)
    };
    using State = std::conditional_t<Deferred, DeferredState, NoState>;
    struct ParentFactor {
        Rgb factor{0.0f};
        bool has = false;
    };
    struct CutNode {
        float bound;  // luminance of the node's bound
        int32_t node;
        Rgb estimate;
        [[no_unique_address]] State state{};
        bool operator<(const CutNode& o) const { return bound != o.bound ? bound < o.bound : node > o.node; }
    };
    std::vector<CutNode> heap;      // a max-heap (std::push_heap) on bound
    struct Pending {
        int32_t node;
        int32_t parent;  // the parent whose estimate it may inherit; -1: none (the root, the children
                         // of a crossed node that did not share its own parent's representative)
        Rgb parentEstimate;
        // Deferred bounds: the parent's factor, where there is one.
        [[no_unique_address]] std::conditional_t<Deferred, ParentFactor, NoState> parentFactor{};
    };
    std::vector<Pending> pending;   // nodes to add to the cut (children of refined nodes)
    std::vector<CutNode> added;     // nodes with an estimate, to push on the heap
    std::vector<int32_t> queued;    // nodes to estimate, in one batch
    std::vector<Rgb> bounds, estimates;  // of the queued nodes
    std::vector<Rgb> addedBounds;       // of the added (inherited) nodes
    std::vector<State> states, addedStates;  // deferred bounds: of the queued and the added nodes
    bool inUse = false;
};
static_assert(sizeof(CutScratch<false>::CutNode) == 20, "walks without deferred bounds keep 20-byte heap entries");

// `otherLuminance`: the luminance of what the pixel receives besides this cut
// (0: the cut's own total is the reference, as in the paper's media-only images); the
// threshold then applies to the pixel's total, as Lightcuts' relative error
// does (Walter et al. 2005: a fraction of the pixel's value).
// A visitor may also offer
//   void evaluate(const int32_t* nodes, Rgb* estimates, size_t count)
// (leaf() for leaves, estimate() for the others, of `count` nodes at once): the
// walk then estimates the nodes a refinement adds (both children, and the
// children of crossed nodes) in one call, so that the VRL kernel fills lanes.
// Nodes refined together at most (see "Batched refinement" above): the cuts'
// kernel call has four lanes.
inline constexpr int kRefineBatch = 4;

template <class Visitor>
Rgb walkCut(const LightTree& tree, const CutSettings& settings, CutStatistics& statistics, Visitor&& visitor,
            float otherLuminance = 0.0f) {
    constexpr bool kDeferred = requires(Rgb& r, bool& t, const Rgb* f) {
        { visitor.bound(int32_t(0), f, r, r, t) } -> std::convertible_to<bool>;
        visitor.tighten(int32_t(0), r, r);
    };
    using Scratch = CutScratch<kDeferred>;
    thread_local Scratch threadScratch;
    Scratch localScratch;
    Scratch& scratch = threadScratch.inUse ? localScratch : threadScratch;
    scratch.inUse = true;
    struct Release {
        Scratch& s;
        ~Release() { s.inUse = false; }
    } release{scratch};
    auto& heap = scratch.heap;
    auto& pending = scratch.pending;
    auto& queued = scratch.queued;
    auto& added = scratch.added;
    heap.clear(), pending.clear(), queued.clear(), scratch.bounds.clear();
    Rgb total(0.0f);
    uint32_t leavesInCut = 0;
    const auto& nodes = tree.nodes();
    const auto flux = [&](int32_t i) -> const Rgb& {
        const LightTreeNode& n = nodes[size_t(i)];
        return n.isLeaf() ? tree.vrls()[n.representative].flux : n.clusterFlux;
    };
    const auto inherit = [&](const Rgb& e, int32_t parent, int32_t child) {
        const Rgb& from = flux(parent);
        const Rgb& to = flux(child);
        return Rgb(from.x > 0.0f ? e.x * (to.x / from.x) : 0.0f, from.y > 0.0f ? e.y * (to.y / from.y) : 0.0f,
                   from.z > 0.0f ? e.z * (to.z / from.z) : 0.0f);
    };
    // The walk's time goes mostly to cache misses on the nodes it reaches and on their
    // representatives' records: a refinement announces its children's nodes, and a
    // queued node its representative, before they are read (no effect on results).
    const auto prefetchNode = [&](int32_t i) {
        const char* first = reinterpret_cast<const char*>(&nodes[size_t(i)]);
        __builtin_prefetch(first);
        __builtin_prefetch(first + sizeof(LightTreeNode) - 1);
    };
    const auto exceeds = [](const Rgb& e, const Rgb& b) { return e.x > b.x || e.y > b.y || e.z > b.z; };
    const auto heapKey = [](const Rgb& b) {
        const float key = luminance(b);
        return key >= 0.0f ? key : std::numeric_limits<float>::infinity();  // NaN: refine
    };
    // Adds a node with its estimate and bound to the cut.
    const auto addToCut = [&](int32_t i, const Rgb& e, const Rgb& b, const typename Scratch::State& d) {
        total += e;
        ++statistics.evaluated;
        if (nodes[i].isLeaf()) {
            ++leavesInCut;
            return;
        }
        ++statistics.boundedEstimates;
        const bool exceeded = exceeds(e, b);
        if (exceeded) ++statistics.boundExceeded;
        typename Scratch::CutNode entry{heapKey(b), i, e, d};
        if constexpr (kDeferred) entry.state.exceeded = exceeded;
        heap.push_back(entry);
        std::push_heap(heap.begin(), heap.end());
    };
    // Adds the nodes in `pending` (and, for crossed nodes, their children) to the cut.
    const auto addPending = [&] {
        queued.clear(), scratch.bounds.clear(), added.clear(), scratch.addedBounds.clear();
        if constexpr (kDeferred) scratch.states.clear(), scratch.addedStates.clear();
        while (!pending.empty()) {
            const typename Scratch::Pending p = pending.back();
            pending.pop_back();
            const int32_t i = p.node;
            const LightTreeNode& node = nodes[i];
            Rgb b(0.0f);
            typename Scratch::State d{};
            bool crossed = false;
            if (!node.isLeaf()) {
                if constexpr (kDeferred)
                    crossed = !visitor.bound(i, p.parentFactor.has ? &p.parentFactor.factor : nullptr, b, d.factor,
                                             d.tight);
                else
                    crossed = !visitor.bound(i, b);
            }
            const bool shares = p.parent >= 0 && node.representative == nodes[p.parent].representative;
            if (crossed) {  // infinite bound: refine without estimating
                ++statistics.intersected;
                // Its estimate, had it been made, is known when it shares the parent's
                // representative: its children may inherit from it. Its children get the
                // factor it was given (their boxes lie in its parent's).
                const Rgb e = shares ? inherit(p.parentEstimate, p.parent, i) : Rgb(0.0f);
                prefetchNode(node.left), prefetchNode(node.right);
                pending.push_back({node.left, shares ? i : -1, e, p.parentFactor});
                pending.push_back({node.right, shares ? i : -1, e, p.parentFactor});
                continue;
            }
            if (shares) {
                added.push_back({0.0f, i, inherit(p.parentEstimate, p.parent, i)});
                scratch.addedBounds.push_back(b);
                if constexpr (kDeferred) scratch.addedStates.push_back(d);
                continue;
            }
            __builtin_prefetch(&tree.vrls()[node.representative]);
            __builtin_prefetch(reinterpret_cast<const char*>(&tree.vrls()[node.representative]) + sizeof(Vrl) - 1);
            queued.push_back(i);
            scratch.bounds.push_back(b);
            if constexpr (kDeferred) scratch.states.push_back(d);
        }
        scratch.estimates.resize(queued.size());
        if constexpr (requires { visitor.evaluate(queued.data(), scratch.estimates.data(), queued.size()); }) {
            visitor.evaluate(queued.data(), scratch.estimates.data(), queued.size());
        } else {
            for (size_t k = 0; k < queued.size(); ++k)
                scratch.estimates[k] = nodes[queued[k]].isLeaf() ? visitor.leaf(queued[k]) : visitor.estimate(queued[k]);
        }
        const auto stateOf = [&](const std::vector<typename Scratch::State>& states, size_t k) {
            if constexpr (kDeferred) return states[k];
            else return typename Scratch::State{};
        };
        for (size_t a = 0; a < added.size(); ++a)
            addToCut(added[a].node, added[a].estimate, scratch.addedBounds[a], stateOf(scratch.addedStates, a));
        for (size_t q = 0; q < queued.size(); ++q)
            addToCut(queued[q], scratch.estimates[q], scratch.bounds[q], stateOf(scratch.states, q));
    };
    pending.push_back({tree.root(), -1, Rgb(0.0f)});
    addPending();
    while (!heap.empty()) {
        const float threshold = settings.errorThreshold * (std::max(0.0f, luminance(total)) + otherLuminance);
        for (int refined = 0; refined < kRefineBatch && !heap.empty();) {
            typename Scratch::CutNode top = heap.front();
            if (top.bound <= threshold) break;
            // The cut's size after `refined` refinements of this batch (each adds one node).
            if (heap.size() + leavesInCut + 2 * size_t(refined) >= settings.maxCutSize) break;
            std::pop_heap(heap.begin(), heap.end());
            heap.pop_back();
            if constexpr (kDeferred) {
                if (!top.state.tight) {  // above the threshold on its cheap bound: make it tight, and look again
                    Rgb b(0.0f);
                    visitor.tighten(top.node, b, top.state.factor);
                    top.state.tight = true;
                    const bool nowExceeded = exceeds(top.estimate, b);
                    if (nowExceeded != top.state.exceeded) {  // count the node against the bound it now has
                        if (nowExceeded) ++statistics.boundExceeded;
                        else --statistics.boundExceeded;
                    }
                    top.state.exceeded = nowExceeded;
                    top.bound = heapKey(b);
                    heap.push_back(top);
                    std::push_heap(heap.begin(), heap.end());
                    continue;
                }
            }
            total -= top.estimate;
            prefetchNode(nodes[top.node].left), prefetchNode(nodes[top.node].right);
            if constexpr (kDeferred) {
                pending.push_back({nodes[top.node].right, top.node, top.estimate, {top.state.factor, true}});
                pending.push_back({nodes[top.node].left, top.node, top.estimate, {top.state.factor, true}});
            } else {
                pending.push_back({nodes[top.node].right, top.node, top.estimate});
                pending.push_back({nodes[top.node].left, top.node, top.estimate});
            }
            ++refined;
        }
        if (pending.empty()) break;
        addPending();
    }
    statistics.cutSize += uint32_t(heap.size()) + leavesInCut;
    // Subtracting refined estimates can leave float dust below zero.
    return Rgb(std::max(0.0f, total.x), std::max(0.0f, total.y), std::max(0.0f, total.z));
}

}  // namespace vrl
