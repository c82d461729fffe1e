// Part (c)'s cut over interleaved points (interleaved_points.h, surface_lightcuts_estimator.h):
// four points of a diffuse sphere in fog (one of them absent, as where a pixel's
// stratum sees no surface), 3000 random VRLs in a tree, fixed seeds.
//  - At threshold 0 the cut reaches every VRL, and VRL k is evaluated at point
//    (k + o) mod Q from its own stream: the result is that sum computed directly
//    (float summation order differs: relative 1e-5).
//  - Summed over the Q offsets, the interleaved results equal the sum over the
//    points of the whole (c) at each: the identity E_o[I] = (1/Q) sum_q L(x_q)
//    the estimator's unbiasedness rests on (relative 1e-5, summation order).
//  - With a threshold, a node's bound is the largest of its bounds at the points,
//    so every estimate is held against a bound that holds where it is made and, a
//    diffuse receiver in an isotropic medium, never exceeds it; the pixel's value
//    stays within 3 thresholds (0.03) of the plain interleaved sum for every
//    offset (each node's error is within one). The points are far apart (normals
//    60-70 degrees apart): with the cut point's bound alone the error was 13-72%.
//  - A class's representative stands for several points (the same pointer at
//    several places): over both representatives of a two-point class and the
//    offsets, the sum is 2 x sum_q L(x_q) (relative 1e-5); the cut takes one bound
//    per class, and with one class and absent points the one point's own deferred
//    bounds, holding and within 5 thresholds of the plain interleaved sum.
//  - A point whose bound is 0 for every node (its camera path's throughput is 0)
//    is not taken as the cut point, and at threshold 0.01 the result stays within
//    5% of the plain interleaved sum (with that point's bound alone it was off by
//    99%: the cut stopped almost at once).
#include "render/lightcuts/cuts/surface_lightcuts_estimator.h"

#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl_estimator.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>

namespace vrl {
namespace {

constexpr uint64_t kStreamKey = 0x5eed;

struct Fixture {
    std::unique_ptr<Scene> scene;
    LightTree tree;
    std::vector<CameraPathSurface> surfaces;  // the present points
    InterleavedPoints points;                 // Q = 4; point 1 absent
};

Fixture sphereInFog(const BsdfDescription& bsdf = test::diffuseBsdf(Rgb(0.6f, 0.5f, 0.4f), false)) {
    Fixture f;
    f.scene = Scene::build(test::sphereInMedium(Rgb(0.8f), Rgb(0.2f), 0.0f, bsdf, false));
    Rng rng(11, 0);
    std::vector<Vrl> vrls;
    for (int i = 0; i < 3000; ++i) {
        Vrl v;
        v.medium = 0;
        v.flux = Rgb(0.2f + rng.next(), 0.2f + rng.next(), 0.2f + rng.next()) * 1e-3f;
        v.origin = Vec3(6 * rng.next() - 3.0f, 6 * rng.next() - 3.0f, 6 * rng.next() - 3.0f);
        const float z = 2 * rng.next() - 1, phi = 6.2831853f * rng.next(), r = std::sqrt(1 - z * z);
        v.direction = Vec3(r * std::cos(phi), r * std::sin(phi), z);
        v.length = 0.1f + 0.5f * rng.next();
        if ((v.origin + v.direction * v.length).length() < 1.0f || v.origin.length() < 1.0f) continue;
        vrls.push_back(v);
    }
    f.tree = LightTree::build(std::move(vrls), LightTreeSettings{256, 11});
    // Three points on the sphere's camera side, some way apart (a pixel's strata, enlarged).
    for (const Vec3& target : {Vec3(-0.3f, 0.2f, -0.9f), Vec3(0.5f, 0.6f, -0.6f), Vec3(0.1f, -0.7f, -0.7f)}) {
        const Vec3 eye(0.0f, 0.0f, -3.5f);
        const auto hit = f.scene->intersect(Ray{eye, (target - eye).normalized()});
        if (!hit) {
            ADD_FAILURE() << "the fixture's ray misses the sphere";
            continue;
        }
        f.surfaces.push_back(cameraPathSurface(*f.scene, *hit, -(target - eye).normalized(), 0, Rgb(1.0f), 0));
    }
    f.points.count = 4;
    if (f.surfaces.size() == 3) f.points.points = {&f.surfaces[0], nullptr, &f.surfaces[1], &f.surfaces[2]};
    return f;
}

CutSettings threshold(float error) {
    CutSettings settings;
    settings.errorThreshold = error;
    settings.maxCutSize = 1u << 30;
    return settings;
}

// VRL k at `x` from its own stream, as the cut's leaves evaluate it.
Rgb vrlAt(const VrlSurfaceEstimator& estimator, const LightTree& tree, uint32_t k, const CameraPathSurface& x) {
    Rng rng = vrlStream(kStreamKey, k);
    return estimator.contribution(tree.vrls()[k], x, rng);
}

// The plain interleaved sum: every VRL at its point, from its own stream.
Rgb plainInterleaved(const Fixture& f, const VrlSurfaceEstimator& estimator) {
    Rgb sum(0.0f);
    for (uint32_t k = 0; k < f.tree.vrls().size(); ++k)
        if (const CameraPathSurface* x = f.points.at(k)) sum += vrlAt(estimator, f.tree, k, *x);
    return sum;
}

void expectNear(const Rgb& a, const Rgb& b, double relative, const char* what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], relative * std::abs(b[c]) + 1e-12) << what << " channel " << c;
}

// The cut's results summed over the Q offsets of `points`.
Rgb sumOverOffsets(const SurfaceLightcutsEstimator& cut, InterleavedPoints points) {
    Rgb sum(0.0f);
    for (uint32_t offset = 0; offset < points.count; ++offset) {
        points.offset = offset;
        CutStatistics statistics;
        sum += cut.estimate(points, kStreamKey, statistics);
    }
    return sum;
}

// The whole (c) at each present point, summed.
Rgb sumOverPoints(const SurfaceLightcutsEstimator& cut, const Fixture& f) {
    Rgb sum(0.0f);
    for (const CameraPathSurface& x : f.surfaces) {
        CutStatistics statistics;
        sum += cut.estimate(x, kStreamKey, statistics);
    }
    return sum;
}

TEST(SurfaceVrlCut, OffsetsAverageToTheMeanOverThePoints) {
    Fixture f = sphereInFog();
    ASSERT_EQ(f.surfaces.size(), 3u);
    const VrlSurfaceEstimator estimator(*f.scene, 1);
    const SurfaceLightcutsEstimator cut(*f.scene, f.tree, estimator, threshold(0.0f));
    // Both are 4 x the pixel's estimate: sum over o of I_o, and sum over q of L(x_q) (x_1 absent: 0).
    expectNear(sumOverOffsets(cut, f.points), sumOverPoints(cut, f), 1e-5, "sum over offsets");
}

TEST(SurfaceVrlCut, RepresentativesAverageToTheMeanOverThePoints) {
    // Points 0 and 2 one class (as on one flat piece of surface), represented by either
    // with probability 1/2; point 3 its own class; point 1 absent. Over both
    // representatives and the four offsets the results add up to 2 x sum_q L(x_q): the
    // identity interleaved_points.h's classes rest on.
    Fixture f = sphereInFog();
    ASSERT_EQ(f.surfaces.size(), 3u);
    const VrlSurfaceEstimator estimator(*f.scene, 1);
    const SurfaceLightcutsEstimator cut(*f.scene, f.tree, estimator, threshold(0.0f));
    Rgb overChoices(0.0f);
    for (const CameraPathSurface* representative : {&f.surfaces[0], &f.surfaces[1]}) {
        f.points.points = {representative, nullptr, representative, &f.surfaces[2]};
        overChoices += sumOverOffsets(cut, f.points);
    }
    expectNear(overChoices, sumOverPoints(cut, f) * 2.0f, 1e-5, "sum over representatives and offsets");
}

// For every offset of f.points: threshold 0 (`exact`) gives the plain interleaved sum;
// `cut` (threshold 0.01) exceeds no bound and stays within `tolerance` of that sum.
void expectCutHolds(Fixture& f, const VrlSurfaceEstimator& estimator, const SurfaceLightcutsEstimator& exact,
                    const SurfaceLightcutsEstimator& cut, const std::string& label, double tolerance) {
    for (uint32_t offset = 0; offset < 4; ++offset) {
        f.points.offset = offset;
        const Rgb plain = plainInterleaved(f, estimator);
        ASSERT_GT(luminance(plain), 0.0f);
        CutStatistics exactStatistics;
        expectNear(exact.estimate(f.points, kStreamKey, exactStatistics), plain, 1e-5, "threshold 0");
        CutStatistics statistics;
        const Rgb walked = cut.estimate(f.points, kStreamKey, statistics);
        const double error = std::abs(double(luminance(walked)) - luminance(plain)) / luminance(plain);
        std::printf("%s, offset %u: cut size %u, %u of %u estimates bounded, relative error %.4f against the plain "
                    "interleaved sum\n",
                    label.c_str(), offset, statistics.cutSize, statistics.boundedEstimates, statistics.evaluated, error);
        EXPECT_EQ(statistics.boundExceeded, 0u) << label << ", offset " << offset;
        EXPECT_GT(statistics.boundedEstimates, 10u);
        EXPECT_LT(error, tolerance) << label << ", offset " << offset;
    }
}

TEST(SurfaceVrlCut, CutAgainstThePlainInterleavedSum) {
    Fixture f = sphereInFog();
    ASSERT_EQ(f.surfaces.size(), 3u);
    const VrlSurfaceEstimator estimator(*f.scene, 1);
    const SurfaceLightcutsEstimator exact(*f.scene, f.tree, estimator, threshold(0.0f));
    const SurfaceLightcutsEstimator cut(*f.scene, f.tree, estimator, threshold(0.01f));
    // Each node's error is within the threshold of the total; a cut's errors add up,
    // partly cancelling: within 3 thresholds (measured 0.3-1.9%).
    expectCutHolds(f, estimator, exact, cut, "three points", 0.03);
}

TEST(SurfaceVrlCut, RepresentativesAreBoundedOncePerClass) {
    // A representative standing for two points (classes {0, 2} and {3}; point 1 absent),
    // and a single representative with absent points ({0, 2}; 1 and 3 absent), on a
    // diffuse and on a glossy sphere (rough plastic, GGX 0.1: there a node's cheap bound
    // takes the largest of its parent's factors at the points, and is made tight before it
    // is refined). At threshold 0 the cut is the plain interleaved sum; at 0.01 no
    // estimate exceeds its bound and the result stays within 5 thresholds of that sum, for
    // every offset (each node's error is within one threshold of the total, and some 400
    // nodes' errors add up, partly cancelling: measured 0.3-3.0%; the same 5 as the blind
    // cut point's test below).
    BsdfDescription glossy;
    glossy.kind = BsdfDescription::Kind::RoughPlastic;
    glossy.distribution = MicrofacetKind::GGX;
    glossy.alphaU = glossy.alphaV = 0.1f;
    glossy.reflectance.value = Rgb(0.6f, 0.5f, 0.4f);
    for (const bool isGlossy : {false, true}) {
        Fixture f = isGlossy ? sphereInFog(glossy) : sphereInFog();
        ASSERT_EQ(f.surfaces.size(), 3u);
        const VrlSurfaceEstimator estimator(*f.scene, 1);
        const SurfaceLightcutsEstimator exact(*f.scene, f.tree, estimator, threshold(0.0f));
        const SurfaceLightcutsEstimator cut(*f.scene, f.tree, estimator, threshold(0.01f));
        const CameraPathSurface* a = &f.surfaces[0];
        const CameraPathSurface* b = &f.surfaces[2];
        for (const auto& layout : {std::array<const CameraPathSurface*, 4>{a, nullptr, a, b},
                                   std::array<const CameraPathSurface*, 4>{a, nullptr, a, nullptr}}) {
            f.points.points = layout;
            std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints> distinct{};
            EXPECT_EQ(f.points.distinct(distinct), layout[3] ? 2u : 1u);
            expectCutHolds(f, estimator, exact, cut,
                           std::string(isGlossy ? "glossy" : "diffuse") + (layout[3] ? ", two classes" : ", one class"),
                           0.05);
        }
    }
}

TEST(SurfaceVrlCut, ACutPointThatSeesNothingDoesNotStopTheCut) {
    Fixture f = sphereInFog();
    ASSERT_EQ(f.surfaces.size(), 3u);
    CameraPathSurface blind = f.surfaces[0];
    blind.throughput = Rgb(0.0f);  // every bound at it is 0
    f.points.points[1] = &blind;   // present, but contributes nothing
    f.points.offset = 3;
    const VrlSurfaceEstimator estimator(*f.scene, 1);
    const Rgb plain = plainInterleaved(f, estimator);
    const SurfaceLightcutsEstimator cut(*f.scene, f.tree, estimator, threshold(0.01f));
    CutStatistics statistics;
    EXPECT_NE(cut.cutPoint(f.points), &blind);
    const Rgb walked = cut.estimate(f.points, kStreamKey, statistics);
    const double error = std::abs(double(luminance(walked)) - luminance(plain)) / luminance(plain);
    std::printf("cut point blind: cut size %u, relative error %.4f against the plain interleaved sum (%g, %g)\n",
                statistics.cutSize, error, double(luminance(walked)), double(luminance(plain)));
    EXPECT_GT(statistics.cutSize, 10u);
    EXPECT_LT(error, 0.05);
}

}  // namespace
}  // namespace vrl
