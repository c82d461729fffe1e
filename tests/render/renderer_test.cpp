// Determinism of the tiled parallel renderer: the same seed gives a
// bit-identical image whatever the thread count.
#include "render/renderer.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstring>

namespace vrl {
namespace {

Image renderWithThreads(const Scene& scene, const RenderSettings& settings, int threads) {
    tbb::task_arena arena(threads);
    Image image;
    arena.execute([&] { image = render(scene, settings).image; });
    return image;
}

bool bitIdentical(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(Rgb)) == 0;
}

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

