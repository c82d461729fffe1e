// Light tracing connected to the camera plus the path tracer for what it cannot
// connect (light_tracing_reference.h) against the path tracer alone: the two
// estimate the same image, and each of its two parts carries light.
#include "render/integrators/light_tracing_reference.h"

#include "render/core/rng.h"
#include "render/integrators/path_tracer.h"
#include "tests/support/test_scenes.h"
#include "tests/support/test_workload.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace vrl {
namespace {

// Per-pixel mean and the variance of that mean, per channel.
struct PixelEstimates {
    std::vector<std::array<double, 3>> mean, varianceOfMean;
};

// The path tracer with jittered rays (the area average the light tracer estimates):
// `samples` paths per pixel, pixel i drawing from Rng(seed, i).
PixelEstimates pathTrace(const Scene& scene, int samples, uint64_t seed) {
    const VolumetricPathTracer tracer(scene, PathTracerSettings{});
    const PerspectiveCamera& camera = scene.camera();
    PixelEstimates out;
    for (int y = 0; y < camera.height(); ++y)
        for (int x = 0; x < camera.width(); ++x) {
            Rng rng(seed, uint64_t(y * camera.width() + x));
            std::array<double, 3> sum{}, sum2{};
            for (int s = 0; s < samples; ++s) {
                const float jx = rng.next(), jy = rng.next();
                const Rgb v = tracer.radiance(camera.generateRay(float(x) + jx, float(y) + jy), scene.cameraMedium(), rng);
                for (int c = 0; c < 3; ++c) sum[c] += v[c], sum2[c] += double(v[c]) * v[c];
            }
            std::array<double, 3> mean{}, variance{};
            for (int c = 0; c < 3; ++c) {
                mean[c] = sum[c] / samples;
                variance[c] = std::max(0.0, sum2[c] - samples * mean[c] * mean[c]) / (samples - 1) / samples;
            }
            out.mean.push_back(mean);
            out.varianceOfMean.push_back(variance);
        }
    return out;
}

// `renders` independent renders of the light-tracing reference (seeds seed, seed + 1, ...):
// their mean per pixel, and its variance from their spread.
PixelEstimates lightTrace(const Scene& scene, LightTracingReferenceSettings settings, int renders, uint64_t seed) {
    std::vector<Image> images;
    for (int r = 0; r < renders; ++r) {
        settings.seed = seed + uint64_t(r);
        images.push_back(renderLightTracingReference(scene, settings));
    }
    PixelEstimates out;
    for (size_t i = 0; i < images[0].pixelCount(); ++i) {
        std::array<double, 3> mean{}, variance{};
        for (int c = 0; c < 3; ++c) {
            for (const Image& image : images) mean[c] += image[i][c];
            mean[c] /= renders;
            for (const Image& image : images) variance[c] += (image[i][c] - mean[c]) * (image[i][c] - mean[c]);
            variance[c] /= double(renders - 1) * renders;
        }
        out.mean.push_back(mean);
        out.varianceOfMean.push_back(variance);
    }
    return out;
}

// The image and its 4x4-pixel blocks (index 0: the whole image).
std::vector<std::vector<size_t>> imageAndBlocks(int width, int height) {
    std::vector<std::vector<size_t>> regions(1);
    for (size_t i = 0; i < size_t(width * height); ++i) regions[0].push_back(i);
    for (int by = 0; by < height; by += 4)
        for (int bx = 0; bx < width; bx += 4) {
            regions.emplace_back();
            for (int y = by; y < std::min(by + 4, height); ++y)
                for (int x = bx; x < std::min(bx + 4, width); ++x) regions.back().push_back(size_t(y * width + x));
        }
    return regions;
}

struct RegionMean {
    double mean = 0, standardError = 0;
};
RegionMean regionMean(const PixelEstimates& e, const std::vector<size_t>& pixels, int c) {
    RegionMean r;
    double variance = 0;
    for (size_t i : pixels) r.mean += e.mean[i][c], variance += e.varianceOfMean[i][c];
    r.mean /= double(pixels.size());
    r.standardError = std::sqrt(variance) / double(pixels.size());
    return r;
}

// The image mean and each 4x4 block's mean per channel agree within 4.5 combined
// standard errors: 17 regions x 3 channels = 51 comparisons at 16x16 pixels, a
// false failure in any has probability < 4e-4 for Gaussian errors (each region
// averages 16 pixels x thousands of paths). The light tracer's standard errors
// come from the spread of 8 independent renders (7 degrees of freedom, so they
// are themselves uncertain by ~27%; the path tracer's, from 4096 paths a pixel,
// are not, and dominate the combined error in most regions). Measured worst
// |difference| / error: 3.05 (glass room) and 2.44 (glossy room).
//
// Returns how far the test can see part 2: the largest, over regions and
// channels, of part 2's own mean over the combined error (above 4.5, leaving part
// 2 out would fail the comparison there). Part 1 must carry at least half the image.
double expectSameImageAsPathTracer(const Scene& scene, const char* what) {
    const int divisor = test::kSanitizedWorkDivisor;
    LightTracingReferenceSettings settings;
    settings.lightPaths = 200000 / uint64_t(divisor);
    settings.samplesPerPixel = 256 / divisor;
    const PixelEstimates both = lightTrace(scene, settings, 8, 101);
    const PixelEstimates path = pathTrace(scene, 4096 / divisor, 7);
    LightTracingReferenceSettings lightOnly = settings, cameraOnly = settings;
    lightOnly.samplesPerPixel = 0;
    cameraOnly.lightPaths = 0;
    const PixelEstimates light = lightTrace(scene, lightOnly, 2, 301), camera = lightTrace(scene, cameraOnly, 2, 401);
    const auto regions = imageAndBlocks(scene.camera().width(), scene.camera().height());
    double worst = 0.0, visible = 0.0;
    for (size_t r = 0; r < regions.size(); ++r)
        for (int c = 0; c < 3; ++c) {
            const RegionMean a = regionMean(both, regions[r], c), b = regionMean(path, regions[r], c);
            const double error = std::hypot(a.standardError, b.standardError);
            worst = std::max(worst, std::abs(a.mean - b.mean) / error);
            visible = std::max(visible, regionMean(camera, regions[r], c).mean / error);
            EXPECT_NEAR(a.mean, b.mean, 4.5 * error) << what << ", region " << r << " (0 = the image), channel " << c;
        }
    const double image = regionMean(path, regions[0], 1).mean;
    const double lightPart = regionMean(light, regions[0], 1).mean, cameraPart = regionMean(camera, regions[0], 1).mean;
    std::printf("%s: worst |light tracing - path tracing| / standard error = %.2f over %zu regions x 3; green mean "
                "%.5g = light tracing %.5g + path tracing %.5g; part 2 / error up to %.1f\n",
                what, worst, regions.size(), image, lightPart, cameraPart, visible);
    EXPECT_GT(lightPart, 0.5 * image) << what;
    EXPECT_GT(cameraPart, 0.0) << what;
    return visible;
}

// Glass sphere and a copper mirror in a medium-filled room lit by a spot light and an
// area light: the camera sees part of the room through the glass and in the mirror
// (part 2) and the rest by light tracing (part 1); the camera is inside the medium.
TEST(LightTracingReference, EqualsPathTracerInGlassAndMirrorRoom) {
    const auto scene = Scene::build(test::glassAndMirrorRoom(Rgb(0.3f, 0.4f, 0.5f), Rgb(0.05f), 0.3f));
    // The blocks that see the glass and the mirror: part 2 is many standard errors there
    // (measured 5.7; a power check, so the sanitizer build's fewer samples allow sqrt(4) less).
    EXPECT_GT(expectSameImageAsPathTracer(*scene, "glass and mirror room"), 4.5 / test::kSanitizedNoiseFactor);
}

// Rough-plastic walls, a smooth-plastic box (a Dirac coating over a diffuse base: both
// parts at one vertex), a rough conductor, and a null-bounded box of a second medium.
TEST(LightTracingReference, EqualsPathTracerInGlossyRoomWithNullBoundaries) {
    const auto scene = Scene::build(test::glossyLitRoom(Rgb(0.15f, 0.2f, 0.25f), Rgb(0.02f), 0.3f, Rgb(0.8f)));
    (void)expectSameImageAsPathTracer(*scene, "glossy room");
}

// A known answer: inside a sphere emitting Le inwards, with diffuse walls of
// reflectance rho and a non-absorbing medium, every pixel is Le / (1 - rho). Part 1
// carries the light scattered by the medium and the walls, part 2 the emission seen
// directly (times its transmittance). Every pixel is an independent estimate, so the
// image mean must be the answer within 4.5 standard errors over the 64 pixels (plus
// 1e-3 relative for the tessellated sphere, as the path tracer's furnace allows); for
// a pixel footprint of 1 (the whole pixel) and 1/4 with part 2 at pixel centres (the
// report's setting), where a wrong 1 / f^2 in the importance would be 16x off.
TEST(LightTracingReference, FurnaceForEveryPixelFootprint) {
    const Rgb radiance(1.0f, 0.5f, 2.0f), reflectance(0.5f, 0.3f, 0.7f);
    const auto scene = Scene::build(test::emittingSphereFurnace(radiance, Rgb(0.5f), 0.3f, reflectance));
    for (const float footprint : {1.0f, 0.25f}) {
        LightTracingReferenceSettings settings;
        settings.lightPaths = 400000 / uint64_t(test::kSanitizedWorkDivisor);
        settings.samplesPerPixel = 16;
        settings.seed = 11;
        settings.pixelFootprint = footprint;
        settings.pixelCentres = footprint < 1.0f;
        const Image image = renderLightTracingReference(*scene, settings);
        for (int c = 0; c < 3; ++c) {
            double sum = 0.0, sum2 = 0.0;
            for (size_t i = 0; i < image.pixelCount(); ++i) sum += image[i][c], sum2 += double(image[i][c]) * image[i][c];
            const double n = double(image.pixelCount()), mean = sum / n;
            const double standardError = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1.0));
            const double expected = radiance[c] / (1.0 - reflectance[c]);
            EXPECT_GT(standardError, 0.0) << "footprint " << footprint << ", channel " << c;
            EXPECT_NEAR(mean, expected, 4.5 * standardError + 1e-3 * expected)
                << "footprint " << footprint << ", channel " << c;
        }
    }
}

TEST(LightTracingReference, SameBitsOnOneThreadAndMany) {
    const auto scene = Scene::build(test::glassAndMirrorRoom(Rgb(0.3f), Rgb(0.05f), 0.0f));
    LightTracingReferenceSettings settings;
    settings.lightPaths = 70000;  // more than one batch of chunks, and not a whole number of them
    settings.samplesPerPixel = 4;
    settings.seed = 5;
    Image one;
    tbb::task_arena(1).execute([&] { one = renderLightTracingReference(*scene, settings); });
    const Image many = renderLightTracingReference(*scene, settings);
    ASSERT_EQ(one.pixelCount(), many.pixelCount());
    for (size_t i = 0; i < one.pixelCount(); ++i) ASSERT_EQ(one[i], many[i]) << "pixel " << i;
}

TEST(LightTracingReference, RejectsNothingToDoNegativeSamplesAndBadFootprints) {
    const auto scene = Scene::build(test::glassAndMirrorRoom(Rgb(0.3f), Rgb(0.05f), 0.0f));
    EXPECT_THROW(renderLightTracingReference(*scene, {}), std::invalid_argument);
    LightTracingReferenceSettings negative;
    negative.lightPaths = 10;
    negative.samplesPerPixel = -1;
    EXPECT_THROW(renderLightTracingReference(*scene, negative), std::invalid_argument);
    for (const float footprint : {0.0f, -0.5f, 1.5f, std::nanf("")}) {
        LightTracingReferenceSettings settings;
        settings.lightPaths = 10;
        settings.pixelFootprint = footprint;
        EXPECT_THROW(renderLightTracingReference(*scene, settings), std::invalid_argument) << footprint;
    }
}

}  // namespace
}  // namespace vrl
