// Error control of VRL Lightcuts: over the same VRLs and seeds, the Lightcuts
// image of part (d), and that of part (c) (VRL-lit surfaces, its own bound), differs from the plain-VRL image by a relative RMSE that
// shrinks with the error threshold and stays below the threshold itself (the
// threshold bounds each refined node's error relative to the pixel's total, and
// the errors of a cut's nodes partly cancel). Both methods draw VRL k's sample
// from the same stream, so at threshold 0 they agree to float rounding.
#include "render/image/image_metrics.h"
#include "render/renderer.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "tests/support/test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cstring>
#include <filesystem>

namespace vrl {
namespace {

RenderSettings multipleScattering(RenderMethod method, float error, const char* part = "multiple",
                                  bool jitter = false) {
    RenderSettings settings;
    settings.jitter = jitter;
    settings.method = method;
    settings.transports = TransportSelection::parse(part);
    settings.vrlCount = 6000;
    settings.seed = 3;
    settings.cut.errorThreshold = error;
    settings.cut.maxCutSize = 1u << 30;  // no safety valve: measure the bound's control alone
    return settings;
}

void expectErrorControl(const Scene& scene, const char* name, const char* part = "multiple", bool jitter = false) {
    const Image plain = render(scene, multipleScattering(RenderMethod::Vrl, 0.0f, part, jitter)).image;
    double previous = 1e30;
    for (float error : {0.1f, 0.03f, 0.01f}) {
        const ImageSet cut = render(scene, multipleScattering(RenderMethod::VrlLightcuts, error, part, jitter));
        const ImageErrorMetrics m = compareImages(plain, cut.image);
        std::printf("%s %s: threshold %.3f -> relative RMSE %.5f against plain VRLs\n", name, part, error,
                    m.relativeRmse);
        EXPECT_LT(m.relativeRmse, error) << name << " " << part << " threshold " << error;
        EXPECT_LT(m.relativeRmse, previous) << name << " " << part << ": error must shrink with the threshold";
        previous = m.relativeRmse;
    }
    const ImageSet exact = render(scene, multipleScattering(RenderMethod::VrlLightcuts, 0.0f, part, jitter));
    const double rmse = compareImages(plain, exact.image).relativeRmse;
    std::printf("%s %s: threshold 0 -> relative RMSE %.2e against plain VRLs\n", name, part, rmse);
    EXPECT_LT(rmse, 1e-4) << name << " " << part << ": threshold 0 refines to every VRL";
}

TEST(Lightcuts, ErrorShrinksWithThresholdOnDefaultScene) {
    SceneDescription d = parseMitsubaScene(std::filesystem::path(VRL_TEST_DATA_DIR) / "../scenes/smoke-room.xml");
    d.sensor.width = 24;
    d.sensor.height = 18;
    const auto scene = Scene::build(d);
    expectErrorControl(*scene, "smoke-room");
}

TEST(Lightcuts, ErrorShrinksWithThresholdInLitRoom) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    expectErrorControl(*scene, "lit room");
}

TEST(Lightcuts, SurfaceErrorShrinksWithThresholdOnDefaultScene) {
    SceneDescription d = parseMitsubaScene(std::filesystem::path(VRL_TEST_DATA_DIR) / "../scenes/smoke-room.xml");
    d.sensor.width = 24;
    d.sensor.height = 18;
    const auto scene = Scene::build(d);
    expectErrorControl(*scene, "smoke-room", "medium-surface");
}

TEST(Lightcuts, SurfaceErrorShrinksWithThresholdInLitRoom) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    expectErrorControl(*scene, "lit room", "medium-surface");
}

// Jittered rays: (c) interleaves its VRLs over 2 x 2 points of each pixel
// (interleaved_points.h), plain and Lightcuts alike (the same points, classes and
// offset); the cut bounds each node at every point a VRL goes to and estimates it at
// its representative's point. The occluder puts edges inside pixels.
TEST(Lightcuts, SurfaceErrorShrinksWithThresholdJitteredInLitRoom) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    expectErrorControl(*scene, "lit room, jittered", "medium-surface", true);
}

// Glossy receivers (a rough-plastic occluder, α 0.1, and a rough-conductor wall panel,
// α 0.4): part (c)'s cut takes their bound factor from the parent node until a node
// may be refined (deferred bounds, cut_walk.h), a heuristic like the glossy bound
// itself; the error still shrinks with the threshold and stays below it, and
// threshold 0 refines to every VRL.
TEST(Lightcuts, SurfaceErrorShrinksWithThresholdInGlossyRoom) {
    const auto scene = Scene::build(test::roomWithGlossyReflectors(Rgb(0.4f), Rgb(0.1f), 0.0f));
    expectErrorControl(*scene, "glossy room", "medium-surface");
}

// The whole four-part image: the path-sampled parts draw the same numbers in
// both methods, so the images differ by the two cuts alone; part (c)'s cut
// measures its error against the whole pixel, and the image's relative RMSE
// against plain VRLs stays below the threshold.
TEST(Lightcuts, WholeImageErrorBelowThresholdOnDefaultScene) {
    SceneDescription d = parseMitsubaScene(std::filesystem::path(VRL_TEST_DATA_DIR) / "../scenes/smoke-room.xml");
    d.sensor.width = 24;
    d.sensor.height = 18;
    const auto scene = Scene::build(d);
    expectErrorControl(*scene, "smoke-room", "surface,single,medium-surface,multiple");
}

// Part (c)'s counters are their own layers, after part (d)'s.
TEST(Lightcuts, SurfaceStatisticsLayers) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    RenderSettings settings = multipleScattering(RenderMethod::VrlLightcuts, 0.02f, "medium-surface,multiple");
    RenderStatistics stats;
    const ImageSet out = render(*scene, settings, {}, &stats);
    const std::vector<std::string> names = {"medium-surface", "multiple", "eval", "inter", "cut",
                                            "medium-surface-eval", "medium-surface-inter", "medium-surface-cut"};
    ASSERT_EQ(out.layers.size(), names.size());
    for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(out.layers[i].first, names[i]);
    for (size_t i = 2; i < names.size(); ++i) EXPECT_TRUE(out.singleChannelLayers.count(names[i])) << names[i];
    double eval = 0, cut = 0;
    for (size_t i = 0; i < out.image.pixelCount(); ++i) {
        eval += out.layers[5].second[i].x;
        cut += out.layers[7].second[i].x;
        EXPECT_GE(out.layers[5].second[i].x, out.layers[7].second[i].x);
    }
    const double n = double(out.image.pixelCount());
    EXPECT_NEAR(stats.surfaceMeanEvaluated, eval / n, 1e-9 * eval);
    EXPECT_NEAR(stats.surfaceMeanCutSize, cut / n, 1e-9 * cut);
    EXPECT_GT(stats.surfaceMeanCutSize, 1.0);
    EXPECT_LT(stats.surfaceMeanCutSize, double(stats.vrlCount)) << "a cut smaller than all VRLs is the point";
    EXPECT_GT(stats.surfaceMeanIntersected, 0.0) << "VRLs end on the walls: some nodes hold the surface point";
}

TEST(Lightcuts, StatisticsLayersAndDeterminism) {
    const auto scene = Scene::build(test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), 0.0f));
    RenderSettings settings = multipleScattering(RenderMethod::VrlLightcuts, 0.02f);
    settings.tileSize = 5;
    RenderStatistics stats;
    ImageSet one, two;
    tbb::task_arena(1).execute([&] { one = render(*scene, settings, {}, &stats); });
    tbb::task_arena(2).execute([&] { two = render(*scene, settings); });
    EXPECT_EQ(std::memcmp(one.image.pixels().data(), two.image.pixels().data(), one.image.pixelCount() * sizeof(Rgb)), 0);
    ASSERT_EQ(one.layers.size(), 4u);  // multiple, eval, inter, cut
    EXPECT_EQ(one.layers[1].first, "eval");
    EXPECT_EQ(one.layers[2].first, "inter");
    EXPECT_EQ(one.layers[3].first, "cut");
    double eval = 0, cut = 0;
    for (size_t i = 0; i < one.image.pixelCount(); ++i) {
        eval += one.layers[1].second[i].x;
        cut += one.layers[3].second[i].x;
        // Every node in the cut was evaluated at some point.
        EXPECT_GE(one.layers[1].second[i].x, one.layers[3].second[i].x);
    }
    const double n = double(one.image.pixelCount());
    EXPECT_NEAR(stats.meanEvaluated, eval / n, 1e-9 * eval);
    EXPECT_NEAR(stats.meanCutSize, cut / n, 1e-9 * cut);
    EXPECT_GT(stats.meanCutSize, 1.0);
    EXPECT_LT(stats.meanCutSize, double(stats.vrlCount)) << "a cut smaller than all VRLs is the point";
    EXPECT_GT(stats.treeBytes, 0u);
}

}  // namespace
}  // namespace vrl
