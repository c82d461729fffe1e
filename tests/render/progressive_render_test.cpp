// Sample passes and progressive rendering (render/sample_passes.h,
// render/sample_sums.h, renderer.h): camera sample s of a pixel draws from its
// own stream, so it does not depend on the samples before it; the
// virtual-light parts evaluated once per pixel do not depend on the sample
// count; and a progressive render that completed P passes is bit for bit the
// fixed render of 2^P - 1 samples, whatever the threads and tiles. No test
// here depends on timing: passes are stopped by the sample cap or at a pass
// boundary seen through the progress callback.
#include "render/renderer.h"
#include "render/sample_passes.h"
#include "render/sample_sums.h"
#include "tests/support/image_compare.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>


namespace vrl {
namespace {

using test::bitIdentical;
using test::sameLayers;

double total(const Image& image) {
    double sum = 0.0;
    for (const auto& p : image.pixels()) sum += luminance(p);
    return sum;
}

RenderSettings smallSettings(RenderMethod method) {
    RenderSettings settings;
    settings.method = method;
    settings.vrlCount = 1500;
    settings.seed = 31;
    settings.jitter = true;
    return settings;
}

ImageSet renderWith(const Scene& scene, const RenderSettings& settings, int threads, RenderStatistics* stats = nullptr,
                    const RenderStop& stop = {}, const ProgressCallback& progress = {},
                    RenderCoverage* coverage = nullptr) {
    tbb::task_arena arena(threads);
    ImageSet images;
    arena.execute([&] { images = render(scene, settings, progress, stats, stop, coverage); });
    return images;
}

TEST(SamplePasses, PassesDoubleAndStopAtTheCap) {
    EXPECT_EQ(samplePass(0, 100).first, 0);
    EXPECT_EQ(samplePass(0, 100).count, 1);
    EXPECT_EQ(samplePass(1, 100).first, 1);
    EXPECT_EQ(samplePass(1, 100).count, 2);
    EXPECT_EQ(samplePass(3, 100).first, 7);
    EXPECT_EQ(samplePass(3, 100).count, 8);
    EXPECT_EQ(samplePass(2, 5).first, 3);  // samples 3, 4: cut at the cap
    EXPECT_EQ(samplePass(2, 5).count, 2);
    EXPECT_EQ(samplePass(3, 5).count, 0);
    for (int n : {1, 2, 3, 4, 7, 8, 1000, kMaxSampleCount}) {
        const int passes = passesFor(n);
        EXPECT_EQ(samplesAfter(passes, n), n) << n;
        EXPECT_LT(samplesAfter(passes - 1, n), n) << n;
        int covered = 0;  // the passes tile [0, n) in order
        for (int p = 0; p < passes; ++p) {
            EXPECT_EQ(samplePass(p, n).first, covered) << n << " pass " << p;
            covered += samplePass(p, n).count;
        }
        EXPECT_EQ(covered, n);
    }
    EXPECT_EQ(passesFor(kMaxSampleCount), 21);
    EXPECT_EQ(samplesAfter(0, 7), 0);
    EXPECT_EQ(samplesAfter(3, 7), 7);
}

TEST(SampleSums, AddPassSkipsPerPixelLayersAndResolveAddsTheParts) {
    SampleSums a = SampleSums::zeros(2, 1, {0, 0, 1}), b = SampleSums::zeros(2, 1, {0, 0, 1});
    a.layers[1][0] = Rgb(2.0f), b.layers[1][0] = Rgb(4.0f);
    a.layers[2][0] = Rgb(5.0f), b.layers[2][0] = Rgb(100.0f);  // per pixel: pass 0's value stays
    b.boundExceeded = 3;
    addPass(a, b);
    EXPECT_EQ(a.layers[1][0], Rgb(6.0f));
    EXPECT_EQ(a.layers[2][0], Rgb(5.0f));
    EXPECT_EQ(a.boundExceeded, 3u);
    const std::vector<Image> layers = resolveSamples(a, {"surface", "multiple"}, 3);
    EXPECT_EQ(layers[1][0], Rgb(2.0f));                // 6 / 3 samples
    EXPECT_EQ(layers[2][0], Rgb(5.0f));                // once per pixel: as is
    EXPECT_EQ(layers[0][0], Rgb(7.0f));                // the image: the parts' sum
    EXPECT_THROW(addPass(a, SampleSums::zeros(2, 1, {0, 1, 1})), std::invalid_argument);
    EXPECT_THROW(resolveSamples(a, {"surface"}, 3), std::invalid_argument);
    EXPECT_THROW(resolveSamples(a, {"surface", "multiple"}, 0), std::invalid_argument);
}

// Sample s has its own stream: pass 1 (samples 1, 2) of a tile is the same
// whether the render stops at 3 samples or goes on to 64, and the parts
// evaluated once per pixel ((c), (d) and the cut counters) are the same at 1
// and 9 samples per pixel.
TEST(ProgressiveRender, SamplesAndPerPixelPartsIgnoreTheSampleCount) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    for (const RenderMethod method : {RenderMethod::Path, RenderMethod::VrlLightcuts, RenderMethod::VrlStochastic}) {
        RenderSettings settings = smallSettings(method);
        const RenderLights lights = prepareLights(*scene, settings);
        const TileRect tile{3, 2, 11, 7};
        settings.samplesPerPixel = 3;
        const TileShader three(*scene, settings, lights);
        settings.samplesPerPixel = 64;
        const TileShader many(*scene, settings, lights);
        const TileSums a = three.shadeTile(tile, 1, 1), b = many.shadeTile(tile, 1, 1);
        ASSERT_EQ(a.sums.layers.size(), b.sums.layers.size());
        for (size_t l = 0; l < a.sums.layers.size(); ++l)
            EXPECT_TRUE(bitIdentical(a.sums.layers[l], b.sums.layers[l])) << methodName(method) << " layer " << l;
        EXPECT_GT(total(a.sums.layers[0]) + (a.sums.layers.size() > 1 ? total(a.sums.layers[1]) : 0.0), 0.0);

        settings.samplesPerPixel = 1;
        const TileImages one = TileShader(*scene, settings, lights).renderTile(tile);
        settings.samplesPerPixel = 9;
        const TileShader nineShader(*scene, settings, lights);
        const TileImages nine = nineShader.renderTile(tile);
        size_t perPixelLayers = 0;
        for (size_t l = 1; l < one.layers.size(); ++l) {
            if (!nineShader.layerPerPixel()[l]) continue;
            ++perPixelLayers;
            EXPECT_TRUE(bitIdentical(one.layers[l], nine.layers[l])) << nineShader.layerNames()[l - 1];
        }
        if (method == RenderMethod::VrlLightcuts) {
            EXPECT_EQ(perPixelLayers, 12u) << "(c), (d), (b)'s surface VPLs and nine cut counters";
            EXPECT_EQ(one.boundedEstimates, nine.boundedEstimates);
        }
        if (method == RenderMethod::VrlStochastic) {
            EXPECT_EQ(perPixelLayers, 0u) << "stochastic cuts: every layer per sample";
        }
    }
}

// The headline property: a progressive render that completed P passes equals
// the fixed render of 2^P - 1 samples bit for bit, in every layer, whatever
// the threads and tile size; a cap that cuts the last pass gives the fixed
// render of the cap.
TEST(ProgressiveRender, CompletedPassesEqualTheFixedRender) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    for (const RenderMethod method : {RenderMethod::Path, RenderMethod::Vrl, RenderMethod::VrlLightcuts,
                                      RenderMethod::VrlStochastic, RenderMethod::VplLightcuts}) {
        for (const int cap : {7, 5}) {
            RenderSettings fixed = smallSettings(method);
            fixed.samplesPerPixel = cap;
            fixed.tileSize = 16;
            RenderStatistics fixedStats;
            const ImageSet reference = renderWith(*scene, fixed, 2, &fixedStats);
            RenderSettings progressive = fixed;
            progressive.timeLimitSeconds = 1e6;  // the cap ends it, not the clock
            progressive.tileSize = 5;
            RenderStatistics stats;
            RenderCoverage coverage;
            const ImageSet image = renderWith(*scene, progressive, 1, &stats, {}, {}, &coverage);
            EXPECT_EQ(stats.passes, 3) << methodName(method);
            EXPECT_EQ(stats.samplesPerPixel, cap);
            EXPECT_TRUE(coverage.complete());
            EXPECT_TRUE(sameLayers(reference, image)) << methodName(method) << " cap " << cap;
            EXPECT_EQ(stats.boundedEstimates, fixedStats.boundedEstimates) << methodName(method);
            EXPECT_GT(total(image.image), 0.0);
        }
    }
}

// Stopped at the start of pass 3 (as a time limit or Ctrl-C would): the two
// completed passes are kept, the third dropped: the fixed render of 3 samples.
TEST(ProgressiveRender, AStoppedPassIsDroppedAndTheCompletedOnesKept) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings = smallSettings(RenderMethod::VrlLightcuts);
    settings.samplesPerPixel = 3;
    const ImageSet reference = renderWith(*scene, settings, 2);
    settings.samplesPerPixel = 1000;
    settings.timeLimitSeconds = 1e6;
    std::atomic<bool> stopNow{false};
    const ProgressCallback progress = [&](const char* phase, double) {
        if (std::string(phase).rfind("rendering pass 3 ", 0) == 0) stopNow = true;
    };
    RenderStatistics stats;
    RenderCoverage coverage;
    const ImageSet image = renderWith(*scene, settings, 2, &stats, RenderStop{[&] { return stopNow.load(); }},
                                      progress, &coverage);
    EXPECT_EQ(stats.passes, 2);
    EXPECT_EQ(stats.samplesPerPixel, 3);
    EXPECT_TRUE(coverage.complete());
    EXPECT_TRUE(sameLayers(reference, image));
}

// Stopped in the first pass: what it finished is kept as a partial image (1 sample per pixel).
TEST(ProgressiveRender, AFirstPassCutShortKeepsItsFinishedRows) {
    const auto scene = Scene::build(test::smallSmokeRoom());  // 24 x 16
    RenderSettings settings = smallSettings(RenderMethod::Path);
    settings.samplesPerPixel = 1;
    settings.tileSize = 8;
    const ImageSet reference = renderWith(*scene, settings, 1);
    settings.samplesPerPixel = 64;
    settings.timeLimitSeconds = 1e6;
    std::atomic<int> polls{0};
    RenderStatistics stats;
    RenderCoverage coverage;
    // One thread: the stop is polled before each tile and each of its rows; it fires in the second tile.
    const ImageSet image = renderWith(*scene, settings, 1, &stats, RenderStop{[&] { return ++polls > 14; }}, {},
                                      &coverage);
    EXPECT_EQ(stats.passes, 0);
    EXPECT_EQ(stats.samplesPerPixel, 1);
    EXPECT_FALSE(coverage.complete());
    EXPECT_GT(coverage.rowsDone, 0);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 24; ++x) {
            const bool covered = coverage.covered[size_t(y) * 24 + x] != 0;
            EXPECT_EQ(image.image.at(x, y), covered ? reference.image.at(x, y) : Rgb(0.0f)) << x << "," << y;
        }
}

TEST(ProgressiveRender, BadTimeLimitsAreRefused) {
    RenderSettings settings;
    for (const double limit : {-1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
        settings.timeLimitSeconds = limit;
        EXPECT_THROW(validateRenderSettings(settings), std::invalid_argument) << limit;
    }
}

}  // namespace
}  // namespace vrl
