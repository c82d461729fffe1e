#include "render/lightcuts/tree/light_tree.h"

#include "render/core/rng.h"
#include "render/core/timing.h"

#include <spdlog/spdlog.h>
#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace vrl {

namespace {

Imath::Box3f segmentBox(const Vrl& v) {
    Imath::Box3f box(v.origin);
    box.extendBy(v.end());
    return box;
}

// Joins two nodes into a new inner node (not yet placed). `aLength` and
// `bLength`: the lengths of their representatives.
LightTreeNode joinNodes(const LightTreeNode& a, int32_t aIndex, float aLength, const LightTreeNode& b, int32_t bIndex,
                        float bLength, const LightTreeSettings& settings) {
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
    const bool fromA = rng.next() < pa;
    n.representative = fromA ? a.representative : b.representative;
    const float repLength = fromA ? aLength : bLength;
    if (settings.points)
        n.clusterFlux = n.fluxLength;
    else
        n.clusterFlux = repLength > 0.0f ? n.fluxLength / repLength : Rgb(0.0f);
    return n;
}

// Sizes `v` to `n` elements, asking first for transparent huge pages over
// it: at 10^7 VRLs the build's buffers span about 2 GB, and faulting them in
// 4 KiB pages costs seconds on virtual machines.
template <class T>
void allocateHugePaged(std::vector<T>& v, size_t n) {
    v.reserve(n);
#ifdef MADV_HUGEPAGE
    constexpr uintptr_t kPage = 4096;
    const uintptr_t first = (reinterpret_cast<uintptr_t>(v.data()) + kPage - 1) & ~(kPage - 1);
    const uintptr_t last = (reinterpret_cast<uintptr_t>(v.data() + n)) & ~(kPage - 1);
    if (last > first + (uintptr_t(1) << 21)) madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);  // a hint only
#endif
    v.resize(n);
}

// Four floats (or ints) in one SSE/NEON register: GCC and Clang vector
// extensions, so that the partner search keeps its argmin in lanes (a float
// min reduction does not vectorise without -ffast-math).
using Float4 = float __attribute__((vector_size(16)));
using Int4 = int32_t __attribute__((vector_size(16)));

template <class V, class T>
V broadcastAs(T x) {
    return V{x, x, x, x};
}
inline Float4 broadcast(float x) { return broadcastAs<Float4>(x); }
inline Int4 broadcast(int32_t x) { return broadcastAs<Int4>(x); }
inline Float4 load4(const float* p) {
    Float4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
// std::max and std::min lane-wise, NaN handling included (maxps and minps).
inline Float4 max4(Float4 a, Float4 b) { return a < b ? b : a; }
inline Float4 min4(Float4 a, Float4 b) { return b < a ? b : a; }

// Agglomerative clustering (Walter et al. 2008's greedy rule: always merge the
// pair of least cost) of `inputs` (indices into `nodes`): the inputs.size() - 1
// inner nodes go to nodes[firstNewIndex ...], in merge order. Returns the root.
// Builds over disjoint inputs may run concurrently: each writes its own range.
//
// The cost (I_a + I_b) diag(a u b)^2 is reducible: a merged cluster costs at least
// as much with any third cluster as either part did. So the nearest-neighbour
// chain algorithm yields exactly the greedy hierarchy, with about 2-3 best-partner
// scans per cluster instead of a heap's repeated rescans of stale entries.
// Clusters have stable ids; their boxes and weights live in dense
// structure-of-arrays over the live clusters, so each scan is one branch-free,
// vectorised pass.
int32_t agglomerate(std::vector<int32_t> inputs, std::vector<LightTreeNode>& nodes, int32_t firstNewIndex,
                    const std::vector<Vrl>& vrls, const LightTreeSettings& settings) {
    const size_t n = inputs.size();
    if (n == 0) return -1;
    if (n == 1) return inputs[0];
    std::vector<float> minX(n), minY(n), minZ(n), maxX(n), maxY(n), maxZ(n), weight(n);
    std::vector<uint32_t> idAt(n), positionOf(n);
    std::vector<int32_t> node(std::move(inputs));  // by id
    std::vector<float> repLength(n);                // by id: the length of the node's representative
    std::vector<char> inChain(n, 0);    // by id
    size_t live = n;
    const auto load = [&](size_t pos, const LightTreeNode& c) {
        minX[pos] = c.box.min.x, minY[pos] = c.box.min.y, minZ[pos] = c.box.min.z;
        maxX[pos] = c.box.max.x, maxY[pos] = c.box.max.y, maxZ[pos] = c.box.max.z;
        weight[pos] = luminance(c.fluxLength);
    };
    for (size_t i = 0; i < n; ++i) {
        idAt[i] = positionOf[i] = uint32_t(i);
        const LightTreeNode& c = nodes[size_t(node[i])];
        load(i, c);
        repLength[i] = c.isLeaf() ? c.maxLength : vrls[c.representative].length;
    }
    // Position of the least-cost partner of the cluster at position p: the
    // first of least cost if that is below the cost with `start`, else `start`
    // (NaN costs never win). `start` is `preferred` (the previous chain
    // element, which guarantees termination) or another live cluster (with
    // overflowing, infinite costs every cluster must still get a partner).
    const auto cost = [&](size_t p, size_t q) {
        const float dx = std::max(maxX[p], maxX[q]) - std::min(minX[p], minX[q]);
        const float dy = std::max(maxY[p], maxY[q]) - std::min(minY[p], minY[q]);
        const float dz = std::max(maxZ[p], maxZ[q]) - std::min(minZ[p], minZ[q]);
        return (weight[p] + weight[q]) * (dx * dx + dy * dy + dz * dz);
    };
    const auto nearest = [&](size_t p, size_t preferred) {
        const size_t start = preferred < live ? preferred : (p == 0 ? 1 : 0);
        // Four lanes, each keeping the first position of its least cost.
        const Float4 ax0 = broadcast(minX[p]), ay0 = broadcast(minY[p]), az0 = broadcast(minZ[p]);
        const Float4 ax1 = broadcast(maxX[p]), ay1 = broadcast(maxY[p]), az1 = broadcast(maxZ[p]);
        const Float4 w = broadcast(weight[p]), infinity = broadcast(std::numeric_limits<float>::infinity());
        const Int4 self = broadcast(int32_t(p)), step = broadcast(int32_t(4));
        Float4 least = broadcast(cost(p, start));
        Int4 where = broadcast(int32_t(start)), position = {0, 1, 2, 3};
        size_t q = 0;
        for (; q + 4 <= live; q += 4, position += step) {
            const Float4 dx = max4(ax1, load4(&maxX[q])) - min4(ax0, load4(&minX[q]));
            const Float4 dy = max4(ay1, load4(&maxY[q])) - min4(ay0, load4(&minY[q]));
            const Float4 dz = max4(az1, load4(&maxZ[q])) - min4(az0, load4(&minZ[q]));
            const Float4 c = position == self ? infinity : (w + load4(&weight[q])) * (dx * dx + dy * dy + dz * dz);
            const Int4 better = c < least;
            least = better ? c : least;
            where = better ? position : where;
        }
        float bestCost = least[0];
        size_t best = size_t(where[0]);
        for (int j = 1; j < 4; ++j) {
            if (least[j] < bestCost || (least[j] == bestCost && size_t(where[j]) < best)) bestCost = least[j], best = size_t(where[j]);
        }
        for (; q < live; ++q) {
            if (q == p) continue;
            const float c = cost(p, q);
            if (c < bestCost) bestCost = c, best = q;
        }
        return best;
    };
    std::vector<uint32_t> chain;
    int32_t root = -1, index = firstNewIndex;
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
        LightTreeNode& joined = nodes[size_t(index)];
        joined = joinNodes(nodes[size_t(node[a])], node[a], repLength[a], nodes[size_t(node[partner])], node[partner],
                           repLength[partner], settings);
        repLength[a] = joined.representative == nodes[size_t(node[a])].representative ? repLength[a] : repLength[partner];
        node[a] = index;
        load(positionOf[a], joined);
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
        root = index++;
    }
    return root;
}

// A VRL as the median splits see it, packed so that the splits stream through
// memory instead of chasing VRL indices: its segment's box (whose centre is the
// segment's midpoint, the split key) and its index.
struct SplitItem {
    Imath::V3f min, max;
    uint32_t vrl;

    // Bit for bit (origin + end) * 0.5: min + max adds the same two numbers.
    float centroid(int axis) const { return (min[axis] + max[axis]) * 0.5f; }
};

// The split key along one axis; ties by VRL index, so the order is total and
// the median split deterministic.
struct SplitKey {
    float centroid;
    uint32_t vrl;

    bool operator<(const SplitKey& o) const { return centroid != o.centroid ? centroid < o.centroid : vrl < o.vrl; }
};

// Below this many VRLs a pass over a range runs on one thread.
constexpr size_t kParallelPass = size_t(1) << 16;

struct Partitioner {
    uint32_t partitionSize;

    // Splits items[begin, end) recursively; appends [begin, end) ranges of final
    // partitions to `out` in a deterministic order.
    void split(std::vector<SplitItem>& items, size_t begin, size_t end, std::vector<std::pair<size_t, size_t>>& out) const {
        if (end - begin <= partitionSize) {
            out.emplace_back(begin, end);
            return;
        }
        const size_t mid = begin + (end - begin) / 2;
        const int axis = bestAxis(items, begin, end, mid);
        const auto less = [axis](const SplitItem& a, const SplitItem& b) {
            return SplitKey{a.centroid(axis), a.vrl} < SplitKey{b.centroid(axis), b.vrl};
        };
        std::nth_element(items.begin() + ptrdiff_t(begin), items.begin() + ptrdiff_t(mid), items.begin() + ptrdiff_t(end), less);
        std::vector<std::pair<size_t, size_t>> left, right;
        if (end - begin > 16 * size_t(partitionSize)) {
            tbb::parallel_invoke([&] { split(items, begin, mid, left); }, [&] { split(items, mid, end, right); });
        } else {
            split(items, begin, mid, left);
            split(items, mid, end, right);
        }
        out.insert(out.end(), left.begin(), left.end());
        out.insert(out.end(), right.begin(), right.end());
    }

    // The axis whose median split gives child boxes that overlap least (ties:
    // the longer extent). The lower half along an axis is every item whose key
    // is below the median key, so the three candidate splits cost a few passes
    // over the items and no reordering.
    static int bestAxis(const std::vector<SplitItem>& items, size_t begin, size_t end, size_t mid) {
        const std::array<SplitKey, 3> medians = medianKeys(items, begin, end, mid - begin);
        const std::array<Halves, 3> halves = halfBoxes(items, begin, end, medians);
        int best = 0;
        float bestOverlap = std::numeric_limits<float>::infinity(), bestExtent = -1.0f;
        for (int axis = 0; axis < 3; ++axis) {
            const auto& [lo, hi] = halves[size_t(axis)];
            Imath::Box3f all = lo;
            all.extendBy(hi);
            Imath::Box3f overlap(Imath::V3f(std::max(lo.min.x, hi.min.x), std::max(lo.min.y, hi.min.y), std::max(lo.min.z, hi.min.z)),
                                 Imath::V3f(std::min(lo.max.x, hi.max.x), std::min(lo.max.y, hi.max.y), std::min(lo.max.z, hi.max.z)));
            const Imath::V3f size = overlap.max - overlap.min;
            const float volume = overlap.isEmpty() ? 0.0f : std::max(0.0f, size.x) * std::max(0.0f, size.y) * std::max(0.0f, size.z);
            const float extent = all.max[axis] - all.min[axis];
            if (volume < bestOverlap || (volume == bestOverlap && extent > bestExtent)) {
                bestOverlap = volume, bestExtent = extent, best = axis;
            }
        }
        return best;
    }

    // The key of rank `rank` along each axis, by histogram selection: the
    // centroids' range in kBins bins (monotonic in the key), the bin holding
    // the rank, then a selection among that bin's keys only. Counts and
    // min/max are exact in any order, so the parallel passes are deterministic.
    static constexpr size_t kBins = 1024;
    using Histogram = std::vector<uint32_t>;  // 3 x kBins counts

    static std::array<SplitKey, 3> medianKeys(const std::vector<SplitItem>& items, size_t begin, size_t end, size_t rank) {
        using Range = std::array<float, 6>;  // lowest x, y, z centroid, then highest
        const float inf = std::numeric_limits<float>::infinity();
        const Range range = reduce(
            begin, end, Range{inf, inf, inf, -inf, -inf, -inf},
            [&](size_t k0, size_t k1, Range r) {
                for (size_t k = k0; k < k1; ++k) {
                    for (int a = 0; a < 3; ++a) {
                        const float c = items[k].centroid(a);
                        r[size_t(a)] = std::min(r[size_t(a)], c), r[size_t(a) + 3] = std::max(r[size_t(a) + 3], c);
                    }
                }
                return r;
            },
            [](Range a, const Range& b) {
                for (size_t i = 0; i < 3; ++i) a[i] = std::min(a[i], b[i]), a[i + 3] = std::max(a[i + 3], b[i + 3]);
                return a;
            });
        std::array<float, 3> scale{};
        for (size_t a = 0; a < 3; ++a) scale[a] = range[a + 3] > range[a] ? float(kBins) / (range[a + 3] - range[a]) : 0.0f;
        const auto bin = [&](float c, size_t a) {
            const float x = (c - range[a]) * scale[a];
            return !(x >= 0.0f) ? size_t(0) : x >= float(kBins) ? kBins - 1 : size_t(x);  // NaN: bin 0
        };
        const Histogram counts = reduce(
            begin, end, Histogram(3 * kBins, 0),
            [&](size_t k0, size_t k1, Histogram h) {
                for (size_t k = k0; k < k1; ++k) {
                    for (size_t a = 0; a < 3; ++a) ++h[a * kBins + bin(items[k].centroid(int(a)), a)];
                }
                return h;
            },
            [](Histogram a, const Histogram& b) {
                for (size_t i = 0; i < a.size(); ++i) a[i] += b[i];
                return a;
            });
        std::array<SplitKey, 3> medians;
        for (size_t a = 0; a < 3; ++a) {
            size_t target = 0, below = 0;
            while (below + counts[a * kBins + target] <= rank) below += counts[a * kBins + target++];
            std::vector<SplitKey> keys;
            keys.reserve(counts[a * kBins + target]);
            for (size_t k = begin; k < end; ++k) {
                const float c = items[k].centroid(int(a));
                if (bin(c, a) == target) keys.push_back({c, items[k].vrl});
            }
            std::nth_element(keys.begin(), keys.begin() + ptrdiff_t(rank - below), keys.end());
            medians[a] = keys[rank - below];
        }
        return medians;
    }

    // Boxes of the items below the median key along each axis and of the others.
    using Halves = std::pair<Imath::Box3f, Imath::Box3f>;
    static std::array<Halves, 3> halfBoxes(const std::vector<SplitItem>& items, size_t begin, size_t end,
                                           const std::array<SplitKey, 3>& medians) {
        using AllHalves = std::array<Halves, 3>;
        return reduce(
            begin, end, AllHalves{},
            [&](size_t k0, size_t k1, AllHalves h) {
                for (size_t k = k0; k < k1; ++k) {
                    const SplitItem& item = items[k];
                    const Imath::Box3f box(item.min, item.max);
                    for (int a = 0; a < 3; ++a) {
                        Halves& axis = h[size_t(a)];
                        (SplitKey{item.centroid(a), item.vrl} < medians[size_t(a)] ? axis.first : axis.second).extendBy(box);
                    }
                }
                return h;
            },
            [](AllHalves a, const AllHalves& b) {
                for (size_t i = 0; i < 3; ++i) a[i].first.extendBy(b[i].first), a[i].second.extendBy(b[i].second);
                return a;
            });
    }

    // A reduction over [begin, end): in parallel above kParallelPass items.
    template <class T, class Body, class Join>
    static T reduce(size_t begin, size_t end, T identity, Body&& body, Join&& join) {
        if (end - begin < kParallelPass) return body(begin, end, std::move(identity));
        return tbb::parallel_reduce(
            tbb::blocked_range<size_t>(begin, end, kParallelPass / 4), identity,
            [&](const tbb::blocked_range<size_t>& r, T value) { return body(r.begin(), r.end(), std::move(value)); }, join);
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
    const auto start = std::chrono::steady_clock::now();
    // Every node in place from the start: leaves, then each partition's inner
    // nodes, then those above the partitions (2N - 1 in all).
    auto& nodes = tree.nodes_;
    std::vector<SplitItem> items;
    allocateHugePaged(nodes, 2 * count - 1);
    allocateHugePaged(items, count);
    tbb::parallel_for(size_t(0), count, [&](size_t i) {
        LightTreeNode& leaf = nodes[i];
        leaf.box = segmentBox(v[i]);
        leaf.fluxLength = settings.points ? v[i].flux : v[i].flux * v[i].length;
        leaf.clusterFlux = v[i].flux;
        leaf.maxLength = v[i].length;
        leaf.representative = uint32_t(i);
        leaf.vrlCount = 1;
        leaf.medium = v[i].medium;
        items[i] = {leaf.box.min, leaf.box.max, uint32_t(i)};
    });

    // 1. Median splits into partitions.
    std::vector<std::pair<size_t, size_t>> partitions;
    Partitioner{std::max<uint32_t>(2, settings.partitionSize)}.split(items, 0, count, partitions);
    const double splitSeconds = secondsSince(start);

    // 2. Agglomerative clustering inside each partition, in parallel, each into
    // its own range of inner nodes (offsets in partition order: deterministic).
    std::vector<int32_t> firstInner(partitions.size()), roots(partitions.size());
    int32_t next = int32_t(count);
    for (size_t p = 0; p < partitions.size(); ++p) {
        firstInner[p] = next;
        next += int32_t(partitions[p].second - partitions[p].first) - 1;
    }
    tbb::parallel_for(size_t(0), partitions.size(), [&](size_t p) {
        const auto [begin, end] = partitions[p];
        std::vector<int32_t> inputs(end - begin);
        for (size_t k = begin; k < end; ++k) inputs[k - begin] = int32_t(items[k].vrl);
        roots[p] = agglomerate(std::move(inputs), nodes, firstInner[p], v, settings);
    });
    items = {};
    const double clusterSeconds = secondsSince(start) - splitSeconds;

    // 3. Merge the partition roots by the same rule.
    tree.root_ = agglomerate(std::move(roots), nodes, next, v, settings);
    spdlog::debug("light tree: {} VRLs in {} partitions: median splits {:.2f} s, clustering {:.2f} s, merge of the roots {:.2f} s",
                  count, partitions.size(), splitSeconds, clusterSeconds, secondsSince(start) - splitSeconds - clusterSeconds);
    return tree;
}

size_t LightTree::buildScratchBytesPerVrl() {
    // The partitioning's packed boxes; a partition's clustering arrays are
    // O(partitionSize) per thread.
    return sizeof(SplitItem);
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
        // Cuts scale a parent's estimate by flux ratios (cut_walk.h): an inner node's
        // fluxes must be finite and non-negative.
        for (int c = 0; c < 3; ++c)
            if (!(n.clusterFlux[c] >= 0.0f && n.clusterFlux[c] < kInfinity && n.fluxLength[c] >= 0.0f &&
                  n.fluxLength[c] < kInfinity))
                throw std::invalid_argument("light tree: node " + std::to_string(i) +
                                            " has a negative or non-finite flux");
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
