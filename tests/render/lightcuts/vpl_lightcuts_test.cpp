// VPL Lightcuts (the paper's baseline, render/lightcuts/cuts/vpl_lightcuts_estimator.h): the box distance, VPL
// deposition by the light tracer against the VRLs of the same light paths, the
// point-cluster light tree, the exactness of a cut at error threshold 0, the
// conservativeness of the node bound, and the rendered part (d) against plain
// VRLs over the same light paths, plus determinism.
#include "render/core/distance.h"
#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/cuts/vpl_lightcuts_estimator.h"
#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/vrl/light_tracer.h"
#include "tests/support/light_tree_order.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace vrl {
namespace {

// Isotropic grey and chromatic media (the chromatic one has null collisions).
struct MediumCase {
    const char* name;
    Rgb sigmaS, sigmaA;
    float g;
};
const MediumCase kGrey{"grey", Rgb(0.8f), Rgb(0.2f), 0.0f};
const MediumCase kChromatic{"chromatic", Rgb(0.4f, 0.8f, 1.4f), Rgb(0.2f, 0.1f, 0.05f), 0.0f};

VrlSet tracePoints(const Scene& scene, uint64_t lightPaths, uint64_t seed, LightDeposit deposit = LightDeposit::Points) {
    LightTracingSettings settings;
    settings.deposit = deposit;
    settings.lightPaths = lightPaths;
    settings.seed = seed;
    return traceVrls(scene, settings);
}

Vec3 uniformIn(Rng& rng, float halfSize) {
    return Vec3(rng.next() * 2.0f - 1.0f, rng.next() * 2.0f - 1.0f, rng.next() * 2.0f - 1.0f) * halfSize;
}

Vec3 uniformDirection(Rng& rng) {
    const float z = 1.0f - 2.0f * rng.next(), phi = 6.28318530718f * rng.next();
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

bool allInfinite(const Rgb& c) { return std::isinf(c.x) && std::isinf(c.y) && std::isinf(c.z) && minComponent(c) > 0; }

// ---------------------------------------------------------------------------
// 1. distancePointBox

TEST(VplLightcuts, DistancePointBoxInsideOnFaceAndOffCorner) {
    const Imath::Box3f box(Vec3(-1.0f, 0.0f, 2.0f), Vec3(1.0f, 3.0f, 4.0f));
    EXPECT_EQ(distancePointBox(Vec3(0.0f, 1.0f, 3.0f), box), 0.0);      // inside
    EXPECT_EQ(distancePointBox(Vec3(-1.0f, 0.0f, 2.0f), box), 0.0);     // on a corner
    EXPECT_EQ(distancePointBox(Vec3(1.0f, 1.5f, 3.0f), box), 0.0);      // on a face
    EXPECT_EQ(distancePointBox(Vec3(3.0f, 1.5f, 3.0f), box), 2.0);      // off the +x face
    EXPECT_EQ(distancePointBox(Vec3(0.0f, -0.5f, 3.0f), box), 0.5);     // off the -y face
    EXPECT_EQ(distancePointBox(Vec3(0.5f, 2.0f, 6.0f), box), 2.0);      // off the +z face
    EXPECT_EQ(distancePointBox(Vec3(4.0f, 7.0f, 4.0f), box), 5.0);      // off an edge (3-4-5)
    EXPECT_EQ(distancePointBox(Vec3(3.0f, 5.0f, 5.0f), box), 3.0);      // off the max corner: sqrt(4+4+1)
    EXPECT_EQ(distancePointBox(Vec3(-2.0f, -2.0f, 0.0f), box), 3.0);    // off the min corner: sqrt(1+4+4)
    EXPECT_DOUBLE_EQ(distancePointBox(Vec3(2.0f, 4.0f, 5.0f), box), std::sqrt(3.0));
    // A degenerate (point) box, as a VPL leaf has.
    const Imath::Box3f point(Vec3(1.0f, 2.0f, 3.0f), Vec3(1.0f, 2.0f, 3.0f));
    EXPECT_EQ(distancePointBox(Vec3(1.0f, 2.0f, 3.0f), point), 0.0);
    EXPECT_EQ(distancePointBox(Vec3(1.0f, 2.0f, 15.0f), point), 12.0);
}

// ---------------------------------------------------------------------------
// 2. VPL deposition against the VRLs of the same light paths.
//
// With the same seed, Points and Segments trace the same paths (the deposit
// consumes no random numbers). Per collision-free stretch of length L with
// throughput Phi, the VRL scores Phi L sigma_s and the VPL (at the stretch's end,
// if it ends at a collision rather than a surface) scores Phi sigma_s / majorant;
// both have expectation Phi sigma_s E[L]. Their difference D per run is zero-mean
// noise. Over K = 16 seeds, mean(D) must lie within 5 standard errors of 0
// (Student t, 15 dof: P(|t| > 5) ~ 2e-4 per channel), and that test must have
// power: the standard error must be below 1% of the VRL total, so a missing or
// wrong sigma_s / majorant factor (>= 20% here) cannot pass.

void expectPointsMatchSegments(const Scene& scene, const char* name) {
    constexpr int kRuns = 16;
    constexpr uint64_t kPaths = 2000;
    double sumD[3] = {0, 0, 0}, sumD2[3] = {0, 0, 0}, sumVrl[3] = {0, 0, 0};
    size_t pointCount = 0;
    for (int r = 0; r < kRuns; ++r) {
        const uint64_t seed = 100 + r;
        const VrlSet points = tracePoints(scene, kPaths, seed, LightDeposit::Points);
        const VrlSet segments = tracePoints(scene, kPaths, seed, LightDeposit::Segments);
        ASSERT_EQ(points.lightPaths, kPaths);
        ASSERT_EQ(segments.lightPaths, kPaths);
        ASSERT_GT(points.vrls.size(), 100u) << name;
        pointCount += points.vrls.size();
        double vpl[3] = {0, 0, 0}, vrl[3] = {0, 0, 0};
        for (const Vrl& v : points.vrls) {
            ASSERT_EQ(v.length, 0.0f) << name;
            ASSERT_GE(v.medium, 0) << name;
            ASSERT_LT(size_t(v.medium), scene.media().size()) << name;
            ASSERT_FALSE(scene.media()[v.medium].isNonScattering()) << name;
            ASSERT_TRUE(isFinite(v.flux)) << name;
            ASSERT_GE(minComponent(v.flux), 0.0f) << name;
            ASSERT_TRUE(std::isfinite(v.origin.x + v.origin.y + v.origin.z)) << name;
            ASSERT_NEAR(v.direction.length(), 1.0f, 1e-4f) << name;
            for (int c = 0; c < 3; ++c) vpl[c] += v.flux[c];
        }
        for (const Vrl& v : segments.vrls) {
            const Rgb sigmaS = scene.media()[v.medium].sigmaS();
            for (int c = 0; c < 3; ++c) vrl[c] += double(v.flux[c]) * v.length * sigmaS[c];
        }
        for (int c = 0; c < 3; ++c) {
            const double d = vpl[c] - vrl[c];
            sumD[c] += d;
            sumD2[c] += d * d;
            sumVrl[c] += vrl[c];
        }
    }
    std::printf("%s: %zu VPLs per run on average\n", name, pointCount / kRuns);
    for (int c = 0; c < 3; ++c) {
        const double mean = sumD[c] / kRuns;
        const double se = std::sqrt(std::max(0.0, sumD2[c] / kRuns - mean * mean) / (kRuns - 1));
        const double total = sumVrl[c] / kRuns;
        std::printf("%s channel %d: VRL total %.5f, VPL - VRL %.6f +- %.6f\n", name, c, total, mean, se);
        EXPECT_GT(total, 0.0) << name;
        EXPECT_LT(std::abs(mean), 5.0 * se + 1e-6 * total) << name << " channel " << c;
        EXPECT_LT(se, 0.01 * total) << name << " channel " << c << ": too noisy to mean much";
    }
}

TEST(VplLightcuts, PointsEstimateTheSameLightAsSegmentsGrey) {
    const auto scene = Scene::build(test::mediumOnlyCube(kGrey.sigmaS, kGrey.sigmaA, kGrey.g));
    expectPointsMatchSegments(*scene, "grey cube");
}

TEST(VplLightcuts, PointsEstimateTheSameLightAsSegmentsChromatic) {
    const auto scene = Scene::build(test::mediumOnlyCube(kChromatic.sigmaS, kChromatic.sigmaA, kChromatic.g));
    expectPointsMatchSegments(*scene, "chromatic cube");
    // Surfaces (diffuse bounces, an area light) and an HG medium.
    const auto room = Scene::build(test::litRoomWithOccluder(kChromatic.sigmaS * 0.5f, kChromatic.sigmaA * 0.5f, 0.5f));
    expectPointsMatchSegments(*room, "chromatic room");
}

// ---------------------------------------------------------------------------
// 3. The point-cluster light tree.

TEST(VplLightcuts, PointTreeSumsFluxAndBoundsPositions) {
    const auto scene = Scene::build(test::litRoomWithOccluder(kChromatic.sigmaS * 0.5f, kChromatic.sigmaA * 0.5f, 0.5f));
    const VrlSet set = tracePoints(*scene, 3000, 7);
    ASSERT_GT(set.vrls.size(), 5000u);
    // A small partition size: both the partition and the top-level clustering run.
    const LightTree tree = LightTree::build(set.vrls, LightTreeSettings{256, 7, true});
    const auto& nodes = tree.nodes();
    const auto& vpls = tree.vrls();
    const size_t n = vpls.size();
    ASSERT_EQ(n, set.vrls.size());
    ASSERT_EQ(nodes.size(), 2 * n - 1);
    ASSERT_GE(tree.root(), 0);
    double total[3] = {0, 0, 0};
    for (const Vrl& v : vpls)
        for (int c = 0; c < 3; ++c) total[c] += v.flux[c];
    for (size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(nodes[i].isLeaf());
        EXPECT_EQ(nodes[i].fluxLength, vpls[i].flux) << "leaf " << i;
        EXPECT_EQ(nodes[i].clusterFlux, vpls[i].flux) << "leaf " << i;
    }
    const LightTreeNode& root = nodes[tree.root()];
    EXPECT_EQ(root.vrlCount, n);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(root.fluxLength[c], total[c], 1e-5 * total[c]) << "channel " << c;
    // Parents, then per node: cluster flux = summed flux = sum of the children's.
    std::vector<int32_t> parent(nodes.size(), -1);
    for (size_t i = n; i < nodes.size(); ++i) {
        const LightTreeNode& node = nodes[i];
        ASSERT_FALSE(node.isLeaf());
        ASSERT_GE(node.left, 0);
        ASSERT_GE(node.right, 0);
        parent[node.left] = int32_t(i);
        parent[node.right] = int32_t(i);
        EXPECT_EQ(node.clusterFlux, node.fluxLength) << "node " << i;
        const Rgb children = nodes[node.left].fluxLength + nodes[node.right].fluxLength;
        for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(node.fluxLength[c], children[c]) << "node " << i;
        EXPECT_EQ(node.vrlCount, nodes[node.left].vrlCount + nodes[node.right].vrlCount);
        EXPECT_LT(node.representative, n);
    }
    // Every node's box holds the position of every VPL below it (walk up from each leaf),
    // and a leaf's box is its point.
    for (size_t i = 0; i < n; ++i) {
        const Vec3& p = vpls[i].origin;
        EXPECT_EQ(nodes[i].box.min, p);
        EXPECT_EQ(nodes[i].box.max, p);
        int depth = 0;
        for (int32_t a = parent[i]; a >= 0; a = parent[a]) {
            ASSERT_TRUE(nodes[a].box.intersects(p)) << "node " << a << " misses VPL " << i;
            ASSERT_LT(++depth, int(n)) << "cycle";
        }
    }
    EXPECT_EQ(parent[tree.root()], -1);
}

// ---------------------------------------------------------------------------
// 4. At error threshold 0 (and no cut size limit) the cut refines to every VPL:
// the gather is the brute-force sum. The tolerance 1e-4 (relative) covers float
// accumulation over ~1e4 terms, including the estimates subtracted again when
// their nodes are refined.

void expectExactGather(const Scene& scene, float halfSize, uint64_t paths, const char* name) {
    const VrlSet set = tracePoints(scene, paths, 11);
    ASSERT_GT(set.vrls.size(), 2000u) << name;
    const LightTree tree = LightTree::build(set.vrls, LightTreeSettings{512, 11, true});
    CutSettings cut;
    cut.errorThreshold = 0.0f;
    cut.maxCutSize = std::numeric_limits<uint32_t>::max();
    const VplLightcutsEstimator estimator(scene, tree, cut);
    Rng rng(5, 0);
    for (int k = 0; k < 6; ++k) {
        const Vec3 x = uniformIn(rng, halfSize);
        const int medium = scene.mediumAt(x);
        ASSERT_GE(medium, 0) << name;
        const Vec3 toCamera = uniformDirection(rng);
        double brute[3] = {0, 0, 0};
        for (const Vrl& v : tree.vrls()) {
            const Rgb c = estimator.vplContribution(v, v.flux, x, toCamera, medium);
            for (int ch = 0; ch < 3; ++ch) brute[ch] += c[ch];
        }
        CutStatistics statistics;
        const Rgb gathered = estimator.gather(x, toCamera, medium, statistics);
        std::printf("%s point %d: gather (%.6g %.6g %.6g), brute force (%.6g %.6g %.6g), cut %u of %zu\n", name, k,
                    gathered.x, gathered.y, gathered.z, brute[0], brute[1], brute[2], statistics.cutSize,
                    tree.vrls().size());
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_GT(brute[ch], 0.0) << name;
            EXPECT_NEAR(gathered[ch], brute[ch], 1e-4 * brute[ch]) << name << " point " << k << " channel " << ch;
        }
        EXPECT_EQ(statistics.cutSize, uint32_t(tree.vrls().size())) << name << ": threshold 0 cuts at the leaves";
    }
}

TEST(VplLightcuts, ZeroThresholdGatherIsBruteForceSum) {
    // Chromatic HG medium in a convex null-bounded cube (no visibility rays)...
    const auto cube = Scene::build(test::mediumOnlyCube(kChromatic.sigmaS, kChromatic.sigmaA, 0.6f));
    expectExactGather(*cube, 0.95f, 2500, "HG cube");
    // ... and a room with an occluder (visibility rays, surface bounces).
    const auto room = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    expectExactGather(*room, 1.9f, 2500, "room");
}

// ---------------------------------------------------------------------------
// 5. The bound is conservative in an isotropic medium with a convex boundary:
// for every inner node, at every test point, bound >= the representative's
// estimate with the cluster flux, and >= each single VPL's exact term below the
// node (per channel); infinite when the point lies in the node's box.

void expectConservativeBound(const Scene& scene, const char* name) {
    ASSERT_TRUE(scene.media()[0].boundaryConvex());
    ASSERT_TRUE(scene.media()[0].phase().isIsotropic());
    const VrlSet set = tracePoints(scene, 4000, 21);
    ASSERT_GT(set.vrls.size(), 5000u) << name;
    const LightTree tree = LightTree::build(set.vrls, LightTreeSettings{512, 21, true});
    const VplLightcutsEstimator estimator(scene, tree, CutSettings{});
    const auto& nodes = tree.nodes();
    const auto& vpls = tree.vrls();
    const size_t n = vpls.size();
    const std::vector<int32_t> order = test::childrenBeforeParents(tree);
    ASSERT_EQ(order.size(), nodes.size());
    const int medium = 0;
    Rng rng(17, 0);
    std::vector<Vec3> points;
    for (int k = 0; k < 6; ++k) points.push_back(uniformIn(rng, 0.98f));
    // Points just outside some node's box, where the bound is tightest.
    for (size_t i = n; i < nodes.size() && points.size() < 12; i += (nodes.size() - n) / 6 + 1) {
        const Vec3 p = nodes[i].box.max + Vec3(0.01f);
        if (std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)}) < 1.0f) points.push_back(p);
    }
    std::vector<Rgb> maxBelow(nodes.size());
    size_t checked = 0, infinite = 0;
    double tightest = std::numeric_limits<double>::infinity();  // least bound / largest VPL term
    for (size_t k = 0; k < points.size(); ++k) {
        const Vec3& x = points[k];
        const Vec3 toCamera = uniformDirection(rng);
        for (int32_t i : order) {
            const LightTreeNode& node = nodes[i];
            if (node.isLeaf()) {
                maxBelow[i] = estimator.vplContribution(vpls[i], vpls[i].flux, x, toCamera, medium);
                continue;
            }
            const Rgb& l = maxBelow[node.left];
            const Rgb& r = maxBelow[node.right];
            maxBelow[i] = Rgb(std::max(l.x, r.x), std::max(l.y, r.y), std::max(l.z, r.z));
            const Rgb b = estimator.bound(i, x, medium);
            if (node.box.intersects(x)) {
                ASSERT_TRUE(allInfinite(b)) << name << ": point " << k << " in the box of node " << i;
                ++infinite;
                continue;
            }
            ASSERT_FALSE(std::isnan(b.x + b.y + b.z)) << name << " node " << i;
            const Rgb e = estimator.vplContribution(vpls[node.representative], node.clusterFlux, x, toCamera, medium);
            for (int c = 0; c < 3; ++c) {
                ASSERT_GE(b[c], e[c]) << name << ": representative of node " << i << " at point " << k << " channel " << c;
                ASSERT_GE(b[c], maxBelow[i][c]) << name << ": a VPL of node " << i << " at point " << k << " channel " << c;
                if (maxBelow[i][c] > 0.0f) tightest = std::min(tightest, double(b[c]) / maxBelow[i][c]);
            }
            ++checked;
        }
    }
    // Inside every inner node's box (its centre): infinite.
    for (size_t i = n; i < nodes.size(); ++i)
        ASSERT_TRUE(allInfinite(estimator.bound(int32_t(i), nodes[i].box.center(), medium))) << name << " node " << i;
    std::printf("%s: %zu finite bounds checked, %zu infinite, least bound / largest VPL term %.6f\n", name, checked,
                infinite, tightest);
    EXPECT_GT(checked, 10 * (nodes.size() - n)) << "most (point, node) pairs have a finite bound";
}

TEST(VplLightcuts, BoundIsConservativeInIsotropicConvexMedium) {
    const auto grey = Scene::build(test::mediumOnlyCube(kGrey.sigmaS, kGrey.sigmaA, 0.0f));
    expectConservativeBound(*grey, "grey cube");
    const auto chromatic = Scene::build(test::mediumOnlyCube(kChromatic.sigmaS, kChromatic.sigmaA, 0.0f));
    expectConservativeBound(*chromatic, "chromatic cube");
}

// ---------------------------------------------------------------------------
// 6. The rendered part (d) against plain VRLs.

SceneDescription smallCube(const MediumCase& m, int side) {
    SceneDescription d = test::mediumOnlyCube(m.sigmaS, m.sigmaA, m.g);
    d.sensor.width = d.sensor.height = side;
    return d;
}

RenderSettings multipleScattering(RenderMethod method, uint64_t seed, uint64_t lightPaths) {
    RenderSettings settings;
    settings.method = method;
    settings.transports = TransportSelection::parse("multiple");
    settings.lightPaths = lightPaths;
    settings.seed = seed;
    return settings;
}

double meanLuminance(const Image& image) {
    double sum = 0.0;
    for (const Rgb& p : image.pixels()) sum += luminance(p);
    return sum / double(image.pixelCount());
}

// Both methods estimate the same part (d); with the same seed and light path
// count they trace the same light paths (VPLs at the collisions of the paths
// whose stretches are the VRLs), so their per-seed difference D is a low-variance
// paired statistic. Over K = 8 seeds, mean(D) must lie within 5 standard errors
// (Student t, 7 dof: P(|t| > 5) ~ 0.0016) plus 2% of the mean for the bias of the
// cut at the default error threshold 0.02 (a node is left unrefined only while
// its bound is below 2% of the gather; over 64 seeds the threshold-0.02 and
// threshold-0 renders of these scenes differed by under 0.5% of the mean, and
// both agreed with plain VRLs within 1 standard error). The VPL gather keeps the
// 1/w^2 singularity, so D is heavy-tailed; the t statistic stays robust to a
// single outlier run, which inflates the standard error as much as the mean.
// Power: the standard error of D must be under 3% of the mean (about 0.9% with
// these seeds), so a missing phase, sigma_s or sigma_s / majorant factor fails.
TEST(VplLightcuts, MultipleScatteringMatchesPlainVrls) {
    for (const MediumCase& m : {kGrey, kChromatic}) {
        const auto scene = Scene::build(smallCube(m, 6));
        constexpr int kRuns = 8;
        double sumD = 0, sumD2 = 0, sumVrl = 0;
        for (int r = 0; r < kRuns; ++r) {
            const uint64_t seed = 40 + r;
            const ImageSet vpl = render(*scene, multipleScattering(RenderMethod::VplLightcuts, seed, 1500));
            const ImageSet vrl = render(*scene, multipleScattering(RenderMethod::Vrl, seed, 1500));
            for (const Rgb& p : vpl.image.pixels()) {
                ASSERT_TRUE(isFinite(p)) << m.name;
                ASSERT_GE(minComponent(p), 0.0f) << m.name;
            }
            ASSERT_EQ(vpl.layers.size(), 4u);
            EXPECT_EQ(vpl.layers[0].first, "multiple");
            EXPECT_EQ(vpl.layers[1].first, "eval");
            EXPECT_EQ(vpl.layers[2].first, "inter");
            EXPECT_EQ(vpl.layers[3].first, "cut");
            for (size_t i = 0; i < vpl.image.pixelCount(); ++i) {
                EXPECT_EQ(vpl.layers[0].second[i], vpl.image[i]);
                EXPECT_GT(vpl.layers[1].second[i].x, 0.0f) << "every pixel sees the medium";
                EXPECT_GE(vpl.layers[3].second[i].x, 1.0f);
                EXPECT_GE(vpl.layers[1].second[i].x, vpl.layers[3].second[i].x) << "cut nodes were evaluated";
            }
            const double a = meanLuminance(vpl.image), b = meanLuminance(vrl.image);
            sumD += a - b;
            sumD2 += (a - b) * (a - b);
            sumVrl += b;
        }
        const double mean = sumD / kRuns, vrlMean = sumVrl / kRuns;
        const double se = std::sqrt(std::max(0.0, sumD2 / kRuns - mean * mean) / (kRuns - 1));
        std::printf("%s: plain VRL mean luminance %.6f, VPL - VRL %.6f +- %.6f\n", m.name, vrlMean, mean, se);
        EXPECT_GT(vrlMean, 0.0);
        EXPECT_LT(std::abs(mean), 5.0 * se + 0.02 * vrlMean) << m.name;
        EXPECT_LT(se, 0.03 * vrlMean) << m.name << ": too noisy to mean much";
    }
}

// ---------------------------------------------------------------------------
// 7. Determinism: the same seed gives the same image bit for bit whatever the
// thread count and tile size; another seed gives another image.

TEST(VplLightcuts, SameSeedSameImageOtherSeedOtherImage) {
    const auto scene = Scene::build(smallCube(kChromatic, 12));
    RenderSettings settings = multipleScattering(RenderMethod::VplLightcuts, 5, 1000);
    ImageSet one, two, other;
    RenderStatistics stats;
    tbb::task_arena(1).execute([&] { one = render(*scene, settings, {}, &stats); });
    settings.tileSize = 5;
    tbb::task_arena(2).execute([&] { two = render(*scene, settings); });
    settings.seed = 6;
    other = render(*scene, settings);
    ASSERT_EQ(one.layers.size(), two.layers.size());
    const size_t bytes = one.image.pixelCount() * sizeof(Rgb);
    EXPECT_EQ(std::memcmp(one.image.pixels().data(), two.image.pixels().data(), bytes), 0);
    for (size_t l = 0; l < one.layers.size(); ++l)
        EXPECT_EQ(std::memcmp(one.layers[l].second.pixels().data(), two.layers[l].second.pixels().data(), bytes), 0)
            << one.layers[l].first;
    EXPECT_NE(std::memcmp(one.image.pixels().data(), other.image.pixels().data(), bytes), 0);
    EXPECT_GT(stats.vrlCount, 0u);
    EXPECT_EQ(stats.lightPaths, 1000u);
    EXPECT_GT(stats.meanCutSize, 1.0);
    EXPECT_LT(stats.meanCutSize, double(stats.vrlCount) * kDefaultVplDistanceSamples);
}

}  // namespace
}  // namespace vrl
