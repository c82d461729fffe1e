// The public scenes in ../shared/scenes load unchanged and render: every scene
// the step-5 issue lists is parsed as written (only the resolution, sample and
// VRL counts are lowered), built, and rendered with VRL Lightcuts at a small
// resolution; the image must be finite, non-negative and lit. The surface-only
// scenes (staircase, veach-lamp) are filled with smoke as the paper did.
// Skipped, with the reason printed, when the folder is absent.
#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/scene_io/medium_fill.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>

namespace vrl {
namespace {

const std::filesystem::path kScenes = VRL_SHARED_SCENES_DIR;

struct RealScene {
    const char* file;        // relative to ../shared/scenes
    const char* fillMedium;  // --medium for scenes without media, or nullptr
    int width, height;
};

const RealScene kRealScenes[] = {
    {"volumetric-caustic/scene_v0.6.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/vol_cbox.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/volpath_test1.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/volpath_test2.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/volpath_test3.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/volpath_test4.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/volpath_test5.xml", nullptr, 24, 24},
    {"lajolla-volpath-test/volpath_test6.xml", nullptr, 24, 24},
    {"staircase/scene.xml", "sigmaS=0.05,sigmaA=0.01", 18, 32},
    {"veach-lamp-mitsuba-bidir/scene.xml", "sigmaS=0.1,sigmaA=0.02", 32, 18},
};

void PrintTo(const RealScene& scene, std::ostream* out) { *out << scene.file; }

class RealScenes : public ::testing::TestWithParam<RealScene> {};

TEST_P(RealScenes, LoadsUnchangedAndRendersWithLightcuts) {
    const RealScene& real = GetParam();
    const auto file = kScenes / real.file;
    if (!std::filesystem::exists(file)) GTEST_SKIP() << "shared scene " << file << " is absent";
    const auto start = std::chrono::steady_clock::now();
    SceneDescription description = parseMitsubaScene(file);
    if (real.fillMedium) fillWithMedium(description, parseFillMedium(real.fillMedium));
    description.sensor.width = real.width;
    description.sensor.height = real.height;
    const auto scene = Scene::build(description);
    const double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    RenderSettings settings;
    settings.method = RenderMethod::VrlLightcuts;
    settings.samplesPerPixel = 2;
    settings.vrlCount = 4000;
    settings.maxDepth = description.integrator.maxDepth;
    RenderStatistics statistics;
    const ImageSet images = render(*scene, settings, {}, &statistics);
    double sum = 0.0;
    for (const Rgb& p : images.image.pixels()) {
        ASSERT_TRUE(isFinite(p)) << real.file;
        ASSERT_GE(minComponent(p), 0.0f) << real.file;
        sum += luminance(p);
    }
    const double mean = sum / double(images.image.pixelCount());
    std::printf("%s: %zu shapes, %zu textures, load %.2f s, %llu VRLs, mean luminance %.4g\n", real.file,
                scene->shapes().size(), scene->textures().size(), loadSeconds,
                (unsigned long long)statistics.vrlCount, mean);
    EXPECT_GT(mean, 0.0) << real.file << " rendered black";
    // Multiple scattering needs paths of at least three segments.
    if (description.integrator.maxDepth < 0 || description.integrator.maxDepth >= 3) {
        EXPECT_GT(statistics.vrlCount, 0u) << real.file;
    }
}

INSTANTIATE_TEST_SUITE_P(SharedScenes, RealScenes, ::testing::ValuesIn(kRealScenes),
                         [](const ::testing::TestParamInfo<RealScene>& info) {
                             std::string name = info.param.file;
                             name = name.substr(0, name.find('.'));
                             for (char& c : name)
                                 if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                             return name;
                         });

}  // namespace
}  // namespace vrl
