// Known-answer tests of the reference volumetric path tracer: furnaces, a pure
// absorber, and single scattering against a numerical quadrature (airlight).
#include "render/integrators/path_tracer.h"
#include "render/renderer.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>

#include <cmath>

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

// Closed emitting sphere with a non-absorbing medium inside: L = Le everywhere.
// 8x8 pixels x 128 spp (8192 paths), seed 7; tolerance 4 standard errors of the
// pixel mean (a false failure has probability < 1e-4 per channel).
void expectFurnace(const Rgb& radiance, const Rgb& sigmaS, float g) {
    const auto scene = Scene::build(test::emittingSphereFurnace(radiance, sigmaS, g));
    RenderSettings settings;
    settings.samplesPerPixel = 128;
    settings.seed = 7;
    settings.maxDepth = -1;
    const ImageSet out = render(*scene, settings);
    const PixelStatistics s = statisticsOverPixels(out.image);
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(s.standardError[c], 0.0) << "channel " << c << ": no variance means nothing was sampled";
        EXPECT_NEAR(s.mean[c], radiance[c], 4.0 * s.standardError[c] + 1e-6) << "channel " << c;
    }
}

TEST(PathTracerFurnace, GreyIsotropicMediumInEmittingSphere) { expectFurnace(Rgb(1.0f), Rgb(1.0f), 0.0f); }

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

}  // namespace
}  // namespace vrl
