// Known-answer tests of the reference volumetric path tracer: furnaces, a pure
// absorber, single scattering against a numerical quadrature (airlight), and
// MIS of NEE and BSDF sampling at surfaces against the NEE-only estimator.
#include "render/integrators/path_tracer.h"
#include "render/renderer.h"
#include "render/vrl/surface_vpl_estimator.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

namespace vrl {
namespace {

struct PixelStatistics {
    double mean[3] = {0, 0, 0};
    double standardError[3] = {0, 0, 0};
};

// Mean and standard error over the pixels of an image whose pixels all have
// the same expectation (each pixel is an independent estimate).
PixelStatistics statisticsOverPixels(const Image& image) {
    PixelStatistics s;
    const double n = double(image.pixelCount());
    for (int c = 0; c < 3; ++c) {
        double sum = 0, sum2 = 0;
        for (size_t i = 0; i < image.pixelCount(); ++i) {
            sum += image[i][c];
            sum2 += double(image[i][c]) * image[i][c];
        }
        s.mean[c] = sum / n;
        s.standardError[c] = std::sqrt(std::max(0.0, sum2 / n - s.mean[c] * s.mean[c]) / (n - 1));
    }
    return s;
}

// Closed emitting sphere with a non-absorbing medium inside: L = Le everywhere
// (Le / (1 - rho) with diffuse walls of reflectance rho).
// 8x8 pixels x 128 spp (8192 paths) unless told, seed 7; tolerance 4 standard errors
// of the pixel mean (a false failure has probability < 1e-4 per channel) plus
// `relative` of the answer.
void expectFurnace(const Rgb& radiance, const Rgb& sigmaS, float g, const Rgb& wallReflectance = Rgb(0.0f),
                   int samplesPerPixel = 128, double relative = 0.0) {
    const auto scene = Scene::build(test::emittingSphereFurnace(radiance, sigmaS, g, wallReflectance));
    RenderSettings settings;
    settings.samplesPerPixel = samplesPerPixel;
    settings.seed = 7;
    settings.maxDepth = -1;
    const ImageSet out = render(*scene, settings);
    const PixelStatistics s = statisticsOverPixels(out.image);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(s.standardError[c], 0.0) << "channel " << c << ": no variance means nothing was sampled";
        const double expected = radiance[c] / (1.0 - wallReflectance[c]);
        EXPECT_NEAR(s.mean[c], expected, 4.0 * s.standardError[c] + relative * expected + 1e-6) << "channel " << c;
    }
}

TEST(PathTracerFurnace, GreyIsotropicMediumInEmittingSphere) { expectFurnace(Rgb(1.0f), Rgb(1.0f), 0.0f); }

// MIS of NEE and phase sampling at medium vertices keeps this furnace's errors
// honest: NEE alone carries 1 / d^2 next to the emitting wall (unbounded variance,
// whose sample error understates the spread; with seeds 1-12 its blue standard error
// was 0.05-1.6 and seed 3 missed in every channel; with MIS 0.05-0.16).
TEST(PathTracerFurnace, ChromaticForwardScatteringMedium) {
    expectFurnace(Rgb(0.5f, 1.0f, 2.0f), Rgb(0.4f, 1.5f, 3.0f), 0.7f);
}

TEST(PathTracerFurnace, DenseBackwardScatteringMedium) { expectFurnace(Rgb(2.0f), Rgb(6.0f), -0.5f); }

// Pure absorber: no scattering, so the answer is deterministic: Le exp(-sigma_a d).
TEST(PathTracerAbsorber, AreaLightThroughAbsorbingSlab) {
    const Rgb radiance(3.0f, 2.0f, 1.0f), sigmaA(0.5f, 1.0f, 2.0f);
    const float thickness = 1.5f;
    const auto scene = Scene::build(test::absorberSlab(radiance, sigmaA, thickness));
    RenderSettings settings;
    settings.samplesPerPixel = 4;
    const ImageSet out = render(*scene, settings);
    const Image& image = out.image;
    for (int y = 0; y < image.height(); ++y) {
        for (int x = 0; x < image.width(); ++x) {
            // The slab is crossed obliquely off-centre: d / cos(angle to the axis).
            const Ray ray = scene->camera().generateRay(x + 0.5f, y + 0.5f);
            const float path = thickness / ray.direction.z;
            for (int c = 0; c < 3; ++c) {
                const float expected = radiance[c] * std::exp(-sigmaA[c] * path);
                EXPECT_NEAR(image.at(x, y)[c], expected, 1e-4f * expected) << "pixel " << x << "," << y << " c" << c;
            }
        }
    }
}

// Single scattering of a point light in an infinite medium (the airlight
// integral) by quadrature along the camera ray, in the equiangular variable
// theta (t = delta + h tan(theta)), where the integrand is smooth.
Rgb airlightQuadrature(const Ray& ray, const Vec3& light, const Rgb& intensity, const HomogeneousMedium& medium) {
    const Vec3 toLight = light - ray.origin;
    const double delta = toLight.dot(ray.direction);
    const double h = (toLight - ray.direction * float(delta)).length();
    const double thetaA = std::atan2(0.0 - delta, h), thetaB = std::atan2(double(ray.tMax) - delta, h);
    const int intervals = 20000;  // Simpson, even count
    Rgb sum(0.0f);
    double acc[3] = {0, 0, 0};
    for (int i = 0; i <= intervals; ++i) {
        const double theta = thetaA + (thetaB - thetaA) * i / intervals;
        const double t = delta + h * std::tan(theta);
        const Vec3 x = ray.at(float(t));
        const Vec3 toL = light - x;
        const double d = toL.length();
        const double phase = medium.phase().eval(ray.direction, toL / float(d));
        const double w = (i == 0 || i == intervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        for (int c = 0; c < 3; ++c) {
            // integrand dt = sigma_s f T(t) I T(d) / d^2 dt, and dt / d^2 = dtheta / h
            acc[c] += w * medium.sigmaS()[c] * phase * std::exp(-medium.sigmaT()[c] * (t + d)) * intensity[c] / h;
        }
    }
    for (int c = 0; c < 3; ++c) sum[c] = float(acc[c] * (thetaB - thetaA) / (3.0 * intervals));
    return sum;
}

void expectAirlight(const Rgb& sigmaS, const Rgb& sigmaA, float g) {
    const Vec3 lightPosition(0.4f, 0.3f, 2.5f);
    const Rgb intensity(5.0f, 4.0f, 3.0f);
    const auto scene = Scene::build(test::pointLightInInfiniteMedium(intensity, lightPosition, sigmaS, sigmaA, g));
    const VolumetricPathTracer tracer(*scene, PathTracerSettings{2});  // maxDepth 2: single scattering only
    const int samples = 40000;  // per pixel; seed = pixel index
    for (int y = 0; y < 4; ++y) {
        for (int x = 0; x < 4; ++x) {
            const Ray ray = scene->camera().generateRay(x + 0.5f, y + 0.5f);
            const Rgb expected = airlightQuadrature(ray, lightPosition, intensity, scene->media()[0]);
            Rng rng(11, uint64_t(y * 4 + x));
            double sum[3] = {0, 0, 0}, sum2[3] = {0, 0, 0};
            for (int s = 0; s < samples; ++s) {
                const Rgb v = tracer.radiance(ray, 0, rng);
                for (int c = 0; c < 3; ++c) {
                    sum[c] += v[c];
                    sum2[c] += double(v[c]) * v[c];
                }
            }
            for (int c = 0; c < 3; ++c) {
                const double mean = sum[c] / samples;
                const double se = std::sqrt(std::max(0.0, sum2[c] / samples - mean * mean) / (samples - 1));
                // 4.5 standard errors over 48 comparisons (false failure < 1e-3 in all) plus
                // 0.1% for the float quadrature.
                EXPECT_NEAR(mean, expected[c], 4.5 * se + 1e-3 * expected[c])
                    << "pixel " << x << "," << y << " channel " << c;
            }
        }
    }
}

TEST(PathTracerAirlight, IsotropicGreyMedium) { expectAirlight(Rgb(0.5f), Rgb(0.1f), 0.0f); }
TEST(PathTracerAirlight, ChromaticHenyeyGreensteinMedium) {
    expectAirlight(Rgb(0.2f, 0.5f, 0.9f), Rgb(0.05f, 0.1f, 0.02f), 0.7f);
}

// maxDepth = 1: only directly visible emitters; a point light is never seen directly.
TEST(PathTracerMaxDepth, DepthOneRendersOnlyVisibleEmitters) {
    const auto scene = Scene::build(test::pointLightInInfiniteMedium(Rgb(5.0f), Vec3(0, 0, 2), Rgb(0.5f), Rgb(0.1f), 0.0f));
    RenderSettings settings;
    settings.samplesPerPixel = 16;
    settings.maxDepth = 1;
    const ImageSet out = render(*scene, settings);
    for (size_t i = 0; i < out.image.pixelCount(); ++i) EXPECT_EQ(out.image[i], Rgb(0.0f));
}

// maxDepth = 2 is single scattering; 3 adds a second bounce, so strictly more light
// (expected ratio well above the 1% noise of 4096 paths per pixel).
TEST(PathTracerMaxDepth, DeeperPathsAddMultipleScattering) {
    const auto scene = Scene::build(test::pointLightInInfiniteMedium(Rgb(5.0f), Vec3(0, 0, 2), Rgb(1.0f), Rgb(0.0f), 0.0f));
    RenderSettings settings;
    settings.samplesPerPixel = 256;
    settings.seed = 3;
    settings.maxDepth = 2;
    const Image single = render(*scene, settings).image;
    settings.maxDepth = 3;
    const Image twice = render(*scene, settings).image;
    double a = 0, b = 0;
    for (size_t i = 0; i < single.pixelCount(); ++i) {
        a += luminance(single[i]);
        b += luminance(twice[i]);
    }
    EXPECT_GT(a, 0.0);
    EXPECT_GT(b, 1.1 * a);
}

// Per-pixel statistics of one tracer: `samples` paths through each pixel centre,
// pixel i drawing from Rng(seed, i): the sample mean and the variance of one path.
struct PixelMoments {
    int samples = 0;
    std::vector<std::array<double, 3>> mean, variance;
};

PixelMoments tracePixels(const Scene& scene, const PathTracerSettings& settings, int samples, uint64_t seed) {
    const VolumetricPathTracer tracer(scene, settings);
    const SensorDescription& sensor = scene.description().sensor;
    PixelMoments m;
    m.samples = samples;
    for (int y = 0; y < sensor.height; ++y) {
        for (int x = 0; x < sensor.width; ++x) {
            const Ray ray = scene.camera().generateRay(x + 0.5f, y + 0.5f);
            Rng rng(seed, uint64_t(y * sensor.width + x));
            std::array<double, 3> sum{}, sum2{};
            for (int s = 0; s < samples; ++s) {
                const Rgb v = tracer.radiance(ray, scene.cameraMedium(), rng);
                for (int c = 0; c < 3; ++c) sum[c] += v[c], sum2[c] += double(v[c]) * v[c];
            }
            std::array<double, 3> mean{}, variance{};
            for (int c = 0; c < 3; ++c) {
                mean[c] = sum[c] / samples;
                variance[c] = std::max(0.0, sum2[c] - samples * mean[c] * mean[c]) / (samples - 1);
            }
            m.mean.push_back(mean);
            m.variance.push_back(variance);
        }
    }
    return m;
}

// Mean over a set of pixels and its standard error (independent pixels).
struct RegionMean {
    double mean = 0, standardError = 0;
};
RegionMean regionMean(const PixelMoments& m, const std::vector<size_t>& pixels, int c) {
    RegionMean r;
    double variance = 0;
    for (size_t i : pixels) r.mean += m.mean[i][c], variance += m.variance[i][c] / m.samples;
    r.mean /= double(pixels.size());
    r.standardError = std::sqrt(variance) / double(pixels.size());
    return r;
}

// Inside a sphere, sampling a point uniformly on it and sampling a cosine-weighted
// direction give the same solid-angle density (cos / pi), so at every wall vertex
// both MIS weights are exactly 1/2: a weight that is off, or a strategy counted
// twice or not at all, moves the answer Le / (1 - rho) by a large fraction of it
// (counting NEE with weight 1: +25% in vacuum). Reflecting walls (rho 0.5, 0.3, 0.7
// per channel). In vacuum the estimate is nearly noise-free (SE ~1e-3 at 8192
// paths), and a 2e-4 relative deficit of the tessellated sphere and ray offsets,
// there with NEE alone too, is allowed for (1e-3). With a scattering medium, 2048
// spp (SE ~1% of the answer).
TEST(PathTracerMis, ReflectingEmittingSphereFurnace) {
    expectFurnace(Rgb(1.0f), Rgb(0.0f), 0.0f, Rgb(0.5f, 0.3f, 0.7f), 128, 1e-3);
    expectFurnace(Rgb(1.0f), Rgb(0.5f), 0.3f, Rgb(0.5f, 0.3f, 0.7f), 2048, 1e-3);
}

// MIS changes how paths are weighted, not which paths count: its expectation must be
// the NEE-only estimator's, with and without the medium-medium restriction (whose
// surface vertices all lie past the second vertex, so both strategies apply there).
// Scene (glossyLitRoom): rough-plastic walls, a smooth-plastic box (Dirac coating +
// diffuse base), a rough-conductor panel, an area light and a spot light, a medium
// with a null-bounded box of a second medium below the light. 16x16 pixels x 1024 paths, seeds 31 (MIS) and 32 (NEE only).
// Compared: the image mean and each 4x4-pixel block's mean per channel, within 4.5
// combined standard errors (2 x 17 x 3 = 102 comparisons; a false failure in any
// has probability < 1e-3 for Gaussian errors; a mean averages 16384+ paths).
TEST(PathTracerMis, SameExpectationAsNeeOnlyInGlossyRoomWithMedia) {
    const auto scene = Scene::build(test::glossyLitRoom(Rgb(0.15f, 0.2f, 0.25f), Rgb(0.02f), 0.3f, Rgb(0.8f)));
    const int width = scene->description().sensor.width, height = scene->description().sensor.height;
    std::vector<std::vector<size_t>> regions(1);
    for (size_t i = 0; i < size_t(width * height); ++i) regions[0].push_back(i);
    for (int by = 0; by < height; by += 4)
        for (int bx = 0; bx < width; bx += 4) {
            regions.emplace_back();
            for (int y = by; y < by + 4; ++y)
                for (int x = bx; x < bx + 4; ++x) regions.back().push_back(size_t(y * width + x));
        }
    for (const bool restricted : {false, true}) {
        PathTracerSettings settings{-1, 5, restricted};
        const PixelMoments mis = tracePixels(*scene, settings, 1024, 31);
        settings.lightMis = false;
        const PixelMoments nee = tracePixels(*scene, settings, 1024, 32);
        for (size_t r = 0; r < regions.size(); ++r)
            for (int c = 0; c < 3; ++c) {
                const RegionMean a = regionMean(mis, regions[r], c), b = regionMean(nee, regions[r], c);
                EXPECT_GT(a.mean, 0.0) << "restricted " << restricted << ", region " << r << ", channel " << c;
                EXPECT_NEAR(a.mean, b.mean, 4.5 * std::hypot(a.standardError, b.standardError))
                    << "restricted " << restricted << ", region " << r << " (0 = whole image), channel " << c;
            }
    }
}

// Part (a)'s split with surface VPLs (PathStart::surfaceVplRadius): the path tracer
// weighs x2's non-Dirac reflection by max(0, 1 - d^2/R^2) only where x2's model
// reflects broadly (reflectsBroadly), since the VPLs on narrow lobes give part (a)
// nothing. In the lit room with narrow rough-plastic walls and light panel (alpha
// 0.1) and a diffuse occluder (the only Lambertian x1; from it, every x2 is a wall
// or the panel), R > 0 must leave every path as R = 0 traces it: the same bits, pixel
// by pixel, 16 paths per pixel (without the guard, 35 of 256 pixels differ). With
// diffuse walls instead (broad x2, and every x1 Lambertian), the same R changes
// pixels (all 256). Part (a)'s restriction as the
// integrator sets it: x1 reached by transmittance only, no medium vertex after x1.
TEST(PathTracerSurfaceVplSplit, LeavesNarrowLobeX2WholeAndWeighsBroadX2) {
    const auto trace = [](const Scene& scene, float radius) {
        PathStart start;
        start.firstSegmentTransmittanceOnly = true;
        start.afterFirstSurface = PathStart::AfterFirstSurface::NotInMedium;
        start.surfaceVplRadius = radius;
        const VolumetricPathTracer tracer(scene, PathTracerSettings{});
        const PerspectiveCamera& camera = scene.camera();
        std::vector<Rgb> pixels;
        for (int y = 0; y < camera.filmHeight(); ++y)
            for (int x = 0; x < camera.filmWidth(); ++x) {
                Rgb sum(0.0f);
                for (uint64_t i = 0; i < 16; ++i) {
                    Rng rng(53, Rng::combine(camera.filmPixelIndex(x, y), i));
                    sum += tracer.radiance(camera.generateRay(x + 0.5f, y + 0.5f), scene.cameraMedium(), rng, start);
                }
                pixels.push_back(sum);
            }
        return pixels;
    };
    const auto differing = [](const std::vector<Rgb>& a, const std::vector<Rgb>& b) {
        size_t count = 0;
        for (size_t i = 0; i < a.size(); ++i) count += !(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z);
        return count;
    };
    SceneDescription narrowWalls = test::litRoomWithOccluder(Rgb(0.2f), Rgb(0.05f), 0.0f);
    const BsdfDescription narrow = test::roughPlastic(Rgb(0.6f, 0.55f, 0.5f), 0.1f, true);
    narrowWalls.shapes[0].bsdf = narrow;  // the room
    narrowWalls.shapes[2].bsdf = narrow;  // the light panel
    const auto narrowScene = Scene::build(narrowWalls);
    ASSERT_FALSE(reflectsBroadly(narrowScene->shapes()[0].bsdf));
    ASSERT_TRUE(lambertianBounded(narrowScene->shapes()[1].bsdf));
    const std::vector<Rgb> whole = trace(*narrowScene, 0.0f);
    EXPECT_EQ(differing(whole, trace(*narrowScene, 0.5f)), 0u) << "narrow-lobe x2 must stay path-traced in full";
    const auto diffuseScene = Scene::build(test::litRoomWithOccluder(Rgb(0.2f), Rgb(0.05f), 0.0f));
    const size_t changed = differing(trace(*diffuseScene, 0.0f), trace(*diffuseScene, 0.5f));
    std::printf("broad x2: %zu of %zu pixels changed by R = 0.5\n", changed, whole.size());
    EXPECT_GT(changed, 10u) << "a broad x2 within R must be weighted";
}

// The point of MIS: on a glossy surface (Beckmann alpha 0.05) lit by an area light,
// NEE alone is noisy where the light's reflection is, BSDF sampling is not, and the
// power heuristic keeps the better of the two. maxDepth 2 (direct lighting only),
// 16x12 pixels x 256 paths, seeds 41 (MIS) and 42 (NEE only). The variance of one
// path, summed over pixels and channels: the measured ratio MIS / NEE is 0.13 here
// (0.14 with 4096 paths); the test asks for < 0.5, far from the measurement and from
// 1 (no gain), so it tests the gain and not the seed. The sample variance of NEE alone is heavy-tailed and tends to be
// underestimated, which only makes the comparison harder to pass. Means agree within
// 4.5 combined standard errors.
TEST(PathTracerMis, LowersVarianceOfGlossyReflectionOfAreaLight) {
    const auto scene = Scene::build(test::glossyFloorUnderAreaLight(0.05f));
    PathTracerSettings settings{2};
    const PixelMoments mis = tracePixels(*scene, settings, 256, 41);
    settings.lightMis = false;
    const PixelMoments nee = tracePixels(*scene, settings, 256, 42);
    std::vector<size_t> all(mis.mean.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = i;
    double varianceMis = 0, varianceNee = 0;
    for (size_t i = 0; i < all.size(); ++i)
        for (int c = 0; c < 3; ++c) varianceMis += mis.variance[i][c], varianceNee += nee.variance[i][c];
    std::printf("glossy floor, alpha 0.05: per-path variance summed over pixels and channels: MIS %.5g, "
                "NEE only %.5g, ratio %.4f\n",
                varianceMis, varianceNee, varianceMis / varianceNee);
    EXPECT_GT(varianceNee, 0.0);
    EXPECT_LT(varianceMis, 0.5 * varianceNee);
    for (int c = 0; c < 3; ++c) {
        const RegionMean a = regionMean(mis, all, c), b = regionMean(nee, all, c);
        EXPECT_GT(a.mean, 0.0);
        EXPECT_NEAR(a.mean, b.mean, 4.5 * std::hypot(a.standardError, b.standardError)) << "channel " << c;
    }
}

}  // namespace
}  // namespace vrl
