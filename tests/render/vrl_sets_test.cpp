// Several independent VRL sets (RenderSettings::vrlSets, `--vrl-sets P`,
// vrl-stochastic only): set 0 is the one-set render's set, the other sets are
// traced from their own streams, camera sample s draws from set s mod P, and
// the image stays bit-identical across threads, tiles and progressive passes.
// Each set's estimate is unbiased for its set (stochastic_lightcuts_test.cpp),
// and independent sets are independent draws of the light tracer, so their mean
// converges to the true transport; these tests pin down the bookkeeping that
// this argument needs (distinct sets, the sample-to-set rule, determinism).
#include "render/lightcuts/tree/light_tree_io.h"
#include "render/renderer.h"
#include "tests/support/image_compare.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>


namespace vrl {
namespace {

using test::bitIdentical;
using test::sameLayers;

RenderSettings stochasticSettings(int sets, int spp) {
    RenderSettings settings;
    settings.method = RenderMethod::VrlStochastic;
    settings.vrlCount = 1500;
    settings.seed = 17;
    settings.jitter = true;
    settings.cut.stochasticCutSize = 8;
    settings.vrlSets = sets;
    settings.samplesPerPixel = spp;
    return settings;
}

ImageSet renderWith(const Scene& scene, const RenderSettings& settings, int threads, RenderStatistics* stats = nullptr) {
    tbb::task_arena arena(threads);
    ImageSet images;
    arena.execute([&] { images = render(scene, settings, {}, stats); });
    return images;
}

// The whole image as one tile, from given lights.
Image shadeWhole(const Scene& scene, const RenderSettings& settings, const RenderLights& lights) {
    const TileShader shader(scene, settings, lights);
    const PerspectiveCamera& camera = scene.camera();
    return shader.renderTile({0, 0, camera.width(), camera.height()}).layers[0];
}

LightTree copyOf(const LightTree& tree) { return deserializeLightTree(serializeLightTree(tree)); }

TEST(VrlSets, SetZeroIsTheOneSetTreeAndTheOthersAreTracedApart) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderStatistics one, three;
    const RenderLights single = prepareLights(*scene, stochasticSettings(1, 1), {}, &one);
    const RenderLights sets = prepareLights(*scene, stochasticSettings(3, 1), {}, &three);
    ASSERT_TRUE(single.moreTrees.empty());
    ASSERT_EQ(sets.moreTrees.size(), 2u);
    EXPECT_EQ(serializeLightTree(sets.tree), serializeLightTree(single.tree));
    EXPECT_NE(serializeLightTree(sets.moreTrees[0]), serializeLightTree(sets.tree));
    EXPECT_NE(serializeLightTree(sets.moreTrees[1]), serializeLightTree(sets.moreTrees[0]));
    // Each set is a whole light-tracing run of about vrlCount VRLs; the statistics count all of them.
    uint64_t vrls = sets.tree.vrls().size(), paths = 0;
    for (const LightTree& tree : sets.moreTrees) {
        EXPECT_GE(tree.vrls().size(), 1500u);
        EXPECT_LT(tree.vrls().size(), 3000u);
        vrls += tree.vrls().size();
    }
    paths = three.lightPaths;
    EXPECT_EQ(three.vrlSets, 3);
    EXPECT_EQ(one.vrlSets, 1);
    EXPECT_EQ(three.vrlCount, vrls);
    EXPECT_GT(paths, 2 * one.lightPaths);
    EXPECT_GT(three.treeBytes, 2 * one.treeBytes);
}

// Sample s uses set s mod P: with P copies of one set the image is the one-set image
// bit for bit, and with the sets in another order it is not.
TEST(VrlSets, SampleSDrawsFromSetSModP) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    const RenderSettings oneSet = stochasticSettings(1, 6), threeSets = stochasticSettings(3, 6);
    const RenderLights lights = prepareLights(*scene, threeSets);
    RenderLights first;  // set 0 alone
    first.tree = copyOf(lights.tree);
    RenderLights copies;  // set 0 three times
    copies.tree = copyOf(lights.tree);
    copies.moreTrees.push_back(copyOf(lights.tree));
    copies.moreTrees.push_back(copyOf(lights.tree));
    const Image reference = shadeWhole(*scene, oneSet, first);
    EXPECT_TRUE(bitIdentical(shadeWhole(*scene, threeSets, copies), reference));
    const Image mixed = shadeWhole(*scene, threeSets, lights);
    EXPECT_FALSE(bitIdentical(mixed, reference));
    RenderLights rotated;  // sets 1, 2, 0: every sample but none sees another set
    rotated.tree = copyOf(lights.moreTrees[0]);
    rotated.moreTrees.push_back(copyOf(lights.moreTrees[1]));
    rotated.moreTrees.push_back(copyOf(lights.tree));
    EXPECT_FALSE(bitIdentical(shadeWhole(*scene, threeSets, rotated), mixed));
    // One sample per pixel uses set 0 only: the image does not depend on P.
    EXPECT_TRUE(sameLayers(renderWith(*scene, stochasticSettings(1, 1), 2), renderWith(*scene, stochasticSettings(4, 1), 2)));
}

TEST(VrlSets, BitIdenticalAcrossThreadsTilesAndProgressivePasses) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    RenderSettings settings = stochasticSettings(3, 7);
    settings.tileSize = 8;
    RenderStatistics stats;
    const ImageSet a = renderWith(*scene, settings, 1, &stats);
    EXPECT_EQ(stats.samplesPerPixel, 7);
    settings.tileSize = 16;
    const ImageSet b = renderWith(*scene, settings, 2);
    EXPECT_TRUE(sameLayers(a, b));
    // A progressive render that completes its 3 passes (1 + 2 + 4 samples, the cap) equals the fixed one.
    settings.timeLimitSeconds = 1e6;
    RenderStatistics progressive;
    const ImageSet c = renderWith(*scene, settings, 2, &progressive);
    EXPECT_EQ(progressive.passes, 3);
    EXPECT_TRUE(sameLayers(a, c));
}

TEST(VrlSets, OnlyVrlStochasticTakesSeveralSetsAndTheCountIsBounded) {
    for (const RenderMethod method : {RenderMethod::Path, RenderMethod::Vrl, RenderMethod::VrlLightcuts,
                                      RenderMethod::Vpl, RenderMethod::VplLightcuts}) {
        RenderSettings settings = stochasticSettings(2, 1);
        settings.method = method;
        try {
            validateRenderSettings(settings);
            ADD_FAILURE() << methodName(method) << " accepted 2 VRL sets";
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("vrl-stochastic"), std::string::npos) << e.what();
        }
    }
    for (const int sets : {0, -1, kMaxVrlSets + 1})
        EXPECT_THROW(validateRenderSettings(stochasticSettings(sets, 1)), std::invalid_argument) << sets;
    EXPECT_NO_THROW(validateRenderSettings(stochasticSettings(kMaxVrlSets, 1)));
    // The memory estimate (checked before any light is traced) grows with the sets.
    EXPECT_EQ(estimateLightMemoryBytes(stochasticSettings(4, 1)), 4 * estimateLightMemoryBytes(stochasticSettings(1, 1)));
    // It counts what each cut adds per VRL: the stochastic importance's 64-byte record
    // per inner node; the deterministic cut's cones (32 B) and leaf segments (32 B).
    // Without parts (a), (b): the deterministic cut would add its surface VPLs and their tree.
    RenderSettings deterministic = stochasticSettings(1, 1);
    deterministic.method = RenderMethod::VrlLightcuts;
    deterministic.vrlSets = 1;
    const uint64_t withSurfaceVpls = estimateLightMemoryBytes(deterministic);
    deterministic.transports = TransportSelection::parse("medium-surface,multiple");
    EXPECT_EQ(estimateLightMemoryBytes(stochasticSettings(1, 1)),
              estimateLightMemoryBytes(deterministic) + (64 - 32 - 32) * uint64_t(deterministic.vrlCount));
    EXPECT_GT(withSurfaceVpls, estimateLightMemoryBytes(deterministic));
}

TEST(VrlSets, ShaderRefusesLightsOfAnotherSetCount) {
    const auto scene = Scene::build(test::smallSmokeRoom());
    const RenderLights three = prepareLights(*scene, stochasticSettings(3, 2));
    EXPECT_THROW(TileShader(*scene, stochasticSettings(2, 2), three), std::invalid_argument);
    EXPECT_THROW(TileShader(*scene, stochasticSettings(1, 2), three), std::invalid_argument);
    RenderLights one;
    one.tree = copyOf(three.tree);
    EXPECT_THROW(TileShader(*scene, stochasticSettings(3, 2), one), std::invalid_argument);
    EXPECT_NO_THROW(TileShader(*scene, stochasticSettings(3, 2), three));
}

}  // namespace
}  // namespace vrl
