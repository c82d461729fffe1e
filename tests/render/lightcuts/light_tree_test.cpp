// Light tree build (Vibert et al. 2019 §4, "Building the light tree"): the
// invariants every built tree must satisfy, for realistic VRL sets (light
// tracing) and random ones with degenerate cases (zero-length, identical,
// coplanar and collinear VRLs), for small partitions (many partitions and a
// top-level merge), the default partition size and the global agglomerative
// build; the merge rule and the partitions against a brute-force greedy
// reference; representatives drawn in proportion to luminance(flux x length)
// (binomial tests); determinism across thread counts and seeds; a bit-exact
// serialisation round trip; and the hybrid build's cost against the global one.
#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/light_tree_io.h"
#include "render/vrl/light_tracer.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace vrl {
namespace {

constexpr uint32_t kGlobal = 1u << 30;  // partitionSize >= N: the global agglomerative build

uint32_t bits(float f) { return std::bit_cast<uint32_t>(f); }
bool sameBits(const Imath::V3f& a, const Imath::V3f& b) {
    return bits(a.x) == bits(b.x) && bits(a.y) == bits(b.y) && bits(a.z) == bits(b.z);
}

// ---------------------------------------------------------------------------
// VRL sets

// Light-traced VRLs, traced once and shared by the tests. The lit room (an
// occluder, two lights, an HG medium): ~20k VRLs from 3600 paths.
const std::vector<Vrl>& litRoomVrls() {
    static const std::vector<Vrl> vrls = [] {
        const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.5f));
        LightTracingSettings settings;
        settings.lightPaths = 3600;
        settings.seed = 5;
        return traceVrls(*scene, settings).vrls;
    }();
    return vrls;
}

// The smoke room (walls, a sphere, a spot light): ~5k VRLs from 800 paths,
// small enough for the O(N^2) global build.
const std::vector<Vrl>& smokeRoomVrls() {
    static const std::vector<Vrl> vrls = [] {
        const auto scene = Scene::build(test::smallSmokeRoom());
        LightTracingSettings settings;
        settings.lightPaths = 800;
        settings.seed = 3;
        return traceVrls(*scene, settings).vrls;
    }();
    return vrls;
}

Vec3 randomDirection(Rng& rng) {
    for (;;) {
        const Vec3 d(2 * rng.next() - 1, 2 * rng.next() - 1, 2 * rng.next() - 1);
        const float l2 = d.length2();
        if (l2 > 1e-4f && l2 <= 1.0f) return d / std::sqrt(l2);
    }
}

enum class RandomKind { Mixed, Identical, Plane, Line, AllZeroLength, Scattered };

// `n` random VRLs of the given kind, from the stream (seed, kind).
// Scattered: in a box [-5, 5]^3, random directions, lengths in [0.01, 0.51],
// fluxes over three decades, three media. Mixed: the same with 10% of zero
// length, 5% black and 10% exact copies of earlier VRLs.
std::vector<Vrl> randomVrls(size_t n, RandomKind kind, uint64_t seed) {
    Rng rng(seed, uint64_t(kind));
    std::vector<Vrl> vrls;
    vrls.reserve(n);
    Vrl first;
    first.origin = {0.3f, -1.2f, 2.0f};
    first.direction = Vec3(1, 2, 2) / 3.0f;
    first.length = 0.7f;
    first.flux = {0.2f, 0.5f, 0.1f};
    first.medium = 1;
    for (size_t i = 0; i < n; ++i) {
        Vrl v;
        v.origin = {10 * rng.next() - 5, 10 * rng.next() - 5, 10 * rng.next() - 5};
        v.direction = randomDirection(rng);
        v.length = 0.01f + 0.5f * rng.next();
        const float scale = std::pow(10.0f, -3.0f * rng.next());
        v.flux = Rgb(rng.next(), rng.next(), rng.next()) * scale;
        v.medium = int32_t(rng.nextUint() % 3);
        switch (kind) {
        case RandomKind::Mixed: {
            const float u = rng.next();
            if (u < 0.1f) v.length = 0.0f;
            else if (u < 0.15f) v.flux = Rgb(0.0f);
            else if (u < 0.25f && !vrls.empty()) v = vrls[rng.nextUint() % vrls.size()];
            break;
        }
        case RandomKind::Identical: v = first; break;
        case RandomKind::Plane:  // z = 1.5, directions in the plane
            v.origin.z = 1.5f;
            v.direction.z = 0.0f;
            v.direction = v.direction.length2() > 0 ? v.direction.normalized() : Vec3(1, 0, 0);
            v.medium = 0;
            break;
        case RandomKind::Line:  // on the x axis, both directions
            v.origin = {v.origin.x, 0.0f, 0.0f};
            v.direction = {rng.next() < 0.5f ? -1.0f : 1.0f, 0.0f, 0.0f};
            v.medium = 2;
            break;
        case RandomKind::AllZeroLength: v.length = 0.0f; break;
        case RandomKind::Scattered: break;
        }
        vrls.push_back(v);
    }
    return vrls;
}

// ---------------------------------------------------------------------------
// Invariants. Each returns the first violation found, naming the node.

std::string at(size_t i) { return "node " + std::to_string(i) + ": "; }

// The VRLs are kept as given; 2N-1 nodes; node i < N is the leaf of VRL i;
// every node reached once from the root, every VRL in exactly one reachable
// leaf; inner vrlCount is the children's sum.
::testing::AssertionResult structureIsValid(const LightTree& tree, const std::vector<Vrl>& input) {
    const size_t n = input.size();
    const auto& vrls = tree.vrls();
    const auto& nodes = tree.nodes();
    if (vrls.size() != n) return ::testing::AssertionFailure() << vrls.size() << " VRLs for " << n << " given";
    for (size_t i = 0; i < n; ++i) {
        const Vrl &a = vrls[i], &b = input[i];
        if (!sameBits(a.origin, b.origin) || !sameBits(a.direction, b.direction) || bits(a.length) != bits(b.length) ||
            !sameBits(a.flux, b.flux) || a.medium != b.medium)
            return ::testing::AssertionFailure() << "VRL " << i << " differs from the input";
    }
    if (n == 0) {
        if (!nodes.empty() || tree.root() != -1 || !tree.empty())
            return ::testing::AssertionFailure() << "empty input but " << nodes.size() << " nodes, root " << tree.root();
        return ::testing::AssertionSuccess();
    }
    if (nodes.size() != 2 * n - 1)
        return ::testing::AssertionFailure() << nodes.size() << " nodes for " << n << " VRLs";
    if (tree.root() < 0 || size_t(tree.root()) >= nodes.size())
        return ::testing::AssertionFailure() << "root " << tree.root() << " out of range";
    for (size_t i = 0; i < n; ++i) {
        const LightTreeNode& leaf = nodes[i];
        if (!leaf.isLeaf() || leaf.right != -1 || leaf.representative != i || leaf.vrlCount != 1)
            return ::testing::AssertionFailure() << at(i) << "not the leaf of VRL " << i << " (left " << leaf.left
                                                 << ", right " << leaf.right << ", representative "
                                                 << leaf.representative << ", vrlCount " << leaf.vrlCount << ")";
    }
    std::vector<char> seen(nodes.size(), 0);
    std::vector<int32_t> stack{tree.root()};
    size_t leaves = 0;
    while (!stack.empty()) {
        const int32_t i = stack.back();
        stack.pop_back();
        if (i < 0 || size_t(i) >= nodes.size()) return ::testing::AssertionFailure() << "child index " << i << " out of range";
        if (seen[size_t(i)]) return ::testing::AssertionFailure() << at(size_t(i)) << "reached twice";
        seen[size_t(i)] = 1;
        const LightTreeNode& node = nodes[size_t(i)];
        if (size_t(i) < n) {
            ++leaves;
            continue;
        }
        if (node.isLeaf() || node.right < 0 || size_t(node.left) >= nodes.size() || size_t(node.right) >= nodes.size())
            return ::testing::AssertionFailure() << at(size_t(i)) << "inner node with children " << node.left << ", "
                                                 << node.right;
        const uint32_t sum = nodes[size_t(node.left)].vrlCount + nodes[size_t(node.right)].vrlCount;
        if (node.vrlCount != sum)
            return ::testing::AssertionFailure() << at(size_t(i)) << "vrlCount " << node.vrlCount << " != " << sum;
        stack.push_back(node.left);
        stack.push_back(node.right);
    }
    if (leaves != n) return ::testing::AssertionFailure() << leaves << " leaves reachable of " << n;
    const auto unreached = std::find(seen.begin(), seen.end(), 0);
    if (unreached != seen.end())
        return ::testing::AssertionFailure() << at(size_t(unreached - seen.begin())) << "not reachable from the root";
    if (nodes[size_t(tree.root())].vrlCount != n)
        return ::testing::AssertionFailure() << "root vrlCount " << nodes[size_t(tree.root())].vrlCount;
    return ::testing::AssertionSuccess();
}

bool contains(const Imath::Box3f& outer, const Imath::Box3f& inner) {
    return outer.min.x <= inner.min.x && outer.min.y <= inner.min.y && outer.min.z <= inner.min.z &&
           outer.max.x >= inner.max.x && outer.max.y >= inner.max.y && outer.max.z >= inner.max.z;
}

// Leaves bound both endpoints of their VRL; inner boxes bound their children's.
::testing::AssertionResult boxesAreNested(const LightTree& tree) {
    const auto& nodes = tree.nodes();
    for (size_t i = 0; i < nodes.size(); ++i) {
        const LightTreeNode& node = nodes[i];
        if (node.isLeaf()) {
            const Vrl& v = tree.vrls()[node.representative];
            if (!node.box.intersects(v.origin) || !node.box.intersects(v.end()))
                return ::testing::AssertionFailure() << at(i) << "leaf box misses an endpoint of its VRL";
        } else {
            for (int32_t c : {node.left, node.right})
                if (!contains(node.box, nodes[size_t(c)].box))
                    return ::testing::AssertionFailure() << at(i) << "box does not contain child " << c << "'s";
        }
    }
    return ::testing::AssertionSuccess();
}

bool closeRelative(double a, double b, double relative) {
    return std::abs(a - b) <= relative * std::max(std::abs(a), std::abs(b)) + 1e-30;
}

// flux x length conserved: leaves carry their VRL's, inner nodes their
// children's sum (relative 1e-5 per channel), the root the sum over all VRLs
// (relative 1e-4: float summation over up to 2 10^4 terms); clusterFlux x
// length of the representative == fluxLength (relative 1e-5).
::testing::AssertionResult fluxLengthIsConserved(const LightTree& tree) {
    const auto& nodes = tree.nodes();
    const auto& vrls = tree.vrls();
    double total[3] = {0, 0, 0};
    for (const Vrl& v : vrls)
        for (int c = 0; c < 3; ++c) total[c] += double(v.flux[c]) * double(v.length);
    for (size_t i = 0; i < nodes.size(); ++i) {
        const LightTreeNode& node = nodes[i];
        const double repLength = vrls[node.representative].length;
        for (int c = 0; c < 3; ++c) {
            double expected;
            if (node.isLeaf()) {
                expected = double(vrls[i].flux[c]) * double(vrls[i].length);
            } else {
                expected = double(nodes[size_t(node.left)].fluxLength[c]) + double(nodes[size_t(node.right)].fluxLength[c]);
            }
            if (!closeRelative(node.fluxLength[c], expected, 1e-5))
                return ::testing::AssertionFailure() << at(i) << "fluxLength[" << c << "] " << node.fluxLength[c]
                                                     << " != " << (node.isLeaf() ? "flux x length " : "children's sum ")
                                                     << expected;
            if (!closeRelative(double(node.clusterFlux[c]) * repLength, node.fluxLength[c], 1e-5))
                return ::testing::AssertionFailure() << at(i) << "clusterFlux[" << c << "] " << node.clusterFlux[c]
                                                     << " x representative length " << repLength << " != fluxLength "
                                                     << node.fluxLength[c];
        }
    }
    if (!tree.empty()) {
        const Rgb& root = nodes[size_t(tree.root())].fluxLength;
        for (int c = 0; c < 3; ++c)
            if (!closeRelative(root[c], total[c], 1e-4))
                return ::testing::AssertionFailure() << "root fluxLength[" << c << "] " << root[c]
                                                     << " != sum over VRLs " << total[c];
    }
    return ::testing::AssertionSuccess();
}

// Inner nodes: the representative is one of the children's, maxLength the
// larger of theirs, medium the common one or -1. Leaves: their VRL's length
// and medium, clusterFlux its flux.
::testing::AssertionResult summariesAreConsistent(const LightTree& tree) {
    const auto& nodes = tree.nodes();
    const auto& vrls = tree.vrls();
    for (size_t i = 0; i < nodes.size(); ++i) {
        const LightTreeNode& node = nodes[i];
        if (node.isLeaf()) {
            const Vrl& v = vrls[i];
            if (bits(node.maxLength) != bits(v.length) || node.medium != v.medium || !sameBits(node.clusterFlux, v.flux))
                return ::testing::AssertionFailure() << at(i) << "leaf summary differs from VRL " << i;
            continue;
        }
        const LightTreeNode &l = nodes[size_t(node.left)], &r = nodes[size_t(node.right)];
        if (node.representative != l.representative && node.representative != r.representative)
            return ::testing::AssertionFailure() << at(i) << "representative " << node.representative
                                                 << " is neither child's (" << l.representative << ", "
                                                 << r.representative << ")";
        if (node.maxLength != std::max(l.maxLength, r.maxLength))
            return ::testing::AssertionFailure() << at(i) << "maxLength " << node.maxLength << " != max("
                                                 << l.maxLength << ", " << r.maxLength << ")";
        const int32_t medium = l.medium == r.medium ? l.medium : -1;
        if (node.medium != medium)
            return ::testing::AssertionFailure() << at(i) << "medium " << node.medium << " != " << medium;
    }
    return ::testing::AssertionSuccess();
}

void expectValidTree(const LightTree& tree, const std::vector<Vrl>& input) {
    ASSERT_TRUE(structureIsValid(tree, input));
    EXPECT_TRUE(boxesAreNested(tree));
    EXPECT_TRUE(fluxLengthIsConserved(tree));
    EXPECT_TRUE(summariesAreConsistent(tree));
}

// Every node field (and every VRL) bit for bit.
::testing::AssertionResult identicalTrees(const LightTree& a, const LightTree& b) {
    if (a.root() != b.root() || a.nodes().size() != b.nodes().size() || a.vrls().size() != b.vrls().size())
        return ::testing::AssertionFailure() << "shapes differ: root " << a.root() << " / " << b.root() << ", "
                                             << a.nodes().size() << " / " << b.nodes().size() << " nodes";
    for (size_t i = 0; i < a.vrls().size(); ++i) {
        const Vrl &x = a.vrls()[i], &y = b.vrls()[i];
        if (!sameBits(x.origin, y.origin) || !sameBits(x.direction, y.direction) || bits(x.length) != bits(y.length) ||
            !sameBits(x.flux, y.flux) || x.medium != y.medium)
            return ::testing::AssertionFailure() << "VRL " << i << " differs";
    }
    for (size_t i = 0; i < a.nodes().size(); ++i) {
        const LightTreeNode &x = a.nodes()[i], &y = b.nodes()[i];
        if (!sameBits(x.box.min, y.box.min) || !sameBits(x.box.max, y.box.max) ||
            !sameBits(x.fluxLength, y.fluxLength) || !sameBits(x.clusterFlux, y.clusterFlux) ||
            bits(x.maxLength) != bits(y.maxLength) || x.representative != y.representative ||
            x.vrlCount != y.vrlCount || x.left != y.left || x.right != y.right || x.medium != y.medium)
            return ::testing::AssertionFailure() << at(i) << "differs";
    }
    return ::testing::AssertionSuccess();
}

LightTree buildWithThreads(const std::vector<Vrl>& vrls, const LightTreeSettings& settings, int threads) {
    tbb::task_arena arena(threads);
    LightTree tree;
    arena.execute([&] { tree = LightTree::build(vrls, settings); });
    return tree;
}

// The build's objective: sum over inner nodes of luminance(fluxLength) x diagonal^2.
double treeCost(const LightTree& tree) {
    double cost = 0;
    for (const LightTreeNode& node : tree.nodes()) {
        if (node.isLeaf()) continue;
        const Imath::V3f d = node.box.max - node.box.min;
        cost += double(luminance(node.fluxLength)) * (double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
    }
    return cost;
}

// ---------------------------------------------------------------------------
// Invariants over VRL sets x partition sizes.

struct BuildCase {
    std::string name;
    std::vector<Vrl> (*vrls)();
    uint32_t partitionSize;
};

void PrintTo(const BuildCase& c, std::ostream* os) { *os << c.name << ", partitionSize " << c.partitionSize; }

std::string caseName(const ::testing::TestParamInfo<BuildCase>& info) {
    return info.param.name + "_" + (info.param.partitionSize == kGlobal ? std::string("global")
                                                                         : std::to_string(info.param.partitionSize));
}

class LightTreeInvariants : public ::testing::TestWithParam<BuildCase> {};

TEST_P(LightTreeInvariants, HoldForEveryNode) {
    const std::vector<Vrl> vrls = GetParam().vrls();
    ASSERT_GT(vrls.size(), 1u);
    LightTreeSettings settings;
    settings.partitionSize = GetParam().partitionSize;
    settings.seed = 11;
    const LightTree tree = LightTree::build(vrls, settings);
    expectValidTree(tree, vrls);
}

std::vector<Vrl> litRoom20k() { return litRoomVrls(); }
std::vector<Vrl> smokeRoom5k() { return smokeRoomVrls(); }
std::vector<Vrl> mixed() { return randomVrls(3000, RandomKind::Mixed, 1); }
std::vector<Vrl> identical() { return randomVrls(2000, RandomKind::Identical, 2); }
std::vector<Vrl> plane() { return randomVrls(2500, RandomKind::Plane, 3); }
std::vector<Vrl> line() { return randomVrls(2500, RandomKind::Line, 4); }
std::vector<Vrl> zeroLength() { return randomVrls(1500, RandomKind::AllZeroLength, 5); }

std::vector<BuildCase> buildCases() {
    std::vector<BuildCase> cases;
    // The global build is O(N^2): run on every set but the ~20k one.
    cases.push_back({"LitRoom20k", litRoom20k, 64});
    cases.push_back({"LitRoom20k", litRoom20k, 2048});
    const std::pair<const char*, std::vector<Vrl> (*)()> sets[] = {
        {"SmokeRoom5k", smokeRoom5k}, {"Mixed", mixed}, {"Identical", identical},
        {"Plane", plane},             {"Line", line},   {"ZeroLength", zeroLength}};
    for (const auto& [name, make] : sets)
        for (uint32_t size : {64u, 2048u, kGlobal}) cases.push_back({name, make, size});
    cases.push_back({"Mixed", mixed, 2});  // the smallest partitions: all merging in the top level
    return cases;
}

INSTANTIATE_TEST_SUITE_P(SetsAndPartitions, LightTreeInvariants, ::testing::ValuesIn(buildCases()), caseName);

TEST(LightTree, EmptyInputGivesEmptyTree) {
    const LightTree tree = LightTree::build({});
    EXPECT_TRUE(tree.empty());
    EXPECT_EQ(tree.root(), -1);
    EXPECT_TRUE(tree.nodes().empty());
    EXPECT_TRUE(tree.vrls().empty());
}

TEST(LightTree, SingleVrlGivesSingleLeafRoot) {
    const std::vector<Vrl> vrls = randomVrls(1, RandomKind::Mixed, 7);
    for (uint32_t size : {1u, 64u, kGlobal}) {
        LightTreeSettings settings;
        settings.partitionSize = size;
        const LightTree tree = LightTree::build(vrls, settings);
        ASSERT_EQ(tree.root(), 0);
        ASSERT_EQ(tree.nodes().size(), 1u);
        EXPECT_TRUE(tree.nodes()[0].isLeaf());
        expectValidTree(tree, vrls);
    }
}

TEST(LightTree, SmallInputsAreValidForEveryPartitionSize) {
    for (size_t n = 2; n <= 9; ++n) {
        const std::vector<Vrl> vrls = randomVrls(n, RandomKind::Mixed, 100 + n);
        for (uint32_t size : {0u, 1u, 2u, 3u, kGlobal}) {
            LightTreeSettings settings;
            settings.partitionSize = size;
            SCOPED_TRACE("n " + std::to_string(n) + ", partitionSize " + std::to_string(size));
            expectValidTree(LightTree::build(vrls, settings), vrls);
        }
    }
}

// ---------------------------------------------------------------------------
// Representative choice: P(representative from child A) =
// luminance(A.fluxLength) / (luminance(A.fluxLength) + luminance(B.fluxLength)).

// Two VRLs whose weights by luminance(flux x length) differ from those by
// luminance(flux), by any single channel or by their average, so that a wrong
// weight shows. N = 20000 two-leaf trees, seeds 0..N-1; tolerance 5 standard
// deviations of the binomial count (false alarm ~6e-7).
TEST(LightTree, TwoLeafRepresentativeFrequencyMatchesLuminanceOfFluxTimesLength) {
    struct Pair {
        Rgb flux0, flux1;
        float length0, length1;
    };
    const Pair pairs[] = {
        {Rgb(2.0f, 0.0f, 0.0f), Rgb(0.0f, 0.1f, 0.0f), 1.0f, 2.0f},   // p0 = 0.748 (0.856 by flux alone)
        {Rgb(0.1f, 0.2f, 0.9f), Rgb(0.3f, 0.1f, 0.1f), 0.05f, 0.4f},  // p0 = 0.079 (0.41 by flux alone)
        {Rgb(1.0f, 1.0f, 1.0f), Rgb(0.0f, 0.0f, 0.0f), 0.5f, 0.5f},   // p0 = 1: a black VRL never represents
        {Rgb(1.0f, 1.0f, 1.0f), Rgb(5.0f, 5.0f, 5.0f), 0.7f, 0.0f},   // p0 = 1: a zero-length VRL never represents
    };
    const int trials = 20000;
    for (const Pair& p : pairs) {
        std::vector<Vrl> vrls(2);
        vrls[0].origin = {0, 0, 0};
        vrls[1].origin = {0.5f, 0.2f, -0.1f};
        vrls[0].direction = vrls[1].direction = {0, 0, 1};
        vrls[0].flux = p.flux0, vrls[1].flux = p.flux1;
        vrls[0].length = p.length0, vrls[1].length = p.length1;
        const double w0 = luminance(p.flux0 * p.length0), w1 = luminance(p.flux1 * p.length1);
        const double expected = w0 / (w0 + w1);
        int firstChosen = 0;
        for (int seed = 0; seed < trials; ++seed) {
            LightTreeSettings settings;
            settings.seed = uint64_t(seed);
            const LightTree tree = LightTree::build(vrls, settings);
            ASSERT_EQ(tree.nodes().size(), 3u);
            firstChosen += tree.nodes()[size_t(tree.root())].representative == 0;
        }
        const double sigma = std::sqrt(trials * expected * (1 - expected));
        EXPECT_NEAR(firstChosen, trials * expected, 5 * sigma + 0.5)
            << "expected P(VRL 0) = " << expected << ", observed " << double(firstChosen) / trials;
    }
}

// Over every inner node of 200 trees of the same 3000 mixed VRLs (same shape,
// seeds 0..199, partitionSize 64): the count of nodes that took the left
// child's representative against the sum of its probabilities, within 5
// standard deviations of the sum of Bernoulli variances; the shape must not
// depend on the seed.
TEST(LightTree, SiblingRepresentativeFrequencyMatchesLuminanceOfFluxTimesLength) {
    const std::vector<Vrl> vrls = randomVrls(3000, RandomKind::Mixed, 21);
    const int trees = 200;
    LightTreeSettings settings;
    settings.partitionSize = 64;
    const LightTree first = LightTree::build(vrls, settings);
    double count = 0, mean = 0, variance = 0;
    // Also per probability bin, so a bias that cancels overall still shows.
    const int bins = 5;
    double binCount[bins] = {}, binMean[bins] = {}, binVariance[bins] = {};
    for (int seed = 0; seed < trees; ++seed) {
        settings.seed = uint64_t(seed);
        const LightTree tree = LightTree::build(vrls, settings);
        ASSERT_EQ(tree.nodes().size(), first.nodes().size());
        for (size_t i = vrls.size(); i < tree.nodes().size(); ++i) {
            const LightTreeNode& node = tree.nodes()[i];
            ASSERT_EQ(node.left, first.nodes()[i].left);
            ASSERT_EQ(node.right, first.nodes()[i].right);
            const LightTreeNode &l = tree.nodes()[size_t(node.left)], &r = tree.nodes()[size_t(node.right)];
            const double wl = luminance(l.fluxLength), wr = luminance(r.fluxLength);
            if (wl + wr <= 0) continue;
            const double p = wl / (wl + wr);
            const double took = node.representative == l.representative;
            const int bin = std::min(bins - 1, int(p * bins));
            count += took, mean += p, variance += p * (1 - p);
            binCount[bin] += took, binMean[bin] += p, binVariance[bin] += p * (1 - p);
        }
    }
    EXPECT_NEAR(count, mean, 5 * std::sqrt(variance) + 0.5) << "over all inner nodes";
    for (int b = 0; b < bins; ++b)
        EXPECT_NEAR(binCount[b], binMean[b], 5 * std::sqrt(binVariance[b]) + 0.5)
            << "nodes with P(left) in [" << double(b) / bins << ", " << double(b + 1) / bins << ")";
}

// ---------------------------------------------------------------------------
// Determinism

TEST(LightTree, SameTreeWithOneAndTwoThreads) {
    const std::vector<Vrl>& vrls = litRoomVrls();
    for (uint32_t size : {64u, 2048u}) {
        LightTreeSettings settings;
        settings.partitionSize = size;
        settings.seed = 17;
        const LightTree one = buildWithThreads(vrls, settings, 1), two = buildWithThreads(vrls, settings, 2);
        EXPECT_TRUE(identicalTrees(one, two)) << "partitionSize " << size;
    }
}

TEST(LightTree, SameSeedSameTreeOtherSeedOnlyOtherRepresentatives) {
    const std::vector<Vrl> vrls = randomVrls(3000, RandomKind::Mixed, 31);
    LightTreeSettings settings;
    settings.partitionSize = 64;
    settings.seed = 1;
    const LightTree a = LightTree::build(vrls, settings), b = LightTree::build(vrls, settings);
    EXPECT_TRUE(identicalTrees(a, b));
    settings.seed = 2;
    const LightTree c = LightTree::build(vrls, settings);
    ASSERT_EQ(a.root(), c.root());
    ASSERT_EQ(a.nodes().size(), c.nodes().size());
    size_t otherRepresentatives = 0;
    for (size_t i = 0; i < a.nodes().size(); ++i) {
        const LightTreeNode &x = a.nodes()[i], &y = c.nodes()[i];
        ASSERT_TRUE(sameBits(x.box.min, y.box.min) && sameBits(x.box.max, y.box.max) &&
                    sameBits(x.fluxLength, y.fluxLength) && bits(x.maxLength) == bits(y.maxLength) &&
                    x.vrlCount == y.vrlCount && x.left == y.left && x.right == y.right && x.medium == y.medium)
            << at(i) << "a field other than representative/clusterFlux depends on the seed";
        otherRepresentatives += x.representative != y.representative;
    }
    EXPECT_GT(otherRepresentatives, a.nodes().size() / 20) << "the seed should matter for representatives";
}

// ---------------------------------------------------------------------------
// Serialisation of a built tree

TEST(LightTree, BuiltTreeRoundTripsThroughSerialisationBitExactly) {
    for (uint32_t size : {64u, kGlobal}) {
        const std::vector<Vrl> vrls = randomVrls(3000, RandomKind::Mixed, 41);
        LightTreeSettings settings;
        settings.partitionSize = size;
        settings.seed = 3;
        const LightTree tree = LightTree::build(vrls, settings);
        const std::vector<uint8_t> blob = serializeLightTree(tree);
        const LightTree back = deserializeLightTree(blob);
        EXPECT_TRUE(identicalTrees(tree, back)) << "partitionSize " << size;
        EXPECT_EQ(serializeLightTree(back), blob) << "partitionSize " << size;
    }
    const LightTree realistic = LightTree::build(litRoomVrls());
    const std::vector<uint8_t> blob = serializeLightTree(realistic);
    EXPECT_TRUE(identicalTrees(realistic, deserializeLightTree(blob)));
    EXPECT_EQ(serializeLightTree(deserializeLightTree(blob)), blob);
}

// ---------------------------------------------------------------------------
// The merge rule against a brute-force reference: the greedy clustering that
// repeatedly merges the pair of clusters minimising I_c E_c^2 (luminance of
// the merged flux x length times the merged box's squared diagonal), in
// double. Random scattered VRLs (no copies, no zero weights) make ties
// improbable, so the tree must hold exactly the reference's clusters.

struct RefCluster {
    double lo[3], hi[3];
    double weight;  // luminance of flux x length (linear, so summable)
    std::vector<uint32_t> members;  // sorted VRL indices
};

RefCluster refLeaf(const std::vector<Vrl>& vrls, uint32_t i) {
    const Vrl& v = vrls[i];
    const Vec3 a = v.origin, b = v.end();
    RefCluster c;
    for (int k = 0; k < 3; ++k) c.lo[k] = std::min(a[k], b[k]), c.hi[k] = std::max(a[k], b[k]);
    c.weight = luminance(v.flux * v.length);
    c.members = {i};
    return c;
}

RefCluster refJoin(const RefCluster& a, const RefCluster& b) {
    RefCluster c;
    for (int k = 0; k < 3; ++k) c.lo[k] = std::min(a.lo[k], b.lo[k]), c.hi[k] = std::max(a.hi[k], b.hi[k]);
    c.weight = a.weight + b.weight;
    c.members = a.members;
    c.members.insert(c.members.end(), b.members.begin(), b.members.end());
    std::sort(c.members.begin(), c.members.end());
    return c;
}

double refCost(const RefCluster& a, const RefCluster& b) {
    double diagonal2 = 0;
    for (int k = 0; k < 3; ++k) {
        const double d = std::max(a.hi[k], b.hi[k]) - std::min(a.lo[k], b.lo[k]);
        diagonal2 += d * d;
    }
    return (a.weight + b.weight) * diagonal2;
}

// The clusters (as sorted VRL index lists) that greedy agglomeration of `live` creates.
std::set<std::vector<uint32_t>> greedyClusters(std::vector<RefCluster> live) {
    std::set<std::vector<uint32_t>> created;
    while (live.size() > 1) {
        size_t bestI = 0, bestJ = 1;
        double best = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < live.size(); ++i)
            for (size_t j = i + 1; j < live.size(); ++j) {
                const double cost = refCost(live[i], live[j]);
                if (cost < best) best = cost, bestI = i, bestJ = j;
            }
        live[bestI] = refJoin(live[bestI], live[bestJ]);
        created.insert(live[bestI].members);
        live[bestJ] = std::move(live.back());
        live.pop_back();
    }
    return created;
}

// Sorted VRL indices below every node.
std::vector<std::vector<uint32_t>> membersOfNodes(const LightTree& tree) {
    const auto& nodes = tree.nodes();
    std::vector<std::vector<uint32_t>> members(nodes.size());
    std::vector<std::pair<int32_t, bool>> stack{{tree.root(), false}};  // post-order
    while (!stack.empty()) {
        const auto [i, expanded] = stack.back();
        stack.pop_back();
        const LightTreeNode& node = nodes[size_t(i)];
        if (node.isLeaf()) {
            members[size_t(i)] = {node.representative};
        } else if (!expanded) {
            stack.push_back({i, true});
            stack.push_back({node.left, false});
            stack.push_back({node.right, false});
        } else {
            auto& m = members[size_t(i)];
            m = members[size_t(node.left)];
            m.insert(m.end(), members[size_t(node.right)].begin(), members[size_t(node.right)].end());
            std::sort(m.begin(), m.end());
        }
    }
    return members;
}

// N = 300: every inner node of the global build is a cluster of the reference.
TEST(LightTree, GlobalBuildIsGreedyAgglomerationByLuminanceTimesSquaredDiagonal) {
    const std::vector<Vrl> vrls = randomVrls(300, RandomKind::Scattered, 51);
    LightTreeSettings settings;
    settings.partitionSize = kGlobal;
    const LightTree tree = LightTree::build(vrls, settings);
    ASSERT_TRUE(structureIsValid(tree, vrls));
    std::vector<RefCluster> leaves;
    for (uint32_t i = 0; i < vrls.size(); ++i) leaves.push_back(refLeaf(vrls, i));
    const std::set<std::vector<uint32_t>> expected = greedyClusters(leaves);
    const auto members = membersOfNodes(tree);
    const std::set<std::vector<uint32_t>> built(members.begin() + vrls.size(), members.end());
    EXPECT_EQ(built.size(), vrls.size() - 1);
    EXPECT_TRUE(built == expected) << "the global build differs from greedy agglomeration";
}

// N = 3000, partitionSize 64: six rounds of median splits give 64 partitions
// of 46 or 47 VRLs, so the partitions are exactly the subtrees of at most 64
// VRLs whose parent has more. Each must be the greedy agglomeration of its
// VRLs, and the nodes above them the greedy agglomeration of the partitions.
TEST(LightTree, HybridBuildIsGreedyInsideMedianSplitPartitionsAndAcrossThem) {
    const std::vector<Vrl> vrls = randomVrls(3000, RandomKind::Scattered, 52);
    const uint32_t partitionSize = 64;
    LightTreeSettings settings;
    settings.partitionSize = partitionSize;
    const LightTree tree = LightTree::build(vrls, settings);
    ASSERT_TRUE(structureIsValid(tree, vrls));
    const auto& nodes = tree.nodes();
    const auto members = membersOfNodes(tree);
    std::vector<int32_t> parent(nodes.size(), -1);
    for (size_t i = vrls.size(); i < nodes.size(); ++i) parent[size_t(nodes[i].left)] = parent[size_t(nodes[i].right)] = int32_t(i);
    std::vector<size_t> partitions;
    for (size_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].vrlCount <= partitionSize && (parent[i] < 0 || nodes[size_t(parent[i])].vrlCount > partitionSize))
            partitions.push_back(i);
    ASSERT_EQ(partitions.size(), 64u);
    std::vector<RefCluster> partitionClusters;
    for (size_t root : partitions) {
        ASSERT_TRUE(nodes[root].vrlCount == 46 || nodes[root].vrlCount == 47) << at(root) << nodes[root].vrlCount;
        std::vector<RefCluster> leaves;
        for (uint32_t i : members[root]) leaves.push_back(refLeaf(vrls, i));
        const std::set<std::vector<uint32_t>> expected = greedyClusters(leaves);
        std::set<std::vector<uint32_t>> built;
        for (size_t i = vrls.size(); i < nodes.size(); ++i)
            if (nodes[i].vrlCount <= partitionSize && members[i].front() >= members[root].front() &&
                std::includes(members[root].begin(), members[root].end(), members[i].begin(), members[i].end()))
                built.insert(members[i]);
        EXPECT_TRUE(built == expected) << "partition at " << at(root) << "differs from greedy agglomeration";
        RefCluster c = leaves[0];
        for (size_t k = 1; k < leaves.size(); ++k) c = refJoin(c, leaves[k]);
        partitionClusters.push_back(c);
    }
    std::set<std::vector<uint32_t>> top;
    for (size_t i = vrls.size(); i < nodes.size(); ++i)
        if (nodes[i].vrlCount > partitionSize) top.insert(members[i]);
    EXPECT_EQ(top.size(), 63u);
    EXPECT_TRUE(top == greedyClusters(partitionClusters)) << "the merge of the partition roots differs from greedy";
}

TEST(LightTree, PartitionSizeAtLeastNIsTheGlobalBuild) {
    const std::vector<Vrl> vrls = randomVrls(1500, RandomKind::Mixed, 53);
    LightTreeSettings settings;
    settings.seed = 4;
    settings.partitionSize = 1500;
    const LightTree exact = LightTree::build(vrls, settings);
    settings.partitionSize = 2048;
    const LightTree larger = LightTree::build(vrls, settings);
    settings.partitionSize = kGlobal;
    const LightTree global = LightTree::build(vrls, settings);
    EXPECT_TRUE(identicalTrees(exact, global));
    EXPECT_TRUE(identicalTrees(larger, global));
}

// Two slabs far apart in y, each wide in x: only a split along y gives child
// boxes that do not overlap, so the first median split must separate the
// slabs and no partition (the 8 subtrees of 64 VRLs) may mix them.
TEST(LightTree, MedianSplitKeepsTheAxisWhoseHalvesOverlapLeast) {
    Rng rng(54, 0);
    std::vector<Vrl> vrls(512);
    for (size_t i = 0; i < vrls.size(); ++i) {
        Vrl& v = vrls[i];
        const float slabY = i % 2 ? 10.0f : 0.0f;
        v.origin = {100 * rng.next() - 50, slabY + rng.next() * 0.5f, 2 * rng.next() - 1};
        v.direction = randomDirection(rng);
        v.length = 0.2f + 0.3f * rng.next();
        v.flux = Rgb(rng.next(), rng.next(), rng.next());
        v.medium = 0;
    }
    LightTreeSettings settings;
    settings.partitionSize = 64;
    const LightTree tree = LightTree::build(vrls, settings);
    ASSERT_TRUE(structureIsValid(tree, vrls));
    const auto members = membersOfNodes(tree);
    size_t partitions = 0;
    for (size_t i = vrls.size(); i < tree.nodes().size(); ++i) {
        if (tree.nodes()[i].vrlCount != 64) continue;
        ++partitions;
        const auto slab = [](uint32_t k) { return k % 2; };
        const bool oneSlab = std::all_of(members[i].begin(), members[i].end(),
                                         [&](uint32_t k) { return slab(k) == slab(members[i].front()); });
        EXPECT_TRUE(oneSlab) << at(i) << "a partition mixes the two slabs";
    }
    EXPECT_EQ(partitions, 8u);
}

// ---------------------------------------------------------------------------
// Quality: the hybrid build against the global agglomerative one on 5156
// light-traced VRLs of the smoke room (800 paths, seed 3). Measured: the
// global build costs 41277, partitionSize 2048 (4 partitions) 1.010x that,
// partitionSize 64 (128 partitions) 1.113x; the paper reports a 25% gathering
// overhead for its hybrid tree. Bound: 1.3x. The summed cost is dominated by
// the few large nodes near the root, so it is a coarse check: a balanced tree
// pairing VRLs in input order scores 1.77x, median splits down to 64 VRLs with
// balanced pairing inside them only 1.23x. The merge rule itself is pinned
// down by the greedy-reference tests above.
TEST(LightTree, HybridBuildCostIsCloseToGlobalBuild) {
    const std::vector<Vrl>& vrls = smokeRoomVrls();
    ASSERT_GE(vrls.size(), 5000u);
    LightTreeSettings settings;
    settings.partitionSize = kGlobal;
    const auto start = std::chrono::steady_clock::now();
    const double global = treeCost(LightTree::build(vrls, settings));
    const double globalSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_GT(global, 0.0);
    std::printf("[ quality  ] %zu VRLs, global build: cost %.6g (%.3f s)\n", vrls.size(), global, globalSeconds);
    for (uint32_t size : {2048u, 64u}) {
        settings.partitionSize = size;
        const auto t = std::chrono::steady_clock::now();
        const double hybrid = treeCost(LightTree::build(vrls, settings));
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
        std::printf("[ quality  ] partitionSize %u: cost %.6g = %.3fx global (%.3f s)\n", size, hybrid,
                    hybrid / global, seconds);
        EXPECT_LE(hybrid, 1.3 * global) << "partitionSize " << size;
    }
}

// ---------------------------------------------------------------------------
// Known bug, reported, not fixed here (render/light_tree.cpp, agglomerate's
// pushBest): a merge cost (w_a + w_b) * diagonal^2 that overflows float to
// +inf (here finite fluxes of 1e33 W, 1 km apart) never beats the +inf that
// marks the cluster itself, so the cluster gets no heap entry and is never
// merged: the hybrid build returns root -1 over 4 VRLs, the global build a
// root holding 2 of the 4. Enable once fixed.
TEST(LightTree, MergeCostOverflowStillJoinsEveryVrl) {
    std::vector<Vrl> vrls(4);
    const float x[4] = {0.0f, 0.5f, 1000.0f, 1000.5f};
    for (size_t i = 0; i < vrls.size(); ++i) {
        vrls[i].origin = {x[i], 0.0f, 0.0f};
        vrls[i].direction = {0.0f, 0.0f, 1.0f};
        vrls[i].length = 1.0f;
        vrls[i].flux = Rgb(1e33f);
        vrls[i].medium = 0;
    }
    for (uint32_t size : {2u, kGlobal}) {
        LightTreeSettings settings;
        settings.partitionSize = size;
        SCOPED_TRACE("partitionSize " + std::to_string(size));
        expectValidTree(LightTree::build(vrls, settings), vrls);
    }
}

}  // namespace
}  // namespace vrl
