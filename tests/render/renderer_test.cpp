// Determinism of the tiled parallel renderer: the same seed gives a
// bit-identical image whatever the thread count and tile size, and a crop
// window equals that window of the full film.
#include "render/render_metadata.h"
#include "render/renderer.h"
#include "tests/support/image_compare.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace vrl {
namespace {

Image renderWithThreads(const Scene& scene, const RenderSettings& settings, int threads) {
    tbb::task_arena arena(threads);
    Image image;
    arena.execute([&] { image = render(scene, settings).image; });
    return image;
}

using test::bitIdentical;

TEST(RendererDeterminism, SameSeedSameImageWithOneAndTwoThreads) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings;
    settings.samplesPerPixel = 4;
    settings.seed = 42;
    settings.tileSize = 5;  // many small tiles, so the two runs schedule them differently
    const Image one = renderWithThreads(*scene, settings, 1);
    const Image two = renderWithThreads(*scene, settings, 2);
    EXPECT_TRUE(bitIdentical(one, two));
    double total = 0;
    for (const auto& p : one.pixels()) total += luminance(p);
    EXPECT_GT(total, 0.0) << "a black image would make this test vacuous";
}

TEST(RendererDeterminism, JitteredSamplingIsDeterministicToo) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings;
    settings.samplesPerPixel = 2;
    settings.jitter = true;
    settings.seed = 5;
    EXPECT_TRUE(bitIdentical(renderWithThreads(*scene, settings, 1), renderWithThreads(*scene, settings, 2)));
}

TEST(RendererDeterminism, DifferentSeedsGiveDifferentImages) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings;
    settings.samplesPerPixel = 2;
    settings.seed = 1;
    const Image a = renderWithThreads(*scene, settings, 2);
    settings.seed = 2;
    const Image b = renderWithThreads(*scene, settings, 2);
    EXPECT_FALSE(bitIdentical(a, b));
}

TEST(RendererDeterminism, VrlMethodSameImageWithOneAndTwoThreads) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings;
    settings.method = RenderMethod::Vrl;
    settings.samplesPerPixel = 2;
    settings.vrlCount = 2000;
    settings.seed = 17;
    settings.tileSize = 5;
    const Image one = renderWithThreads(*scene, settings, 1);
    EXPECT_TRUE(bitIdentical(one, renderWithThreads(*scene, settings, 2)));
    double total = 0;
    for (const auto& p : one.pixels()) total += luminance(p);
    EXPECT_GT(total, 0.0);
}

ImageSet renderSetWithThreads(const Scene& scene, const RenderSettings& settings, int threads) {
    tbb::task_arena arena(threads);
    ImageSet images;
    arena.execute([&] { images = render(scene, settings); });
    return images;
}

// Every layer of `a` (image first) equals that of `b` bit for bit, once `crop` cuts `a` down (if given).
::testing::AssertionResult sameLayers(const ImageSet& a, const ImageSet& b, const std::optional<FilmCrop>& crop = {}) {
    const auto window = [&](const Image& full) {
        if (!crop) return full;
        Image out(crop->width, crop->height);
        for (int y = 0; y < crop->height; ++y)
            for (int x = 0; x < crop->width; ++x) out.at(x, y) = full.at(crop->x0 + x, crop->y0 + y);
        return out;
    };
    if (!bitIdentical(window(a.image), b.image)) return ::testing::AssertionFailure() << "the image differs";
    if (a.layers.size() != b.layers.size()) return ::testing::AssertionFailure() << "layer counts differ";
    for (size_t l = 0; l < a.layers.size(); ++l)
        if (a.layers[l].first != b.layers[l].first || !bitIdentical(window(a.layers[l].second), b.layers[l].second))
            return ::testing::AssertionFailure() << "layer " << a.layers[l].first << " differs";
    return ::testing::AssertionSuccess();
}

RenderSettings smallSettings(RenderMethod method, bool jitter) {
    RenderSettings settings;
    settings.method = method;
    settings.samplesPerPixel = 3;
    settings.vrlCount = 1500;
    settings.seed = 23;
    settings.jitter = jitter;
    return settings;
}

// Each camera sample draws from its pixel's stream, keyed by (seed, film pixel)
// and read in sample order: with jitter on, neither the thread count nor the
// tile size changes a bit (1 thread with 8-pixel tiles against 2 with 32).
TEST(RendererDeterminism, JitteredImagesIgnoreThreadsAndTileSize) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    for (const RenderMethod method : {RenderMethod::Path, RenderMethod::VrlLightcuts}) {
        RenderSettings settings = smallSettings(method, true);
        settings.tileSize = 8;
        const ImageSet one = renderSetWithThreads(*scene, settings, 1);
        settings.tileSize = 32;
        EXPECT_TRUE(sameLayers(one, renderSetWithThreads(*scene, settings, 2))) << methodName(method);
        double total = 0;
        for (const auto& p : one.image.pixels()) total += luminance(p);
        EXPECT_GT(total, 0.0) << "a black image would make this test vacuous";
    }
}

// The embedded render's tiles: halved until each thread has kTilesPerThread of them, never
// below kMinBalancedTileSize, never above the requested side.
TEST(RendererTiles, BalancedTileSizeGivesEveryThreadEnoughTiles) {
    EXPECT_EQ(balancedTileSize(45, 80, 32, 2), 8);     // 6 tiles of 32, 15 of 16, 60 of 8
    EXPECT_EQ(balancedTileSize(320, 240, 32, 2), 32);  // 80 tiles already
    EXPECT_EQ(balancedTileSize(320, 240, 32, 8), 16);  // 80 < 128: 300 of 16
    EXPECT_EQ(balancedTileSize(8, 8, 32, 16), kMinBalancedTileSize);
    EXPECT_EQ(balancedTileSize(1280, 720, 16, 1), 16);  // never larger than asked
    EXPECT_EQ(balancedTileSize(10, 10, 3, 8), 3);       // nor halved below the minimum
    for (const int threads : {1, 2, 3, 8, 64})
        for (const int width : {1, 7, 45, 320, 1280}) {
            const int side = balancedTileSize(width, 80, 32, threads);
            const int64_t tiles = int64_t(imageTiles(width, 80, side).size());
            EXPECT_TRUE(tiles >= int64_t(kTilesPerThread) * threads || side / 2 < kMinBalancedTileSize)
                << width << "x80, " << threads << " threads: " << tiles << " tiles of " << side;
        }
}

// A crop window (hdrfilm cropOffsetX..., --crop) renders the window of the full
// film bit for bit: every layer, with jitter on and off, for path and vrl-lightcuts.
const Image& layer(const ImageSet& set, const std::string& name) {
    for (const auto& [n, image] : set.layers)
        if (n == name) return image;
    throw std::runtime_error("no layer " + name);
}

// K x K shading points: the once-per-pixel parts (c), (d) and (b)'s surface VPLs
// become the mean of K^2 stratified points, each uniform over the pixel, so their
// expectation does not change. With the same seed the VRL set is the same, and the
// per-pixel differences against one point are independent with mean zero: their
// image mean lies within 4 standard errors of 0 (a two-sided z-test, p = 6e-5 of
// a false failure; seed fixed). Rays all in one corner, or points left out of the
// mean, move it by far more. The path-sampled parts (a), (b) do not change at all,
// nor do threads change a bit; the counters are summed over the points (about
// K^2 times as many evaluations).
TEST(Renderer, ShadingPointsKeepTheMeanOfTheOncePerPixelParts) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    RenderSettings settings;
    settings.method = RenderMethod::VrlLightcuts;
    settings.samplesPerPixel = 2;
    settings.vrlCount = 4000;
    settings.seed = 31;
    settings.jitter = true;
    RenderStatistics oneStats, fourStats;
    const ImageSet one = render(*scene, settings, {}, &oneStats);
    settings.shadingPointsPerSide = 2;
    const ImageSet four = render(*scene, settings, {}, &fourStats);
    EXPECT_TRUE(bitIdentical(four.image, renderWithThreads(*scene, settings, 1)));
    EXPECT_TRUE(bitIdentical(layer(one, "surface"), layer(four, "surface")));
    EXPECT_TRUE(bitIdentical(layer(one, "single"), layer(four, "single")));
    RenderRecord record;
    record.settings = settings;
    Metadata withPoints, without;
    writeRenderMetadata(record, scene->camera(), withPoints);
    EXPECT_EQ(metadataText(withPoints.at("vrl.shadingPoints")), "2");
    record.settings.shadingPointsPerSide = 1;
    writeRenderMetadata(record, scene->camera(), without);
    EXPECT_FALSE(without.contains("vrl.shadingPoints"));
    EXPECT_GT(fourStats.meanEvaluated, 2.5 * oneStats.meanEvaluated);
    for (const char* name : {"medium-surface", "multiple", "single-vpl"}) {
        const Image &a = layer(one, name), &b = layer(four, name);
        double sum = 0.0, sumSq = 0.0, level = 0.0;
        const size_t n = a.pixels().size();
        for (size_t i = 0; i < n; ++i) {
            const double d = double(luminance(b.pixels()[i])) - double(luminance(a.pixels()[i]));
            sum += d, sumSq += d * d, level += luminance(a.pixels()[i]);
        }
        const double mean = sum / double(n), se = std::sqrt((sumSq / double(n) - mean * mean) / double(n - 1));
        EXPECT_GT(level, 0.0) << name << " is black: the test would mean nothing";
        EXPECT_GT(se, 0.0) << name << ": the points did not move";
        EXPECT_LT(std::abs(mean), 4.0 * se) << name << ": mean difference " << mean << ", SE " << se
                                            << ", mean level " << level / double(n);
    }
    settings.shadingPointsPerSide = kMaxShadingPointsPerSide + 1;
    EXPECT_THROW(render(*scene, settings), std::invalid_argument);
}

TEST(RendererCrop, CropEqualsTheWindowOfTheFullRender) {
    const SceneDescription description = test::smallSmokeRoom();  // 24 x 16
    SceneDescription cropped = description;
    const FilmCrop crop{5, 3, 11, 9};
    cropped.sensor.crop = crop;
    const auto full = Scene::build(description), part = Scene::build(cropped);
    EXPECT_EQ(part->camera().width(), 11);
    EXPECT_EQ(part->camera().height(), 9);
    for (const RenderMethod method : {RenderMethod::Path, RenderMethod::VrlLightcuts}) {
        for (const bool jitter : {false, true}) {
            RenderSettings settings = smallSettings(method, jitter);
            settings.tileSize = 4;  // the crop's tiles do not line up with the full film's
            const ImageSet whole = renderSetWithThreads(*full, settings, 2), window = renderSetWithThreads(*part, settings, 2);
            ASSERT_EQ(window.image.width(), 11);
            ASSERT_EQ(window.image.height(), 9);
            EXPECT_TRUE(sameLayers(whole, window, crop)) << methodName(method) << (jitter ? " jittered" : "");
        }
    }
}

// A cropped render's EXR says so: vrl.width/height are the image's, vrl.crop and
// vrl.film give the window and the film; an uncropped one has neither key.
TEST(RendererCrop, MetadataRecordsTheWindowOnlyWhenCropped) {
    SceneDescription description = test::smallSmokeRoom();  // 24 x 16
    Metadata plain;
    writeRenderMetadata({}, PerspectiveCamera(description.sensor), plain);
    EXPECT_FALSE(plain.contains("vrl.crop"));
    EXPECT_FALSE(plain.contains("vrl.film"));
    description.sensor.crop = FilmCrop{5, 3, 11, 9};
    Metadata cropped;
    writeRenderMetadata({}, PerspectiveCamera(description.sensor), cropped);
    EXPECT_EQ(metadataText(cropped.at("vrl.crop")), "5,3,11,9");
    EXPECT_EQ(metadataText(cropped.at("vrl.film")), "24x16");
    EXPECT_EQ(metadataText(cropped.at("vrl.width")), "11");
    EXPECT_EQ(metadataText(cropped.at("vrl.height")), "9");
}

TEST(Renderer, MethodNamesRoundTripAndUnknownNamesListTheValidOnes) {
    for (RenderMethod m : kRenderMethods) EXPECT_EQ(parseRenderMethod(methodName(m)), m);
    EXPECT_EQ(renderMethodNames().size(), kRenderMethods.size());
    try {
        (void)parseRenderMethod("magic");
        FAIL() << "an unknown method must throw";
    } catch (const std::invalid_argument& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("magic"), std::string::npos) << message;
        for (const auto& name : renderMethodNames()) EXPECT_NE(message.find(name), std::string::npos) << message;
    }
}

TEST(Renderer, RejectsZeroSamples) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings;
    settings.method = RenderMethod::Path;
    settings.samplesPerPixel = 0;
    EXPECT_THROW(render(*scene, settings), std::invalid_argument);
}

TEST(Renderer, ImageIsFiniteAndNonNegative) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings;
    settings.samplesPerPixel = 4;
    const Image image = render(*scene, settings).image;
    for (const auto& p : image.pixels()) {
        EXPECT_TRUE(isFinite(p));
        EXPECT_GE(minComponent(p), 0.0f);
    }
}

// Lights from a blob must belong to the scene: a medium index out of range is
// refused before shading could index out of bounds.
TEST(Renderer, LightsNamingMissingMediaAreRefused) {
    const auto scene = Scene::build(test::mediumOnlyCube(Rgb(1.0f), Rgb(0.0f), 0.0f));
    RenderSettings settings;
    settings.method = RenderMethod::Vrl;
    RenderLights lights;
    lights.vrls.vrls.push_back(Vrl{Vec3(0.0f), Vec3(1, 0, 0), 0.1f, Rgb(1.0f), 7});
    lights.vrls.lightPaths = 1;
    try {
        TileShader shader(*scene, settings, lights);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("medium 7"), std::string::npos) << e.what();
    }
    settings.method = RenderMethod::VrlLightcuts;
    RenderLights treeLights;
    treeLights.tree = LightTree::build({Vrl{Vec3(0.0f), Vec3(1, 0, 0), 0.1f, Rgb(1.0f), -3}});
    EXPECT_THROW(TileShader(*scene, settings, treeLights), std::invalid_argument);
}

}  // namespace
}  // namespace vrl

