// Tests of SurfaceClusterBound: the upper bound on a light-tree node's
// single-sample part-(c) estimate (a VRL cluster lighting a surface point).
//
// Every node of random light trees against random surface points, one sample
// each, evaluated exactly as the cut does (the representative VRL carrying the
// cluster flux, VrlSurfaceEstimator(scene, 1)). For diffuse and smooth-plastic
// surfaces the bound is proven (header), so zero violations are required over
// more than 10^6 (node, point, sample) triples in grey, chromatic and
// Henyey-Greenstein (g = 0.7, -0.9, 0.95; the phase bounded over cones of
// directions) media, unbounded and in a convex box (where the
// bound uses T_r(d)). The trees include degenerate VRLs: zero length, ending on
// the surface (x inside or touching a node), and tangent to it. For glossy
// surfaces (roughconductor, roughplastic; Beckmann and GGX) the default bound over
// the cone of directions to a node (PreparedBsdf::coneBound) is proven too: zero
// violations, from the node's own box and from its parent's factor (the cut's
// deferred bound). The corners heuristic (GlossyBound::Corners) prints its violation
// rate, capped at 0.1%.
// Fixed seeds throughout; the largest estimate / bound ratio is printed.
#include "render/lightcuts/bounds/surface_cluster_bound.h"

#include "render/core/rng.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl_surface_estimator.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace vrl {
namespace {

struct Medium {
    const char* name;
    Rgb sigmaS, sigmaA;
    float g;
};

// The sphere in `m` (test::sphereInMedium).
std::unique_ptr<Scene> sphereInMedium(const Medium& m, const BsdfDescription& bsdf, bool boxed) {
    return Scene::build(test::sphereInMedium(m.sigmaS, m.sigmaA, m.g, bsdf, boxed));
}

Vec3 direction(Rng& rng) {
    const float z = 2 * rng.next() - 1, phi = 6.2831853f * rng.next(), r = std::sqrt(std::max(0.0f, 1 - z * z));
    return Vec3(r * std::cos(phi), r * std::sin(phi), z);
}

// VRLs inside [-4, 4]^3 (a VRL of medium 0 never leaves it): most generic,
// some ending on the sphere, some tangent to it near its surface, some of zero length.
std::vector<Vrl> randomVrls(Rng& rng, int count) {
    std::vector<Vrl> vrls;
    for (int i = 0; i < count; ++i) {
        Vrl v;
        v.medium = 0;
        v.flux = Rgb(0.2f + rng.next(), 0.2f + rng.next(), 0.2f + rng.next()) * 1e-3f;
        const int kind = i % 8;
        if (kind == 0) {  // ends on the sphere
            const Vec3 onSphere = direction(rng);
            const Vec3 from = onSphere * (1.0f + 2.0f * rng.next()) + direction(rng) * 0.3f;
            v.origin = from;
            v.length = (onSphere - from).length();
            v.direction = (onSphere - from) / v.length;
        } else if (kind == 1) {  // tangent to the sphere, just above it
            const Vec3 n = direction(rng);
            const Vec3 t = (direction(rng) - n * n.dot(direction(rng))).normalized();
            v.direction = (t - n * n.dot(t)).normalized();
            v.origin = n * (1.0f + 1e-3f * rng.next()) - v.direction * rng.next();
            v.length = 1.5f * rng.next();
        } else if (kind == 2) {  // zero length
            v.origin = Vec3(7 * rng.next() - 3.5f, 7 * rng.next() - 3.5f, 7 * rng.next() - 3.5f);
            v.direction = direction(rng);
            v.length = 0.0f;
        } else {
            v.origin = Vec3(4 * rng.next() - 2.0f, 4 * rng.next() - 2.0f, 4 * rng.next() - 2.0f);
            v.direction = direction(rng);
            v.length = 0.05f + 1.85f * rng.next();
        }
        vrls.push_back(v);
    }
    return vrls;
}

struct Tally {
    uint64_t triples = 0, violations = 0, infinite = 0, zero = 0;
    double worstRatio = 0.0;
};

// `inherit`: each node's bound is the cut's deferred, cheap one (cut_walk.h), with its
// parent's receiver factor where x lies outside the parent: diffuse and smooth-plastic
// x ignore that factor (theirs is exact and cheap: the full bound, tight).
Tally checkBound(const Scene& scene, uint64_t seed, int vrlCount, int points, bool inherit = false,
                 const ClusterBoundSettings& settings = {}) {
    Rng rng(seed, 0);
    const LightTree tree = LightTree::build(randomVrls(rng, vrlCount), LightTreeSettings{256, seed});
    const SurfaceClusterBound bound(scene, tree, settings);
    std::vector<int32_t> parent(tree.nodes().size(), -1);
    for (int32_t node = 0; node < int32_t(tree.nodes().size()); ++node)
        if (!tree.nodes()[node].isLeaf()) parent[tree.nodes()[node].left] = parent[tree.nodes()[node].right] = node;
    const VrlSurfaceEstimator estimator(scene, 1);
    Tally tally;
    for (int p = 0; p < points; ++p) {
        // A point of the sphere seen from outside it, at any angle.
        const Vec3 eye = direction(rng) * (1.2f + 2.0f * rng.next());
        const Vec3 target = direction(rng) * 0.9f;
        const auto hit = scene.intersect(Ray{eye, (target - eye).normalized()});
        if (!hit) continue;
        const CameraPathSurface x = cameraPathSurface(scene, *hit, -(target - eye).normalized(), 0, Rgb(0.3f + 0.7f * rng.next()), 0);
        for (int32_t node = 0; node < int32_t(tree.nodes().size()); ++node) {
            const LightTreeNode& n = tree.nodes()[node];
            bool inside = false;
            Rgb b = bound.bound(node, x, &inside);
            if (inherit && parent[node] >= 0) {
                Rgb factor(0.0f);
                bool parentInside = false, tight = true;
                bound.bound(parent[node], x, &parentInside, &factor);
                if (!parentInside) {
                    bool insideToo = false;
                    const Rgb cheap = bound.cheapBound(node, x, &insideToo, &factor, nullptr, &tight);
                    EXPECT_EQ(insideToo, inside) << "the crossing test is exact";
                    if (scene.shapes()[0].bsdf.lambertianBound(Vec2(0.0f, 0.0f))) {
                        EXPECT_TRUE(tight);
                        EXPECT_TRUE(cheap.x == b.x && cheap.y == b.y && cheap.z == b.z) << "an exact factor is kept";
                    } else if (!inside) {
                        EXPECT_FALSE(tight);
                    }
                    b = cheap;
                }
            }
            ++tally.triples;
            if (inside) {
                ++tally.infinite;
                continue;
            }
            Vrl representative = tree.vrls()[n.representative];
            representative.flux = n.clusterFlux;
            Rng sample(seed * 7919 + p, uint64_t(node));
            const Rgb e = estimator.contribution(representative, x, sample);
            if (isBlack(b)) ++tally.zero;
            for (int c = 0; c < 3; ++c) {
                if (e[c] > b[c]) ++tally.violations;
                if (b[c] > 0.0f) tally.worstRatio = std::max(tally.worstRatio, double(e[c]) / double(b[c]));
            }
        }
    }
    return tally;
}

const Medium kMedia[] = {{"grey", Rgb(0.8f), Rgb(0.2f), 0.0f},
                         {"chromatic", Rgb(0.4f, 0.8f, 1.4f), Rgb(0.2f, 0.1f, 0.05f), 0.0f},
                         {"hg0.7", Rgb(0.8f), Rgb(0.2f), 0.7f},
                         {"hg-0.9", Rgb(0.8f), Rgb(0.2f), -0.9f},
                         {"hg0.95", Rgb(0.4f, 0.8f, 1.4f), Rgb(0.2f), 0.95f}};

TEST(SurfaceClusterBound, NeverExceededForDiffuseAndSmoothPlastic) {
    BsdfDescription plastic;
    plastic.kind = BsdfDescription::Kind::Plastic;
    plastic.reflectance.value = Rgb(0.6f, 0.3f, 0.2f);
    uint64_t total = 0;
    uint64_t seed = 1;
    for (const Medium& m : kMedia) {
        for (bool boxed : {false, true}) {
            for (const BsdfDescription& bsdf : {test::diffuseBsdf(Rgb(0.7f, 0.5f, 0.3f), false), plastic}) {
                const auto scene = sphereInMedium(m, bsdf, boxed);
                ASSERT_TRUE(SurfaceClusterBound::provenFor(scene->shapes()[0].bsdf));
                if (boxed) {
                    ASSERT_TRUE(scene->media()[0].boundaryConvex()) << "the bound's T_r(d) case is not exercised";
                }
                const Tally t = checkBound(*scene, seed++, 600, 160, /*inherit=*/m.g == 0.0f && boxed);
                std::printf("%s %s %s: %llu triples, %llu violations, %llu x inside a node, %llu zero bounds, "
                            "worst estimate/bound %.4f\n",
                            m.name, boxed ? "boxed" : "unbounded",
                            bsdf.kind == BsdfDescription::Kind::Plastic ? "plastic" : "diffuse",
                            (unsigned long long)t.triples, (unsigned long long)t.violations,
                            (unsigned long long)t.infinite, (unsigned long long)t.zero, t.worstRatio);
                EXPECT_EQ(t.violations, 0u) << m.name << (boxed ? " boxed" : " unbounded");
                EXPECT_GT(t.infinite, 0u) << "no node held x: the degenerate case is not exercised";
                EXPECT_GT(t.zero, 0u) << "no node lay behind x: the side test is not exercised";
                EXPECT_GT(t.worstRatio, 0.01) << "the bound is too loose to mean much";
                total += t.triples;
            }
        }
    }
    std::printf("total: %llu (node, point, sample) triples\n", (unsigned long long)total);
    EXPECT_GE(total, 1'000'000u);
}

TEST(SurfaceClusterBound, NeverExceededForRoughPlasticAndConductor) {
    // The cone bound (GlossyBound::Cones, the default) of Beckmann and GGX lobes, in a
    // grey boxed medium and an HG one (g = 0.7): zero violations, own box and parent's factor.
    struct Glossy {
        const char* name;
        BsdfDescription::Kind kind;
        MicrofacetKind distribution;
        float alphaU, alphaV;
    };
    const Glossy models[] = {{"roughconductor ggx 0.2", BsdfDescription::Kind::RoughConductor, MicrofacetKind::GGX, 0.2f, 0.2f},
                             {"roughplastic ggx 0.1", BsdfDescription::Kind::RoughPlastic, MicrofacetKind::GGX, 0.1f, 0.1f},
                             {"roughplastic beckmann 0.05/0.3", BsdfDescription::Kind::RoughPlastic,
                              MicrofacetKind::Beckmann, 0.05f, 0.3f},
                             {"roughconductor beckmann 0.02", BsdfDescription::Kind::RoughConductor,
                              MicrofacetKind::Beckmann, 0.02f, 0.02f}};
    uint64_t seed = 40, total = 0;
    for (const Glossy& g : models) {
        BsdfDescription bsdf;
        bsdf.kind = g.kind;
        bsdf.distribution = g.distribution;
        bsdf.alphaU = g.alphaU, bsdf.alphaV = g.alphaV;
        bsdf.reflectance.value = Rgb(0.6f, 0.3f, 0.2f);
        for (const Medium& m : {kMedia[0], kMedia[2]}) {
            const auto scene = sphereInMedium(m, bsdf, true);
            ASSERT_TRUE(SurfaceClusterBound::provenFor(scene->shapes()[0].bsdf));
            for (const bool inherit : {false, true}) {
                const Tally t = checkBound(*scene, seed++, 600, 100, inherit);
                std::printf("%s, %s%s: %llu triples, %llu violations, worst estimate/bound %.4f\n", g.name, m.name,
                            inherit ? ", parent's factor" : "", (unsigned long long)t.triples,
                            (unsigned long long)t.violations, t.worstRatio);
                EXPECT_EQ(t.violations, 0u) << g.name << " " << m.name << (inherit ? " inherited" : "");
                EXPECT_GT(t.worstRatio, 0.01) << "the bound is too loose to mean much";
                total += t.triples;
            }
        }
    }
    EXPECT_GE(total, 500'000u);
}

TEST(SurfaceClusterBound, GlossyHeuristicReportsItsViolationRate) {
    BsdfDescription conductor;
    conductor.kind = BsdfDescription::Kind::RoughConductor;
    conductor.alphaU = conductor.alphaV = 0.2f;
    BsdfDescription roughPlastic;
    roughPlastic.kind = BsdfDescription::Kind::RoughPlastic;
    roughPlastic.alphaU = roughPlastic.alphaV = 0.1f;
    BsdfDescription ward;  // no cone bound: the heuristic whatever the setting
    ward.kind = BsdfDescription::Kind::Ward;
    ward.alphaU = ward.alphaV = 0.2f;
    ClusterBoundSettings corners;
    corners.glossyBound = GlossyBound::Corners;
    uint64_t seed = 50;
    for (const BsdfDescription& bsdf : {conductor, roughPlastic, ward}) {
        const auto scene = sphereInMedium(kMedia[0], bsdf, true);
        EXPECT_FALSE(SurfaceClusterBound::provenFor(scene->shapes()[0].bsdf, corners));
        const ClusterBoundSettings settings = bsdf.kind == BsdfDescription::Kind::Ward ? ClusterBoundSettings{} : corners;
        EXPECT_EQ(SurfaceClusterBound::provenFor(scene->shapes()[0].bsdf), bsdf.kind != BsdfDescription::Kind::Ward);
        // The bound from the node's own box, and the cut's cheap bound from its parent's factor.
        for (const bool inherit : {false, true}) {
            const Tally t = checkBound(*scene, seed, 600, 100, inherit, settings);
            const double rate = double(t.violations) / double(3 * (t.triples - t.infinite));
            std::printf("%s (heuristic)%s: %llu triples, violation rate %.5f%%, worst estimate/bound %.3f\n",
                        bsdf.kind == BsdfDescription::Kind::RoughConductor ? "roughconductor 0.2"
                        : bsdf.kind == BsdfDescription::Kind::Ward         ? "ward 0.2"
                                                                           : "roughplastic 0.1",
                        inherit ? ", parent's factor" : "", (unsigned long long)t.triples, 100.0 * rate,
                        t.worstRatio);
            EXPECT_LT(rate, 1e-3);
        }
        ++seed;
    }
}

}  // namespace
}  // namespace vrl
