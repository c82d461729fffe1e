// walkCut (cut_walk.h), the refinement every cut method shares, with synthetic
// visitors whose estimates follow the walk's contract exactly: a node's estimate
// is Phi(node) times a per-representative colour u(rep), channel by channel.
// Checks:
// * inheritance: a refined node's child with the parent's representative is
//   never evaluated again, so a walk to the leaves evaluates every VRL exactly
//   once (N calls for 2N - 1 cut nodes), crossed nodes included, and its total is
//   the sum over the VRLs to float rounding (relative 1e-5: a leaf's value went
//   through at most depth ~40 flux ratios, each exact to half an ulp);
// * the batched and the per-node evaluation paths give the same bits;
// * batched refinement against a sequential reference walk written here (one
//   node at a time, every node evaluated): refinements share evaluate() calls,
//   the same result within the cut's own error (tolerances below);
// * maxCutSize caps the cut exactly;
// * deferred bounds (a cheap bound from the parent's factor, made tight only
//   before a refinement): where the cheap bound is at least the tight one, the
//   same cut, bits and statistics as tight bounds everywhere (bound violations:
//   at most as many, each node checked against the bound it last had), with fewer
//   tight bounds computed.
#include "render/core/rng.h"
#include "render/lightcuts/cuts/cut_walk.h"
#include "render/lightcuts/tree/light_tree.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <queue>
#include <set>
#include <vector>

namespace vrl {
namespace {

std::vector<Vrl> randomVrls(size_t n, uint64_t seed) {
    Rng rng(seed, 17);
    std::vector<Vrl> vrls(n);
    for (Vrl& v : vrls) {
        v.origin = {10 * rng.next() - 5, 10 * rng.next() - 5, 10 * rng.next() - 5};
        const Vec3 d(rng.next() - 0.5f, rng.next() - 0.5f, rng.next() + 0.1f);
        v.direction = d.normalized();
        v.length = 0.01f + 0.5f * rng.next();
        v.flux = Rgb(rng.next(), rng.next(), rng.next()) * std::pow(10.0f, -3.0f * rng.next());
        if (rng.next() < 0.1f) v.flux.y = 0.0f;  // a black channel: the flux ratio's 0/0 case
        v.medium = 0;
    }
    return vrls;
}

// The per-representative colour of the synthetic estimator.
Rgb unit(uint32_t representative) {
    Rng rng(99, representative);
    return Rgb(0.5f + rng.next(), 0.5f + rng.next(), 0.5f + rng.next());
}

Rgb nodeFlux(const LightTree& tree, int32_t i) {
    const LightTreeNode& n = tree.nodes()[size_t(i)];
    return n.isLeaf() ? tree.vrls()[n.representative].flux : n.clusterFlux;
}

// Bound: Phi(node) x the largest unit colour x a factor that shrinks with the
// node's size, so that the walk refines big nodes first; `crossEvery` > 0 makes
// every such inner node (by index) a crossed one.
struct Synthetic {
    explicit Synthetic(const LightTree& t, int cross = 0, float scale = 1.5f)
        : tree(t), crossEvery(cross), boundScale(scale) {}
    const LightTree& tree;
    int crossEvery = 0;
    float boundScale = 1.5f;  // below 1.5, some estimates exceed their bound
    mutable std::vector<int32_t> evaluatedNodes;
    Rgb leaf(int32_t i) const { return estimate(i); }
    Rgb estimate(int32_t i) const {
        evaluatedNodes.push_back(i);
        return nodeFlux(tree, i) * unit(tree.nodes()[size_t(i)].representative);
    }
    bool bound(int32_t i, Rgb& b) const {
        const LightTreeNode& n = tree.nodes()[size_t(i)];
        if (crossEvery > 0 && i % crossEvery == 0) return false;
        b = n.clusterFlux * (boundScale * float(n.vrlCount));
        return true;
    }
};

// The same bound as a factor (boundScale x vrlCount, which shrinks down the tree)
// times the flux; given the parent's factor, the cheap bound uses it instead: at
// least the tight one, since a parent holds more VRLs.
struct SyntheticDeferred : Synthetic {
    using Synthetic::Synthetic;
    mutable size_t tightBounds = 0, cheapBounds = 0;
    bool bound(int32_t i, const Rgb* inherited, Rgb& b, Rgb& factor, bool& tight) const {
        const LightTreeNode& n = tree.nodes()[size_t(i)];
        if (crossEvery > 0 && i % crossEvery == 0) return false;
        tight = inherited == nullptr;
        factor = inherited ? *inherited : Rgb(boundScale * float(n.vrlCount));
        ++(tight ? tightBounds : cheapBounds);
        b = n.clusterFlux * factor;
        return true;
    }
    void tighten(int32_t i, Rgb& b, Rgb& factor) const {
        bool tight = false;
        bound(i, nullptr, b, factor, tight);
    }
};

struct SyntheticBatched : Synthetic {
    using Synthetic::Synthetic;
    mutable size_t calls = 0;
    void evaluate(const int32_t* ids, Rgb* out, size_t count) const {
        ++calls;
        for (size_t k = 0; k < count; ++k) out[k] = estimate(ids[k]);
    }
};

// Lightcuts one node at a time, every node evaluated (the walk before
// inheritance and batching).
Rgb sequentialWalk(const LightTree& tree, const Synthetic& v, float threshold, uint32_t& evaluated) {
    struct Entry {
        float bound;
        int32_t node;
        Rgb estimate;
        bool operator<(const Entry& o) const { return bound != o.bound ? bound < o.bound : node > o.node; }
    };
    std::priority_queue<Entry> heap;
    Rgb total(0.0f);
    std::vector<int32_t> pending{tree.root()};
    const auto add = [&] {
        while (!pending.empty()) {
            const int32_t i = pending.back();
            pending.pop_back();
            const LightTreeNode& n = tree.nodes()[size_t(i)];
            Rgb b(0.0f);
            if (!n.isLeaf() && !v.bound(i, b)) {
                pending.push_back(n.left), pending.push_back(n.right);
                continue;
            }
            const Rgb e = v.estimate(i);
            ++evaluated;
            total += e;
            if (!n.isLeaf()) heap.push({luminance(b), i, e});
        }
    };
    add();
    while (!heap.empty() && heap.top().bound > threshold * luminance(total)) {
        const Entry top = heap.top();
        heap.pop();
        total -= top.estimate;
        pending.push_back(tree.nodes()[size_t(top.node)].right), pending.push_back(tree.nodes()[size_t(top.node)].left);
        add();
    }
    return total;
}

double relativeDifference(const Rgb& a, const Rgb& b) {
    double worst = 0.0;
    for (int c = 0; c < 3; ++c) {
        const double scale = std::max(std::abs(double(b[c])), 1e-30);
        worst = std::max(worst, std::abs(double(a[c]) - double(b[c])) / scale);
    }
    return worst;
}

CutSettings settingsFor(float threshold, uint32_t maxCutSize = 1u << 30) {
    CutSettings s;
    s.errorThreshold = threshold;
    s.maxCutSize = maxCutSize;
    return s;
}

TEST(CutWalk, ToTheLeavesEvaluatesEveryVrlOnceAndSumsThem) {
    const LightTree tree = LightTree::build(randomVrls(3000, 1));
    Rgb exact(0.0f);
    for (uint32_t k = 0; k < tree.vrls().size(); ++k) exact += tree.vrls()[k].flux * unit(k);
    Synthetic v{tree};
    CutStatistics stats;
    const Rgb total = walkCut(tree, settingsFor(0.0f), stats, v);
    EXPECT_EQ(stats.evaluated, 2 * tree.vrls().size() - 1);  // every node was in the cut once
    EXPECT_EQ(stats.cutSize, tree.vrls().size());
    EXPECT_EQ(v.evaluatedNodes.size(), tree.vrls().size()) << "each representative evaluated once";
    std::set<uint32_t> representatives;
    for (int32_t i : v.evaluatedNodes) representatives.insert(tree.nodes()[size_t(i)].representative);
    EXPECT_EQ(representatives.size(), tree.vrls().size());
    EXPECT_LT(relativeDifference(total, exact), 1e-5) << total.x << " " << exact.x;
}

TEST(CutWalk, CrossedNodesPassTheirRepresentativesEstimateOn) {
    const LightTree tree = LightTree::build(randomVrls(2000, 2));
    Rgb exact(0.0f);
    for (uint32_t k = 0; k < tree.vrls().size(); ++k) exact += tree.vrls()[k].flux * unit(k);
    Synthetic v{tree, 7};
    CutStatistics stats;
    const Rgb total = walkCut(tree, settingsFor(0.0f), stats, v);
    EXPECT_GT(stats.intersected, 0u);
    // A crossed node passes on the estimate its representative has (inherited from
    // its parent, or, at the root, none: then its children evaluate it once): still
    // every VRL exactly once.
    EXPECT_EQ(v.evaluatedNodes.size(), tree.vrls().size());
    EXPECT_LT(relativeDifference(total, exact), 1e-5);
}

// Walks with visitors a and b at `threshold` and expects the same bits, the same
// nodes evaluated in the same order and the same #Eval; their statistics in sa, sb.
template <class A, class B>
void expectSameWalk(const LightTree& tree, float threshold, A& a, B& b, CutStatistics& sa, CutStatistics& sb,
                    uint32_t maxCutSize = 1u << 30) {
    const Rgb ta = walkCut(tree, settingsFor(threshold, maxCutSize), sa, a);
    const Rgb tb = walkCut(tree, settingsFor(threshold, maxCutSize), sb, b);
    EXPECT_EQ(ta.x, tb.x);
    EXPECT_EQ(ta.y, tb.y);
    EXPECT_EQ(ta.z, tb.z);
    EXPECT_EQ(sa.evaluated, sb.evaluated);
    EXPECT_EQ(a.evaluatedNodes, b.evaluatedNodes);
}

TEST(CutWalk, BatchedAndPerNodeEvaluationGiveTheSameBits) {
    const LightTree tree = LightTree::build(randomVrls(3000, 3));
    for (float threshold : {0.0f, 0.001f, 0.02f, 0.2f}) {
        Synthetic a{tree, 11};
        SyntheticBatched b{tree, 11};
        CutStatistics sa, sb;
        expectSameWalk(tree, threshold, a, b, sa, sb);
    }
}

// Batched refinement: several refinements share one evaluate() call (each
// refinement adds one node to evaluate, the other child inherits), and the cut
// stays the sequential walk's within 5% of #Eval (not an invariant: seen equal
// at all three thresholds, 3499, 1353 and 655 nodes, of which 1750, 677 and 328
// evaluated); the totals differ by less than the threshold times the total (the
// cuts' relative error tolerance; these synthetic "bounds" are not bounds, so
// only the two walks are compared, not the leaves' sum).
TEST(CutWalk, RefinementsShareKernelCallsAndKeepTheSequentialCut) {
    const LightTree tree = LightTree::build(randomVrls(4000, 4));
    for (float threshold : {0.002f, 0.02f, 0.1f}) {
        Synthetic reference{tree};
        uint32_t sequentialEvaluated = 0;
        const Rgb sequential = sequentialWalk(tree, reference, threshold, sequentialEvaluated);
        SyntheticBatched v{tree};
        CutStatistics stats;
        const Rgb total = walkCut(tree, settingsFor(threshold), stats, v);
        SCOPED_TRACE(threshold);
        const uint32_t refinements = (stats.evaluated - 1) / 2;
        EXPECT_LT(2 * v.calls, size_t(refinements)) << "refinements are not batched";
        EXPECT_NEAR(double(stats.evaluated), double(sequentialEvaluated), 0.05 * sequentialEvaluated);
        EXPECT_LT(v.evaluatedNodes.size(), size_t(stats.evaluated)) << "children that share the parent's "
                                                                       "representative are inherited";
        EXPECT_NEAR(luminance(total), luminance(sequential), threshold * luminance(sequential));
    }
}

// maxCutSize caps the cut exactly when no node is crossed (each refinement adds
// one node; a batch counts the refinements it has already made).
TEST(CutWalk, MaxCutSizeCapsTheCut) {
    const LightTree tree = LightTree::build(randomVrls(3000, 5));
    for (const uint32_t cap : {1u, 2u, 5u, 8u, 64u, 333u}) {
        CutSettings settings = settingsFor(0.0f);  // would refine to the leaves
        settings.maxCutSize = cap;
        Synthetic v{tree};
        CutStatistics stats;
        walkCut(tree, settings, stats, v);
        EXPECT_EQ(stats.cutSize, std::max(cap, 1u)) << cap;
    }
}

// Deferred bounds whose cheap bound is at least the tight one: the walk refines
// the same nodes in the same order (a cheap node on top is made tight before it can
// be refined, and the threshold test only stops on a bound that is at least the
// tight one), so totals, evaluated nodes and statistics are bit for bit those of
// tight bounds everywhere (boundScale 0.6 makes bound violations, counted against
// the bound each node last had); and nodes left in the cut below the threshold
// never get a tight bound.
TEST(CutWalk, DeferredBoundsKeepTheCutAndSkipTightBoundsOfNodesNotRefined) {
    const LightTree tree = LightTree::build(randomVrls(3000, 6));
    for (const int cross : {0, 13})
        for (const float scale : {1.5f, 0.6f})
            for (const float threshold : {0.0f, 0.002f, 0.02f, 0.2f}) {
                SCOPED_TRACE(testing::Message() << "cross " << cross << " scale " << scale << " e " << threshold);
                Synthetic tightEverywhere{tree, cross, scale};
                SyntheticDeferred deferred{tree, cross, scale};
                CutStatistics st, sd;
                expectSameWalk(tree, threshold, tightEverywhere, deferred, st, sd);
                EXPECT_EQ(st.cutSize, sd.cutSize);
                EXPECT_EQ(st.intersected, sd.intersected);
                EXPECT_EQ(st.boundedEstimates, sd.boundedEstimates);
                // Violations count against the bound each node last had: a node never made
                // tight is checked against its cheap bound (here larger), so at most as many.
                EXPECT_LE(sd.boundExceeded, st.boundExceeded);
                if (scale < 1.0f && threshold < 0.1f) {
                    EXPECT_GT(sd.boundExceeded, 0u);
                }
                if (scale >= 1.5f) {
                    EXPECT_EQ(st.boundExceeded, 0u);
                }
                // Every refined node was made tight first; a cut stopped by the threshold
                // leaves nodes that never were.
                const uint32_t refinements = (st.evaluated + st.intersected - 1) / 2;
                EXPECT_GE(deferred.tightBounds, size_t(refinements) - st.intersected);
                if (threshold >= 0.02f) {
                    EXPECT_LT(deferred.tightBounds, size_t(st.boundedEstimates));
                }
            }
}

// The same under maxCutSize: the cap stops the walk after the same refinements, since
// the deferred walk refines the same nodes in the same order (above). Caps that stop
// the walk before the threshold does, with and without crossed nodes.
TEST(CutWalk, DeferredBoundsKeepTheCutUnderMaxCutSize) {
    const LightTree tree = LightTree::build(randomVrls(3000, 6));
    for (const int cross : {0, 13})
        for (const uint32_t cap : {2u, 8u, 64u, 333u})
            for (const float threshold : {0.0f, 0.002f}) {
                SCOPED_TRACE(testing::Message() << "cross " << cross << " cap " << cap << " e " << threshold);
                Synthetic tightEverywhere{tree, cross, 1.5f};
                SyntheticDeferred deferred{tree, cross, 1.5f};
                CutStatistics st, sd;
                expectSameWalk(tree, threshold, tightEverywhere, deferred, st, sd, cap);
                EXPECT_EQ(st.cutSize, sd.cutSize);
                EXPECT_EQ(st.intersected, sd.intersected);
                EXPECT_EQ(st.boundedEstimates, sd.boundedEstimates);
                CutStatistics uncapped;
                Synthetic uncappedWalk{tree, cross, 1.5f};
                walkCut(tree, settingsFor(threshold), uncapped, uncappedWalk);
                EXPECT_LT(st.cutSize, uncapped.cutSize) << "the cap must stop the walk";
                if (cross == 0) {
                    EXPECT_EQ(sd.cutSize, cap);
                }
            }
}

}  // namespace
}  // namespace vrl
