// Stochastic Lightcuts over a light tree (Yuksel 2019; Lin & Yuksel 2020),
// generic over the query (a camera segment for part (d), a surface point for
// part (c)): the caller supplies a node importance and a one-light estimate.
//
// The cut: starting at the root, the inner node of largest importance is
// replaced by its children until the cut holds `cutSize` nodes or only
// leaves. The cut's nodes and the children left out of it (below) partition the
// leaves, so the total is the sum over the cut's nodes of each node's own sum,
// whatever rule chose the cut. A child whose importance is 0 while its sibling's
// is positive and finite is left out of the cut (neverTaken): its contribution is 0 (below), and a descent
// through its parent would never take it anyway; the slot goes to a node that can
// contribute.
//
// The descent, per cut node C: from C down to a leaf, at each inner node the
// left child is taken with probability p_L = I_L / (I_L + I_R) (I: importance),
// the right one with 1 - p_L. A leaf k under C is reached with probability
// P(k | C) = product of the branch probabilities, and the estimate
// E_k / P(k | C) (E_k: the leaf's one-VRL estimate, itself unbiased) has
// expectation  sum over k under C with P(k | C) > 0 of E[E_k]. It is unbiased for
// node C's sum exactly when every leaf whose contribution can be non-zero has
// P(k | C) > 0, i.e. when no branch it needs has probability 0. The rule here:
// a child's probability is 0 only if its importance is 0 and its sibling's is
// positive, so the importance must be 0 only where the child's contribution is
// provably 0 (its flux is 0, or every VRL in it is behind a reflecting
// surface); when both children's importances are 0 or not finite (underflow),
// the choice falls back to their flux x length, then to 1/2. Leaves in the cut
// are estimated directly (P = 1). Summing the cut's estimates gives an unbiased
// estimate of the whole tree's sum, with cutSize one-light estimates.
// The path probabilities of all leaves under a cut sum to the cut's size (each
// node's descent is a probability distribution over its leaves):
// stochasticLeafProbabilities gives them, for tests.
#pragma once

#include "render/core/rgb.h"
#include "render/core/rng.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vrl {

// What an importance provider returns for an inner node: its two children (left,
// right) and their importances (a NaN counts as infinite). Importances come in
// pairs because every use needs both children's: the cut refines a node into
// both, the descent chooses between them.
struct ChildImportances {
    int32_t node[2];
    double value[2];
};

// The probability of taking the left child, from the children's importances and
// (fallback) their flux x length. In [0, 1]; 0 or 1 only when one importance is 0
// and the other positive (or, in the fallback, one flux x length is 0).
inline double leftProbability(const ChildImportances& c, const LightTree& tree) {
    const double sum = c.value[0] + c.value[1];
    if (sum > 0.0 && std::isfinite(sum)) return c.value[0] / sum;
    const LightTreeNode& left = tree.nodes()[c.node[0]];
    const LightTreeNode& right = tree.nodes()[c.node[1]];
    const double fl = double(left.fluxLength.x) + left.fluxLength.y + left.fluxLength.z;
    const double fr = double(right.fluxLength.x) + right.fluxLength.y + right.fluxLength.z;
    if (fl + fr > 0.0 && std::isfinite(fl + fr)) return fl / (fl + fr);
    return 0.5;
}

// Whether a descent from the parent never takes child k: its importance is 0 beside a
// positive, finite sibling, where leftProbability gives it probability 0 (the ratio
// branch). The cut gives such a child no slot, since its contribution is 0 (the
// importance's contract); the descent reaches the same children through leftProbability,
// and StochasticCut.SkippedChildrenAreTheOnesNoDescentTakes keeps the two in step.
inline bool neverTaken(const ChildImportances& c, int k) {
    return c.value[k] == 0.0 && c.value[1 - k] > 0.0 && std::isfinite(c.value[1 - k]);
}

// Leaves are the tree's first vrls().size() nodes (light_tree.h).
inline bool isLeafNode(const LightTree& tree, int32_t node) { return size_t(node) < tree.vrls().size(); }

// The cut of at most `cutSize` nodes (leaves and inner nodes), refining by largest
// importance (`importance`: ChildImportances(int32_t innerNode)). Adds the number
// of importance evaluations to *importanceEvaluations. `cut` is cleared first.
template <class Importance>
void stochasticCut(const LightTree& tree, uint32_t cutSize, Importance&& importance, std::vector<int32_t>& cut,
                   uint32_t* importanceEvaluations = nullptr) {
    cut.clear();
    if (tree.empty()) return;
    struct Entry {
        double importance;
        int32_t node;
        bool operator<(const Entry& o) const {
            return importance != o.importance ? importance < o.importance : node > o.node;
        }
    };
    // A heap of at most cutSize entries, reused by the thread (no allocation per query).
    thread_local std::vector<Entry> inner;
    inner.clear();
    const int32_t root = tree.root();
    if (isLeafNode(tree, root)) {
        cut.push_back(root);
        return;
    }
    // The root's own importance is never compared with anything.
    inner.push_back({0.0, root});
    const size_t size = std::max<uint32_t>(cutSize, 1u);
    while (!inner.empty() && cut.size() + inner.size() < size) {
        std::pop_heap(inner.begin(), inner.end());
        const int32_t i = inner.back().node;
        inner.pop_back();
        const ChildImportances c = importance(i);
        if (importanceEvaluations) *importanceEvaluations += 2;
        for (int k = 0; k < 2; ++k) {
            if (neverTaken(c, k)) continue;  // no slot: nothing under it contributes
            if (isLeafNode(tree, c.node[k])) {
                cut.push_back(c.node[k]);
                continue;
            }
            double value = c.value[k];
            if (!(value >= 0.0)) value = std::numeric_limits<double>::infinity();  // NaN: refine first
            inner.push_back({value, c.node[k]});
            std::push_heap(inner.begin(), inner.end());
        }
    }
    // The remaining inner nodes, in decreasing importance (the order of the old queue).
    std::sort_heap(inner.begin(), inner.end());
    for (auto it = inner.rbegin(); it != inner.rend(); ++it) cut.push_back(it->node);
}

template <class Importance>
std::vector<int32_t> stochasticCut(const LightTree& tree, uint32_t cutSize, Importance&& importance,
                                   uint32_t* importanceEvaluations = nullptr) {
    std::vector<int32_t> cut;
    stochasticCut(tree, cutSize, importance, cut, importanceEvaluations);
    return cut;
}

// One leaf under `node`, drawn by importance; returns the leaf's node index and
// sets `probability` to P(leaf | node).
template <class Importance>
int32_t stochasticDescent(const LightTree& tree, int32_t node, Rng& rng, Importance&& importance, double& probability,
                          uint32_t* importanceEvaluations = nullptr) {
    probability = 1.0;
    while (!isLeafNode(tree, node)) {
        const ChildImportances c = importance(node);
        const double pl = leftProbability(c, tree);
        if (importanceEvaluations) *importanceEvaluations += 2;
        if (rng.nextDouble() < pl) {
            probability *= pl;
            node = c.node[0];
        } else {
            probability *= 1.0 - pl;
            node = c.node[1];
        }
    }
    return node;
}

// The stochastic cut estimate: every cut node draws one leaf (in cut order, each
// descent drawing from `rng`), then leafEstimates(leaves, count, rng, out) gives
// their one-VRL estimates at once (SIMD lanes), each divided by its probability.
// `leafEstimates`: void(const int32_t* leaves, size_t count, Rng&, Rgb* out).
template <class Importance, class LeafEstimates>
Rgb stochasticCutEstimate(const LightTree& tree, uint32_t cutSize, Rng& rng, CutStatistics& statistics,
                          Importance&& importance, LeafEstimates&& leafEstimates) {
    thread_local std::vector<int32_t> cut;
    thread_local std::vector<int32_t> leaves;
    thread_local std::vector<double> probabilities;
    thread_local std::vector<Rgb> estimates;
    uint32_t evaluations = 0;
    stochasticCut(tree, cutSize, importance, cut, &evaluations);
    leaves.resize(cut.size());
    probabilities.resize(cut.size());
    estimates.resize(cut.size());
    for (size_t k = 0; k < cut.size(); ++k)
        leaves[k] = stochasticDescent(tree, cut[k], rng, importance, probabilities[k], &evaluations);
    leafEstimates(leaves.data(), leaves.size(), rng, estimates.data());
    // probability > 0 by construction: a branch of probability 0 is never taken
    // (rng.nextDouble() < 1 and a zero left probability sends every draw right).
    Rgb total(0.0f);
    for (size_t k = 0; k < cut.size(); ++k) total += estimates[k] * float(1.0 / probabilities[k]);
    statistics.evaluated += uint32_t(cut.size());
    statistics.cutSize += uint32_t(cut.size());
    statistics.importanceEvaluations += evaluations;
    return total;
}

// Every leaf under `node` with P(k | node), the probability that the descent from
// `node` reaches it, and the leaf's own importance as its parent's pair gave it
// (1 when `node` is that leaf): visit(int32_t leaf, double probability, double
// importance), depth first. `stack` is scratch space (cleared first). For tests and
// benchmarks that predict a cut's variance from its descents.
struct LeafDescent {
    int32_t node;
    double probability, importance;
};
template <class Importance, class Visit>
void forEachLeafDescent(const LightTree& tree, int32_t node, Importance&& importance, Visit&& visit,
                        std::vector<LeafDescent>& stack) {
    stack.assign(1, {node, 1.0, 1.0});
    while (!stack.empty()) {
        const LeafDescent e = stack.back();
        stack.pop_back();
        if (isLeafNode(tree, e.node)) {
            visit(e.node, e.probability, e.importance);
            continue;
        }
        const ChildImportances children = importance(e.node);
        const double pl = leftProbability(children, tree);
        stack.push_back({children.node[0], e.probability * pl, children.value[0]});
        stack.push_back({children.node[1], e.probability * (1.0 - pl), children.value[1]});
    }
}

// For tests: P(k) of every leaf k (indexed by VRL, i.e. leaf node) over the cut
// chosen by `importance`: each leaf's probability of being drawn by its cut node's
// descent (1 for a leaf in the cut). They sum to the cut's size.
template <class Importance>
std::vector<double> stochasticLeafProbabilities(const LightTree& tree, uint32_t cutSize, Importance&& importance) {
    std::vector<double> p(tree.vrls().size(), 0.0);
    std::vector<LeafDescent> stack;
    for (const int32_t c : stochasticCut(tree, cutSize, importance))
        forEachLeafDescent(tree, c, importance, [&](int32_t leaf, double q, double) { p[size_t(leaf)] += q; }, stack);
    return p;
}

}  // namespace vrl
