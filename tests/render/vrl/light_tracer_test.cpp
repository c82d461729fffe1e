// Light tracing into short VRLs: determinism, maxDepth, counts and memory, and
// an analytic energy check. In an unbounded medium the expected sum over VRLs
// of flux x length is the light's power times the mean path length weighted by
// throughput: Phi / sigma_t * sum_j albedo^j (= Phi / sigma_a without a depth
// limit), per channel, which exercises spectral tracking and Russian roulette.
#include "render/vrl/light_tracer.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vrl {
namespace {

VrlSet traceWithThreads(const Scene& scene, const LightTracingSettings& settings, int threads) {
    tbb::task_arena arena(threads);
    VrlSet result;
    arena.execute([&] { result = traceVrls(scene, settings); });
    return result;
}

TEST(LightTracer, SameSeedSameVrlsWithOneAndTwoThreads) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.5f));
    LightTracingSettings settings;
    settings.targetVrls = 20000;
    settings.seed = 9;
    const VrlSet a = traceWithThreads(*scene, settings, 1), b = traceWithThreads(*scene, settings, 2);
    ASSERT_EQ(a.vrls.size(), b.vrls.size());
    ASSERT_GT(a.vrls.size(), 0u);
    EXPECT_EQ(a.lightPaths, b.lightPaths);
    EXPECT_EQ(std::memcmp(a.vrls.data(), b.vrls.data(), a.vrls.size() * sizeof(Vrl)), 0);
}

TEST(LightTracer, TargetCountKeepsWholeBatchesAndReportsMemory) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    LightTracingSettings settings;
    settings.targetVrls = 5000;
    const VrlSet set = traceVrls(*scene, settings);
    EXPECT_GE(set.vrls.size(), 5000u);
    EXPECT_LT(set.vrls.size(), 5000u + 20000u) << "one batch of 2048 paths should not overshoot by this much";
    EXPECT_EQ(set.memoryBytes(), set.vrls.size() * sizeof(Vrl));
    EXPECT_LE(sizeof(Vrl), 48u);
    EXPECT_LT(1'000'000 * sizeof(Vrl), 100u * 1000 * 1000) << "10^6 VRLs must fit in well under 100 MB";
    settings.targetVrls = 0;
    settings.lightPaths = 3000;
    EXPECT_EQ(traceVrls(*scene, settings).lightPaths, 3000u);
    settings.lightPaths = 0;
    EXPECT_THROW(traceVrls(*scene, settings), std::invalid_argument);
}

// The surface VPL limit keeps the VPLs of the first whole chunks of paths: the
// same VPLs as without a limit, in the same order, up to the first chunk that would
// pass it, each with its flux divided by the paths that deposited (so flux x paths
// agrees with the unlimited run's, up to float rounding of the two divisions), on
// any thread count; the VRLs do not change. The first chunk is kept whatever the
// limit (a part (b) from 64 paths rather than none).
TEST(LightTracer, SurfaceVplLimitKeepsTheFirstPathsVplsAndRenormalises) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    LightTracingSettings settings;
    settings.targetVrls = 20000;
    settings.seed = 3;
    settings.surfaceVpls = true;
    const VrlSet all = traceVrls(*scene, settings);
    ASSERT_GT(all.surfaceVpls.size(), 3000u);
    EXPECT_EQ(all.surfaceVplPaths, all.lightPaths);
    settings.surfaceVplLimit = 3000;
    const VrlSet a = traceWithThreads(*scene, settings, 1), b = traceWithThreads(*scene, settings, 2);
    ASSERT_EQ(a.surfaceVpls.size(), b.surfaceVpls.size());
    EXPECT_EQ(std::memcmp(a.surfaceVpls.data(), b.surfaceVpls.data(), a.surfaceVpls.size() * sizeof(SurfaceVpl)), 0);
    EXPECT_EQ(a.surfaceVplPaths, b.surfaceVplPaths);
    EXPECT_LE(a.surfaceVpls.size(), 3000u);
    EXPECT_GT(a.surfaceVpls.size(), 2000u) << "a chunk of 64 paths should not leave this much of the limit unused";
    EXPECT_EQ(a.surfaceVplPaths % 64, 0u) << "whole chunks of 64 paths";
    EXPECT_LT(a.surfaceVplPaths, a.lightPaths);
    ASSERT_EQ(a.vrls.size(), all.vrls.size());
    EXPECT_EQ(std::memcmp(a.vrls.data(), all.vrls.data(), a.vrls.size() * sizeof(Vrl)), 0);
    const double ratio = double(all.lightPaths) / double(a.surfaceVplPaths);
    for (size_t i = 0; i < a.surfaceVpls.size(); ++i) {
        const SurfaceVpl &limited = a.surfaceVpls[i], &full = all.surfaceVpls[i];
        ASSERT_EQ(limited.position, full.position) << i;
        ASSERT_EQ(limited.shape, full.shape) << i;
        for (int c = 0; c < 3; ++c)
            ASSERT_NEAR(double(limited.flux[c]), double(full.flux[c]) * ratio, 1e-5 * double(full.flux[c]) * ratio) << i;
    }
    settings.surfaceVplLimit = 1;  // below one chunk's: that chunk's all the same
    const VrlSet one = traceVrls(*scene, settings);
    EXPECT_EQ(one.surfaceVplPaths, 64u);
    ASSERT_GT(one.surfaceVpls.size(), 1u);
    EXPECT_EQ(one.surfaceVpls[1].position, all.surfaceVpls[1].position);
}

TEST(LightTracer, VrlsLieInsideTheirMediumWithPositiveLength) {
    const auto scene = Scene::build(test::mediumOnlyCube(Rgb(0.8f), Rgb(0.2f), 0.0f));
    LightTracingSettings settings;
    settings.targetVrls = 20000;
    const VrlSet set = traceVrls(*scene, settings);
    for (const Vrl& v : set.vrls) {
        ASSERT_GT(v.length, 0.0f);
        ASSERT_EQ(v.medium, 0);
        ASSERT_TRUE(isFinite(v.flux));
        for (const Vec3& p : {v.origin, v.end()}) {
            ASSERT_LE(std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}), 1.0f + 1e-3f);
        }
    }
}

// Sum over VRLs of flux * length, with the standard error from per-path sums
// (paths are independent; the VRLs of one path are not).
struct EnergyEstimate {
    Rgb mean;
    Rgb standardError;
};
EnergyEstimate fluxTimesLength(const Scene& scene, int maxDepth, uint64_t paths, uint64_t seed) {
    // Trace in independent groups to get a standard error.
    const int groups = 16;
    double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
    for (int g = 0; g < groups; ++g) {
        LightTracingSettings settings;
        settings.lightPaths = paths / groups;
        settings.maxDepth = maxDepth;
        settings.seed = seed * 1000 + g;
        settings.targetVrls = 0;
        const VrlSet set = traceVrls(scene, settings);
        Rgb total(0.0f);
        for (const Vrl& v : set.vrls) total += v.flux * v.length;
        for (int c = 0; c < 3; ++c) {
            sum[c] += total[c];
            sum2[c] += double(total[c]) * total[c];
        }
    }
    EnergyEstimate e;
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / groups;
        e.mean[c] = float(mean);
        e.standardError[c] = float(std::sqrt(std::max(0.0, sum2[c] / groups - mean * mean) / (groups - 1)));
    }
    return e;
}

// 64k paths in 16 groups, seed fixed; 4.5 group standard errors per channel
// (t with 15 dof: a false failure below 1e-3 over the 9 comparisons).
void expectEnergy(const Rgb& sigmaS, const Rgb& sigmaA, float g, int maxDepth) {
    const Rgb intensity(2.0f, 3.0f, 4.0f);
    const auto scene = Scene::build(test::pointLightInInfiniteMedium(intensity, Vec3(0.0f), sigmaS, sigmaA, g));
    const EnergyEstimate e = fluxTimesLength(*scene, maxDepth, 1 << 16, 5);
    for (int c = 0; c < 3; ++c) {
        const double power = 4.0 * M_PI * intensity[c], sigmaT = sigmaS[c] + sigmaA[c], albedo = sigmaS[c] / sigmaT;
        // VRLs are segments j = 1 .. maxDepth - 2 (each needs two more segments to the camera).
        const double series = maxDepth < 0 ? 1.0 / (1.0 - albedo) : (1.0 - std::pow(albedo, maxDepth - 2)) / (1.0 - albedo);
        const double expected = power / sigmaT * series;
        EXPECT_GT(e.standardError[c], 0.0f);
        EXPECT_NEAR(e.mean[c], expected, 4.5 * e.standardError[c]) << "channel " << c << " maxDepth " << maxDepth;
    }
}

TEST(LightTracer, EnergyInGreyInfiniteMediumUnlimitedDepth) { expectEnergy(Rgb(0.6f), Rgb(0.4f), 0.0f, -1); }
TEST(LightTracer, EnergyInChromaticMediumUnlimitedDepth) {
    expectEnergy(Rgb(0.3f, 0.9f, 1.5f), Rgb(0.5f, 0.2f, 0.3f), 0.7f, -1);
}
TEST(LightTracer, EnergyWithDepthLimit) { expectEnergy(Rgb(0.3f, 0.9f, 1.5f), Rgb(0.5f, 0.2f, 0.3f), 0.0f, 5); }

TEST(LightTracer, MaxDepthBelowThreeDepositsNothing) {
    const auto scene = Scene::build(test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), Rgb(0.5f), Rgb(0.1f), 0.0f));
    LightTracingSettings settings;
    settings.lightPaths = 1000;
    settings.targetVrls = 0;
    for (int depth : {1, 2}) {
        settings.maxDepth = depth;
        EXPECT_TRUE(traceVrls(*scene, settings).vrls.empty()) << "maxDepth " << depth;
    }
    // maxDepth 3: only first segments, which start at the light (grey: no null collisions).
    settings.maxDepth = 3;
    const VrlSet set = traceVrls(*scene, settings);
    EXPECT_GT(set.vrls.size(), 0u);
    EXPECT_LE(set.vrls.size(), 1000u);
    for (const Vrl& v : set.vrls) ASSERT_LT(v.origin.length(), 1e-3f);
}

// LightPathWalker::walk follows the very paths deposit() turns into VRLs: in a grey
// medium (no null collisions) each medium vertex of path i is where one of its VRLs
// ends and the next begins, numbered 1, 2, ... along the path, with the flux of
// the VRL that ends there times sigma_s / sigma_t; and walk stops at the vertices
// whose camera connection would exceed maxDepth (depth + 1 <= maxDepth), not before
// (some path reaches depth maxDepth - 1).
TEST(LightTracer, WalkVisitsTheVerticesBetweenThePathsVrls) {
    const Rgb sigmaS(0.5f), sigmaA(0.1f);
    const auto scene = Scene::build(test::pointLightInInfiniteMedium(Rgb(1.0f), Vec3(0.0f), sigmaS, sigmaA, 0.3f));
    for (const int maxDepth : {-1, 4}) {
        LightTracingSettings settings;
        settings.seed = 9;
        settings.maxDepth = maxDepth;
        const LightPathWalker walker(*scene, settings);
        size_t visited = 0;
        int deepest = 0;
        for (uint64_t i = 0; i < 200; ++i) {
            std::vector<Vrl> vrls;
            walker.deposit(i, vrls);
            std::vector<LightPathVertex> vertices;
            walker.walk(i, [&](const LightPathVertex& v) { vertices.push_back(v); });
            visited += vertices.size();
            for (size_t j = 0; j < vertices.size(); ++j) {
                const LightPathVertex& v = vertices[j];
                EXPECT_EQ(v.depth, int(j) + 1);
                EXPECT_EQ(v.surface, nullptr);
                deepest = std::max(deepest, v.depth);
                if (maxDepth > 0) {
                    EXPECT_LE(v.depth + 1, maxDepth);
                }
                // VRL j ends at vertex j (VRLs stop at maxDepth - 2 segments, vertices go one further).
                if (j >= vrls.size()) continue;
                const Vrl& before = vrls[j];
                EXPECT_LT((before.origin + before.direction * before.length - v.position).length(), 1e-3f);
                EXPECT_LT((before.direction - v.direction).length(), 1e-5f);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(v.weight[c], before.flux[c] * sigmaS[c] / (sigmaS[c] + sigmaA[c]), 1e-5f * before.flux[c]);
                if (j + 1 < vrls.size()) {
                    EXPECT_LT((vrls[j + 1].origin - v.position).length(), 1e-4f);
                }
            }
            // Unlimited: every VRL ends at a collision, where the path scatters (and may then end in roulette).
            if (maxDepth < 0) {
                EXPECT_EQ(vertices.size(), vrls.size()) << "path " << i;
            }
        }
        EXPECT_GT(visited, 200u);
        if (maxDepth > 0) {
            EXPECT_EQ(deepest, maxDepth - 1);
        }
    }
}

}  // namespace
}  // namespace vrl
