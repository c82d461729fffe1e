#include "render/lightcuts/light_tree.h"

#include "render/core/rng.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace vrl {

namespace {

Imath::Box3f segmentBox(const Vrl& v) {
    Imath::Box3f box(v.origin);
    box.extendBy(v.end());
    return box;
}

// Joins two nodes into a new inner node (not yet placed).
LightTreeNode joinNodes(const LightTreeNode& a, int32_t aIndex, const LightTreeNode& b, int32_t bIndex,
                        const std::vector<Vrl>& vrls, const LightTreeSettings& settings) {
    const uint64_t seed = settings.seed;
    LightTreeNode n;
    n.box = a.box;
    n.box.extendBy(b.box);
    n.fluxLength = a.fluxLength + b.fluxLength;
    n.maxLength = std::max(a.maxLength, b.maxLength);
    n.vrlCount = a.vrlCount + b.vrlCount;
    n.left = aIndex;
    n.right = bIndex;
    n.medium = a.medium == b.medium ? a.medium : -1;
    const float wa = luminance(a.fluxLength), wb = luminance(b.fluxLength);
    Rng rng(seed, Rng::combine(a.representative, b.representative));
    const float pa = wa + wb > 0.0f ? wa / (wa + wb) : 0.5f;
    n.representative = rng.next() < pa ? a.representative : b.representative;
    const float repLength = vrls[n.representative].length;
    if (settings.points)
        n.clusterFlux = n.fluxLength;
    else
        n.clusterFlux = repLength > 0.0f ? n.fluxLength / repLength : Rgb(0.0f);
    return n;
}

// Agglomerative clustering (Walter et al. 2008's greedy rule: always merge the
// pair of least cost) of `inputs` (node indices), appending inner nodes to `out`.
// Nodes are looked up via `lookup(index)`; new nodes get indices
// `firstNewIndex + k`. Returns the root.
//
// The cost (I_a + I_b) diag(a u b)^2 is reducible: a merged cluster costs at least
// as much with any third cluster as either part did. So the nearest-neighbour
// chain algorithm yields exactly the greedy hierarchy, with about 2-3 best-partner
// scans per cluster instead of a heap's repeated rescans of stale entries.
// Clusters have stable ids; their boxes and weights live in dense
// structure-of-arrays over the live clusters, so each scan is one branch-free,
// vectorised pass.
template <class Lookup>
int32_t agglomerate(const std::vector<int32_t>& inputs, Lookup&& lookup, int32_t firstNewIndex,
                    std::vector<LightTreeNode>& out, const std::vector<Vrl>& vrls, const LightTreeSettings& settings) {
    const size_t n = inputs.size();
    if (n == 0) return -1;
    if (n == 1) return inputs[0];
    std::vector<float> minX(n), minY(n), minZ(n), maxX(n), maxY(n), maxZ(n), weight(n), costs(n);
    std::vector<uint32_t> idAt(n), positionOf(n);
    std::vector<int32_t> node(inputs);  // by id
    std::vector<char> inChain(n, 0);    // by id
    size_t live = n;
    const auto load = [&](size_t pos, const LightTreeNode& c) {
        minX[pos] = c.box.min.x, minY[pos] = c.box.min.y, minZ[pos] = c.box.min.z;
        maxX[pos] = c.box.max.x, maxY[pos] = c.box.max.y, maxZ[pos] = c.box.max.z;
        weight[pos] = luminance(c.fluxLength);
    };
    for (size_t i = 0; i < n; ++i) {
        idAt[i] = positionOf[i] = uint32_t(i);
        load(i, lookup(node[i]));
    }
    // Position of the least-cost partner of the cluster at position p; ties go to
    // `preferred` (the previous chain element), which guarantees termination.
    const auto nearest = [&](size_t p, size_t preferred) {
        const float ax0 = minX[p], ay0 = minY[p], az0 = minZ[p], ax1 = maxX[p], ay1 = maxY[p], az1 = maxZ[p];
        const float w = weight[p];
        for (size_t q = 0; q < live; ++q) {
            const float dx = std::max(ax1, maxX[q]) - std::min(ax0, minX[q]);
            const float dy = std::max(ay1, maxY[q]) - std::min(ay0, minY[q]);
            const float dz = std::max(az1, maxZ[q]) - std::min(az0, minZ[q]);
            costs[q] = (w + weight[q]) * (dx * dx + dy * dy + dz * dz);
        }
        costs[p] = std::numeric_limits<float>::infinity();
        // Start from another live cluster: with overflowing (infinite) costs every
        // cluster must still get a partner.
        size_t best = preferred < live ? preferred : (p == 0 ? 1 : 0);
        for (size_t q = 0; q < live; ++q) {
            if (costs[q] < costs[best]) best = q;
        }
        return best;
    };
    std::vector<uint32_t> chain;
    int32_t root = -1;
    while (live > 1) {
        if (chain.empty()) {
            chain.push_back(idAt[0]);
            inChain[idAt[0]] = 1;
        }
        const uint32_t a = chain.back();
        const uint32_t previous = chain.size() >= 2 ? chain[chain.size() - 2] : uint32_t(n);
        const size_t preferred = previous < n ? positionOf[previous] : size_t(-1);
        const uint32_t b = idAt[nearest(positionOf[a], preferred)];
        if (b != previous && !inChain[b]) {  // (inChain[b]: only with NaN costs; merge instead of cycling)
            chain.push_back(b);
            inChain[b] = 1;
            continue;
        }
        const uint32_t partner = previous < n ? previous : b;
        // Merge a and its partner: the result keeps id a, the partner's slot is refilled.
        chain.pop_back();
        inChain[a] = 0;
        if (partner == previous) {
            chain.pop_back();
            inChain[partner] = 0;
        }
        const int32_t index = firstNewIndex + int32_t(out.size());
        out.push_back(joinNodes(lookup(node[a]), node[a], lookup(node[partner]), node[partner], vrls, settings));
        node[a] = index;
        load(positionOf[a], out.back());
        const size_t hole = positionOf[partner], last = live - 1;
        if (hole != last) {
            const uint32_t moved = idAt[last];
            minX[hole] = minX[last], minY[hole] = minY[last], minZ[hole] = minZ[last];
            maxX[hole] = maxX[last], maxY[hole] = maxY[last], maxZ[hole] = maxZ[last];
            weight[hole] = weight[last];
            idAt[hole] = moved;
            positionOf[moved] = uint32_t(hole);
        }
        --live;
        root = index;
    }
    return root;
}

struct Partitioner {
    const std::vector<Vrl>& vrls;
    const std::vector<Vec3>& centroids;
    uint32_t partitionSize;

    // Splits order[begin, end) recursively; appends [begin, end) ranges of final
    // partitions to `out` in a deterministic order.
    void split(std::vector<uint32_t>& order, size_t begin, size_t end, std::vector<std::pair<size_t, size_t>>& out) const {
        if (end - begin <= partitionSize) {
            out.emplace_back(begin, end);
            return;
        }
        const size_t mid = begin + (end - begin) / 2;
        int bestAxis = 0;
        float bestOverlap = std::numeric_limits<float>::infinity(), bestExtent = -1.0f;
        std::vector<uint32_t> candidate;
        for (int axis = 0; axis < 3; ++axis) {
            candidate.assign(order.begin() + begin, order.begin() + end);
            medianSplit(candidate, axis);
            Imath::Box3f lo, hi, all;
            for (size_t k = 0; k < candidate.size(); ++k) (k < mid - begin ? lo : hi).extendBy(segmentBox(vrls[candidate[k]]));
            all = lo;
            all.extendBy(hi);
            Imath::Box3f overlap(Imath::V3f(std::max(lo.min.x, hi.min.x), std::max(lo.min.y, hi.min.y), std::max(lo.min.z, hi.min.z)),
                                 Imath::V3f(std::min(lo.max.x, hi.max.x), std::min(lo.max.y, hi.max.y), std::min(lo.max.z, hi.max.z)));
            const Imath::V3f size = overlap.max - overlap.min;
            const float volume = overlap.isEmpty() ? 0.0f : std::max(0.0f, size.x) * std::max(0.0f, size.y) * std::max(0.0f, size.z);
            const float extent = all.max[axis] - all.min[axis];
            if (volume < bestOverlap || (volume == bestOverlap && extent > bestExtent)) {
                bestOverlap = volume, bestExtent = extent, bestAxis = axis;
            }
        }
        candidate.assign(order.begin() + begin, order.begin() + end);
        medianSplit(candidate, bestAxis);
        std::copy(candidate.begin(), candidate.end(), order.begin() + begin);
        std::vector<std::pair<size_t, size_t>> left, right;
        if (end - begin > 16 * size_t(partitionSize)) {
            tbb::parallel_invoke([&] { split(order, begin, mid, left); }, [&] { split(order, mid, end, right); });
        } else {
            split(order, begin, mid, left);
            split(order, mid, end, right);
        }
        out.insert(out.end(), left.begin(), left.end());
        out.insert(out.end(), right.begin(), right.end());
    }

    void medianSplit(std::vector<uint32_t>& indices, int axis) const {
        const auto less = [&](uint32_t a, uint32_t b) {
            const float ca = centroids[a][axis], cb = centroids[b][axis];
            return ca != cb ? ca < cb : a < b;  // ties by index: deterministic
        };
        std::nth_element(indices.begin(), indices.begin() + indices.size() / 2, indices.end(), less);
    }
};

}  // namespace

LightTree LightTree::build(std::vector<Vrl> vrls, const LightTreeSettings& settings) {
    LightTree tree;
    tree.vrls_ = std::move(vrls);
    const auto& v = tree.vrls_;
    const size_t count = v.size();
    if (count == 0) return tree;
    if (count >= (size_t(1) << 30)) throw std::invalid_argument("light tree: too many VRLs (" + std::to_string(count) + ")");
    tree.nodes_.resize(count);
    std::vector<Vec3> centroids(count);
    tbb::parallel_for(size_t(0), count, [&](size_t i) {
        LightTreeNode& leaf = tree.nodes_[i];
        leaf.box = segmentBox(v[i]);
        leaf.fluxLength = settings.points ? v[i].flux : v[i].flux * v[i].length;
        leaf.clusterFlux = v[i].flux;
        leaf.maxLength = v[i].length;
        leaf.representative = uint32_t(i);
        leaf.vrlCount = 1;
        leaf.medium = v[i].medium;
        centroids[i] = (v[i].origin + v[i].end()) * 0.5f;
    });

    // 1. Median splits into partitions.
    std::vector<uint32_t> order(count);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<std::pair<size_t, size_t>> partitions;
    Partitioner{v, centroids, std::max<uint32_t>(2, settings.partitionSize)}.split(order, 0, count, partitions);

    // 2. Agglomerative clustering inside each partition, in parallel into local arrays.
    std::vector<std::vector<LightTreeNode>> local(partitions.size());
    std::vector<int32_t> localRoot(partitions.size());
    const int32_t localBase = int32_t(count);  // local inner node k is encoded as count + k
    tbb::parallel_for(size_t(0), partitions.size(), [&](size_t p) {
        const auto [begin, end] = partitions[p];
        std::vector<int32_t> inputs(order.begin() + begin, order.begin() + end);
        auto& out = local[p];
        out.reserve(inputs.size());
        localRoot[p] = agglomerate(
            inputs, [&](int32_t i) -> const LightTreeNode& { return i < localBase ? tree.nodes_[i] : out[i - localBase]; },
            localBase, out, v, settings);
    });
    // Append partitions in order, remapping local indices to global ones.
    std::vector<int32_t> roots;
    for (size_t p = 0; p < partitions.size(); ++p) {
        const int32_t base = int32_t(tree.nodes_.size());
        const auto remap = [&](int32_t i) { return i < localBase ? i : base + (i - localBase); };
        for (LightTreeNode node : local[p]) {
            node.left = remap(node.left);
            node.right = remap(node.right);
            tree.nodes_.push_back(node);
        }
        roots.push_back(remap(localRoot[p]));
        local[p] = {};
    }
    // 3. Merge the partition roots by the same rule.
    std::vector<LightTreeNode> top;
    const int32_t topBase = int32_t(tree.nodes_.size());
    const int32_t root = agglomerate(
        roots, [&](int32_t i) -> const LightTreeNode& { return i < topBase ? tree.nodes_[i] : top[i - topBase]; },
        topBase, top, v, settings);
    tree.nodes_.insert(tree.nodes_.end(), top.begin(), top.end());
    tree.root_ = root;
    tree.nodes_.shrink_to_fit();
    return tree;
}

LightTree LightTree::fromParts(std::vector<Vrl> vrls, std::vector<LightTreeNode> nodes, int32_t root) {
    LightTree tree;
    const size_t count = vrls.size();
    if (count == 0) {
        if (!nodes.empty() || root != -1) throw std::invalid_argument("light tree: nodes without VRLs");
        return tree;
    }
    if (nodes.size() != 2 * count - 1) {
        throw std::invalid_argument("light tree: " + std::to_string(nodes.size()) + " nodes for " +
                                    std::to_string(count) + " VRLs (expected " + std::to_string(2 * count - 1) + ")");
    }
    if (root < 0 || size_t(root) >= nodes.size()) throw std::invalid_argument("light tree: root index out of range");
    // Every node reachable exactly once from the root, leaves are the first `count` nodes.
    std::vector<char> seen(nodes.size(), 0);
    std::vector<int32_t> stack{root};
    while (!stack.empty()) {
        const int32_t i = stack.back();
        stack.pop_back();
        if (seen[i]) throw std::invalid_argument("light tree: node " + std::to_string(i) + " is reached twice");
        seen[i] = 1;
        const LightTreeNode& n = nodes[i];
        if (n.representative >= count) throw std::invalid_argument("light tree: representative out of range");
        const bool leaf = size_t(i) < count;
        if (leaf != n.isLeaf() || (leaf && n.right >= 0))
            throw std::invalid_argument("light tree: node " + std::to_string(i) + " has the wrong kind");
        if (leaf) {
            if (n.representative != uint32_t(i) || n.vrlCount != 1)
                throw std::invalid_argument("light tree: leaf " + std::to_string(i) + " does not stand for VRL " +
                                            std::to_string(i));
            continue;
        }
        for (int32_t c : {n.left, n.right}) {
            if (c < 0 || size_t(c) >= nodes.size()) throw std::invalid_argument("light tree: child index out of range");
            stack.push_back(c);
        }
        const LightTreeNode& l = nodes[n.left];
        const LightTreeNode& r = nodes[n.right];
        if (n.vrlCount != l.vrlCount + r.vrlCount ||
            (n.representative != l.representative && n.representative != r.representative))
            throw std::invalid_argument("light tree: node " + std::to_string(i) +
                                        " disagrees with its children (count or representative)");
    }
    if (std::find(seen.begin(), seen.end(), 0) != seen.end())
        throw std::invalid_argument("light tree: some nodes are not reachable from the root");
    tree.vrls_ = std::move(vrls);
    tree.nodes_ = std::move(nodes);
    tree.root_ = root;
    return tree;
}

}  // namespace vrl
