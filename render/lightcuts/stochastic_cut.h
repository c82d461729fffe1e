// Stochastic Lightcuts over a light tree (Yuksel 2019; Lin & Yuksel 2020),
// generic over the query (a camera segment for part (d), a surface point for
// part (c)): the caller supplies a node importance and a one-light estimate.
//
// The cut: starting at the root, the inner node of largest importance is
// replaced by its children until the cut holds `cutSize` nodes or only
// leaves. Any cut is a partition of the leaves, so the total is the sum over
// the cut's nodes of each node's own sum, whatever rule chose the cut.
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
#include "render/lightcuts/cut_settings.h"
#include "render/lightcuts/light_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <vector>

namespace vrl {

// The probability of taking the left child, from the children's importances and
// (fallback) their flux x length. In [0, 1]; 0 or 1 only when one importance is 0
// and the other positive (or, in the fallback, one flux x length is 0).
inline double leftProbability(double importanceLeft, double importanceRight, const LightTreeNode& left,
                              const LightTreeNode& right) {
    const double sum = importanceLeft + importanceRight;
    if (sum > 0.0 && std::isfinite(sum)) return importanceLeft / sum;
    const double fl = double(left.fluxLength.x) + left.fluxLength.y + left.fluxLength.z;
    const double fr = double(right.fluxLength.x) + right.fluxLength.y + right.fluxLength.z;
    if (fl + fr > 0.0 && std::isfinite(fl + fr)) return fl / (fl + fr);
    return 0.5;
}

// The cut of at most `cutSize` nodes (leaves and inner nodes), refining by largest
// importance (`importance`: double(int32_t node); a NaN counts as infinite). Adds
// the number of importance evaluations to *importanceEvaluations.
template <class Importance>
std::vector<int32_t> stochasticCut(const LightTree& tree, uint32_t cutSize, Importance&& importance,
                                   uint32_t* importanceEvaluations = nullptr) {
    std::vector<int32_t> cut;
    if (tree.empty()) return cut;
    struct Entry {
        double importance;
        int32_t node;
        bool operator<(const Entry& o) const {
            return importance != o.importance ? importance < o.importance : node > o.node;
        }
    };
    const auto& nodes = tree.nodes();
    std::priority_queue<Entry> inner;
    const auto add = [&](int32_t i) {
        if (nodes[i].isLeaf()) {
            cut.push_back(i);
            return;
        }
        if (importanceEvaluations) ++*importanceEvaluations;
        double value = importance(i);
        if (!(value >= 0.0)) value = std::numeric_limits<double>::infinity();  // NaN: refine first
        inner.push({value, i});
    };
    add(tree.root());
    while (!inner.empty() && cut.size() + inner.size() < std::max<uint32_t>(cutSize, 1u)) {
        const int32_t i = inner.top().node;
        inner.pop();
        add(nodes[i].left);
        add(nodes[i].right);
    }
    while (!inner.empty()) {
        cut.push_back(inner.top().node);
        inner.pop();
    }
    return cut;
}

// One leaf under `node`, drawn by importance; returns the leaf's node index and
// sets `probability` to P(leaf | node).
template <class Importance>
int32_t stochasticDescent(const LightTree& tree, int32_t node, Rng& rng, Importance&& importance, double& probability,
                          uint32_t* importanceEvaluations = nullptr) {
    const auto& nodes = tree.nodes();
    probability = 1.0;
    while (!nodes[node].isLeaf()) {
        const LightTreeNode& n = nodes[node];
        // The next level's nodes (both cache lines of each), while this level's
        // importances are computed: a descent is a chain of cache misses otherwise.
        const auto prefetch = [&](int32_t i) {
            const char* p = reinterpret_cast<const char*>(&nodes[i]);
            __builtin_prefetch(p);
            __builtin_prefetch(p + sizeof(LightTreeNode) - 1);
        };
        for (const int32_t child : {n.left, n.right})
            if (!nodes[child].isLeaf()) prefetch(nodes[child].left), prefetch(nodes[child].right);
        const double pl = leftProbability(importance(n.left), importance(n.right), nodes[n.left], nodes[n.right]);
        if (importanceEvaluations) *importanceEvaluations += 2;
        if (rng.nextDouble() < pl) {
            probability *= pl;
            node = n.left;
        } else {
            probability *= 1.0 - pl;
            node = n.right;
        }
    }
    return node;
}

// The stochastic cut estimate: sum over the cut of leafEstimate(leaf node, rng) / P.
// `leafEstimate`: Rgb(int32_t leafNode, Rng&).
template <class Importance, class LeafEstimate>
Rgb stochasticCutEstimate(const LightTree& tree, uint32_t cutSize, Rng& rng, CutStatistics& statistics,
                          Importance&& importance, LeafEstimate&& leafEstimate) {
    Rgb total(0.0f);
    uint32_t evaluations = 0;
    const std::vector<int32_t> cut = stochasticCut(tree, cutSize, importance, &evaluations);
    for (const int32_t c : cut) {
        double probability = 1.0;
        const int32_t leaf = stochasticDescent(tree, c, rng, importance, probability, &evaluations);
        // probability > 0 by construction: a branch of probability 0 is never taken
        // (rng.nextDouble() < 1 and a zero left probability sends every draw right).
        total += leafEstimate(leaf, rng) * float(1.0 / probability);
        ++statistics.evaluated;
    }
    statistics.cutSize += uint32_t(cut.size());
    statistics.importanceEvaluations += evaluations;
    return total;
}

// For tests: P(k) of every leaf k (indexed by VRL, i.e. leaf node) over the cut
// chosen by `importance`: each leaf's probability of being drawn by its cut node's
// descent (1 for a leaf in the cut). They sum to the cut's size.
template <class Importance>
std::vector<double> stochasticLeafProbabilities(const LightTree& tree, uint32_t cutSize, Importance&& importance) {
    std::vector<double> p(tree.vrls().size(), 0.0);
    const auto& nodes = tree.nodes();
    std::vector<std::pair<int32_t, double>> stack;
    for (const int32_t c : stochasticCut(tree, cutSize, importance)) {
        stack.push_back({c, 1.0});
        while (!stack.empty()) {
            const auto [i, q] = stack.back();
            stack.pop_back();
            if (nodes[i].isLeaf()) {
                p[size_t(i)] += q;
                continue;
            }
            const double pl = leftProbability(importance(nodes[i].left), importance(nodes[i].right),
                                              nodes[nodes[i].left], nodes[nodes[i].right]);
            stack.push_back({nodes[i].left, q * pl});
            stack.push_back({nodes[i].right, q * (1.0 - pl)});
        }
    }
    return p;
}

}  // namespace vrl
