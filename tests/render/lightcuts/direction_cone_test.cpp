// Tests of DirectionCone and DirectionCones (render/lightcuts/bounds/direction_cone.h):
// every VRL direction below a node lies in the node's cone, through rounding, and
// merged cones are not needlessly wide. Random trees of VRLs with directions that
// are random, nearly equal (spread 1e-7..1e-2 rad), exactly opposite, or
// axis-aligned; seeds fixed (Rng(201, tree)). Containment is an exact test in
// double: zero misses are required.
#include "render/lightcuts/bounds/direction_cone.h"

#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace vrl {
namespace {

constexpr double kPiD = 3.14159265358979323846;

Vec3 randomDirection(Rng& rng) {
    const float z = 2.0f * rng.next() - 1.0f, phi = 2.0f * kPi * rng.next();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z).normalized();
}

TEST(DirectionCone, SingleDirectionAndSphere) {
    const DirectionCone c = DirectionCone::ofDirection(Vec3(0.0f, 3.0f, 4.0f));
    EXPECT_NEAR(c.axis.y, 0.6f, 1e-7f);
    EXPECT_LE(c.halfAngle, 1e-5f);
    EXPECT_TRUE(c.contains(Vec3(0.0f, 0.6f, 0.8f)));
    EXPECT_FALSE(c.contains(Vec3(0.0f, 0.8f, 0.6f)));
    // Opposite directions: the whole sphere.
    const DirectionCone both = DirectionCone::merge(DirectionCone::ofDirection(Vec3(1, 0, 0)),
                                                    DirectionCone::ofDirection(Vec3(-1, 0, 0)));
    EXPECT_TRUE(both.isSphere());
    EXPECT_TRUE(both.contains(Vec3(0, 1, 0)));
    // A zero direction cannot be bounded by a cone: the sphere.
    EXPECT_TRUE(DirectionCone::ofDirection(Vec3(0.0f)).isSphere());
}

// Two directions 90 degrees apart: the smallest cone has half-angle 45 degrees and
// its axis halfway; a cone containing another is returned as it is.
TEST(DirectionCone, MergeIsTheSmallestConeOfTwo) {
    const DirectionCone x = DirectionCone::ofDirection(Vec3(1, 0, 0)), y = DirectionCone::ofDirection(Vec3(0, 1, 0));
    const DirectionCone m = DirectionCone::merge(x, y);
    EXPECT_NEAR(m.halfAngle, kPiD / 4.0, 1e-5);
    EXPECT_NEAR(m.axis.x, std::sqrt(0.5), 1e-6);
    EXPECT_NEAR(m.axis.y, std::sqrt(0.5), 1e-6);
    const DirectionCone wide{Vec3(0, 0, 1), 1.0f};
    const DirectionCone inside{Vec3(0.0f, std::sin(0.3f), std::cos(0.3f)), 0.2f};
    const DirectionCone merged = DirectionCone::merge(wide, inside);
    EXPECT_EQ(merged.halfAngle, wide.halfAngle);
    EXPECT_EQ(merged.axis, wide.axis);
}

// 400 random trees of 2..300 VRLs: every leaf direction is inside each of its
// ancestors' cones; the root cone of nearly equal directions stays narrow.
TEST(DirectionCones, EveryVrlDirectionIsInsideItsAncestorsCones) {
    uint64_t checks = 0, narrowRoots = 0, narrowTrees = 0;
    for (int t = 0; t < 400; ++t) {
        Rng rng(201, uint64_t(t));
        const int count = 2 + int(rng.nextUint() % 299);
        const int kind = t % 4;
        const Vec3 base = randomDirection(rng);
        const float spread = 1e-7f * std::pow(1e5f, rng.next());
        std::vector<Vrl> vrls;
        for (int i = 0; i < count; ++i) {
            Vec3 d;
            switch (kind) {
                case 0: d = randomDirection(rng); break;
                case 1: d = (base + randomDirection(rng) * spread).normalized(); break;
                case 2: d = rng.next() < 0.5f ? base : -base; break;
                default: d = Vec3(0.0f), d[int(rng.nextUint() % 3)] = rng.next() < 0.5f ? 1.0f : -1.0f; break;
            }
            vrls.push_back({Vec3(rng.next(), rng.next(), rng.next()) * 4.0f, d, 0.1f + rng.next(), Rgb(rng.next() + 0.01f), 0});
        }
        const LightTree tree = LightTree::build(vrls, LightTreeSettings{rng.next() < 0.5f ? 2048u : 8u, uint64_t(t)});
        const DirectionCones cones(tree);
        const auto& nodes = tree.nodes();
        std::vector<int32_t> parent(nodes.size(), -1);
        for (size_t n = 0; n < nodes.size(); ++n)
            if (!nodes[n].isLeaf()) parent[size_t(nodes[n].left)] = parent[size_t(nodes[n].right)] = int32_t(n);
        for (size_t leaf = 0; leaf < tree.vrls().size(); ++leaf) {
            const Vec3 d = tree.vrls()[nodes[leaf].representative].direction;
            for (int32_t n = int32_t(leaf); n >= 0; n = parent[size_t(n)], ++checks)
                ASSERT_TRUE(cones[n].contains(d)) << "tree " << t << " node " << n << " half-angle " << cones[n].halfAngle;
        }
        if (kind == 1) {
            ++narrowTrees;
            // The true spread is at most 2 asin(spread); merges may add a little.
            if (cones[tree.root()].halfAngle <= 4.0f * spread + 1e-4f) ++narrowRoots;
        }
    }
    std::printf("[ DirectionCones ] %llu containment checks, %llu of %llu nearly-parallel roots narrow\n",
                (unsigned long long)checks, (unsigned long long)narrowRoots, (unsigned long long)narrowTrees);
    EXPECT_GT(checks, 100000u);
    EXPECT_EQ(narrowRoots, narrowTrees);
}

}  // namespace
}  // namespace vrl
