// The public scenes in ../shared/scenes (VRL_SHARED_SCENES_DIR) through the
// Mitsuba XML parser: counts, plugin kinds and the report of ignored
// parameters; skipped when the folder is absent.
#include "tests/render/scene_io/mitsuba_test_support.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <utility>

namespace vrl {
namespace {

using mitsuba_test::mentions;
using mitsuba_test::expectNear;

// ---------------------------------------------------------------- the public scenes

// ../shared/scenes/<file> parsed (meshes and images are only checked to exist),
// or std::nullopt, with a printed reason, when the folder is absent.
std::optional<SceneDescription> parseSharedScene(const std::string& file) {
    const std::filesystem::path path = std::filesystem::path(VRL_SHARED_SCENES_DIR) / file;
    if (!std::filesystem::exists(path)) {
        std::cout << "[  SKIP    ] " << path << " is absent (the public scenes live beside the project)\n";
        return std::nullopt;
    }
    return parseMitsubaScene(path);
}

TEST(MitsubaParserSharedScenes, VolumetricCaustic) {
    const auto scene = parseSharedScene("volumetric-caustic/scene_v0.6.xml");
    if (!scene) GTEST_SKIP() << "shared scenes absent";
    EXPECT_EQ(scene->integrator.type, "volpath");
    EXPECT_EQ(scene->integrator.maxDepth, -1);
    EXPECT_EQ(scene->sensor.width, 1024);
    EXPECT_EQ(scene->sensor.sampleCount, 64);
    ASSERT_EQ(scene->shapes.size(), 8u);
    EXPECT_EQ(scene->media.size(), 3u);
    const ShapeDescription& sphere = scene->shapes[6];
    EXPECT_EQ(sphere.kind, ShapeDescription::Kind::Sphere);
    ASSERT_TRUE(sphere.bsdf.has_value());
    EXPECT_EQ(sphere.bsdf->kind, BsdfDescription::Kind::Dielectric);
    EXPECT_FLOAT_EQ(sphere.bsdf->intIOR, 1.5f);
    EXPECT_FLOAT_EQ(sphere.bsdf->extIOR, 1.0f);
    EXPECT_FALSE(scene->shapes[3].bsdf.has_value());  // the index-matched front face: medium boundary only
    EXPECT_NE(scene->shapes[3].interiorMedium, -1);
    EXPECT_TRUE(scene->shapes[7].areaRadiance.has_value());
    EXPECT_TRUE(scene->textures.empty());
    EXPECT_TRUE(scene->approximations.empty());
    EXPECT_TRUE(mentions(testing::PrintToString(scene->ignored),
                         {"film 'ldrfilm'", "rfilter 'tent'", "integrator 'volpath' (parameters version)"}));
}

TEST(MitsubaParserSharedScenes, LajollaVolpathTests) {
    const std::pair<std::string, size_t> files[] = {
        {"vol_cbox.xml", 8},        {"vol_cbox_teapot.xml", 7}, {"volpath_test1.xml", 1},   {"volpath_test2.xml", 2},
        {"volpath_test3.xml", 2},   {"volpath_test4.xml", 3},   {"volpath_test4_2.xml", 3}, {"volpath_test5.xml", 3},
        {"volpath_test5_2.xml", 2}, {"volpath_test6.xml", 3},
    };
    for (const auto& [file, shapes] : files) {
        SCOPED_TRACE(file);
        const auto scene = parseSharedScene("lajolla-volpath-test/" + file);
        if (!scene) GTEST_SKIP() << "shared scenes absent";
        EXPECT_EQ(scene->shapes.size(), shapes);
        EXPECT_EQ(scene->integrator.type, "volpath");
        EXPECT_TRUE(scene->textures.empty());
    }
    const auto teapot = parseSharedScene("lajolla-volpath-test/vol_cbox_teapot.xml");
    const BsdfDescription& glass = teapot->shapes.back().bsdf.value();
    EXPECT_EQ(glass.kind, BsdfDescription::Kind::RoughDielectric);
    EXPECT_FLOAT_EQ(glass.intIOR, 1.33f);
    EXPECT_FLOAT_EQ(glass.extIOR, 1.000277f);
    EXPECT_FLOAT_EQ(glass.alphaU, 0.01f);
    EXPECT_EQ(teapot->shapes.back().interiorMedium, 0);
}

TEST(MitsubaParserSharedScenes, Staircase) {
    const auto scene = parseSharedScene("staircase/scene.xml");
    if (!scene) GTEST_SKIP() << "shared scenes absent";
    EXPECT_EQ(scene->integrator.type, "path");
    EXPECT_EQ(scene->integrator.maxDepth, 65);
    EXPECT_EQ(scene->sensor.width, 720);
    EXPECT_EQ(scene->sensor.height, 1280);
    ASSERT_EQ(scene->shapes.size(), 775u);
    EXPECT_EQ(std::count_if(scene->shapes.begin(), scene->shapes.end(),
                            [](const ShapeDescription& s) { return s.kind == ShapeDescription::Kind::Obj; }),
              774);
    // Ten texture files: nine colour textures stored (each file once), and the
    // BrushedAluminium bump map, checked but not stored (nothing samples it).
    ASSERT_EQ(scene->textures.size(), 9u);
    EXPECT_EQ(scene->textures[0].filename.filename(), "WoodFloor.jpg");
    for (const ShapeDescription& shape : scene->shapes) ASSERT_TRUE(shape.bsdf.has_value());
    // Shapes reference BrushedAluminium, the twosided bsdf nested in the (unreferenced)
    // bumpmap: as in Mitsuba they get it without the bump map, so no approximation is in use.
    EXPECT_TRUE(scene->approximations.empty());
    std::set<BsdfDescription::Kind> kinds;
    for (const ShapeDescription& shape : scene->shapes) kinds.insert(shape.bsdf->kind);
    EXPECT_EQ(kinds,
              (std::set<BsdfDescription::Kind>{BsdfDescription::Kind::Diffuse, BsdfDescription::Kind::Dielectric,
                                               BsdfDescription::Kind::Conductor, BsdfDescription::Kind::RoughConductor,
                                               BsdfDescription::Kind::RoughPlastic}));
    const auto textured = std::count_if(scene->shapes.begin(), scene->shapes.end(),
                                        [](const ShapeDescription& s) { return s.bsdf->reflectance.texture >= 0; });
    EXPECT_GT(textured, 0);
    EXPECT_TRUE(mentions(testing::PrintToString(scene->ignored),
                         {"texture 'bitmap' (parameters filterType)", "sampler 'sobol'",
                          "integrator 'path' (parameters strictNormals)", "rfilter 'tent'"}));
}

TEST(MitsubaParserSharedScenes, VeachLamp) {
    const auto scene = parseSharedScene("veach-lamp-mitsuba-bidir/scene.xml");
    if (!scene) GTEST_SKIP() << "shared scenes absent";
    EXPECT_EQ(scene->version, "0.6.0");
    EXPECT_EQ(scene->integrator.type, "sppm");
    EXPECT_EQ(scene->integrator.maxDepth, 6);
    EXPECT_EQ(scene->sensor.sampleCount, 100);
    ASSERT_EQ(scene->shapes.size(), 11u);
    for (int i = 0; i < 11; ++i) {
        EXPECT_EQ(scene->shapes[i].kind, ShapeDescription::Kind::Serialized);
        EXPECT_EQ(scene->shapes[i].shapeIndex, i);
        EXPECT_EQ(scene->shapes[i].filename.filename(), "bidir.serialized");
    }
    EXPECT_EQ(scene->shapes[0].bsdf->kind, BsdfDescription::Kind::Dielectric);
    const BsdfDescription& lamp = scene->shapes[1].bsdf.value();
    EXPECT_EQ(lamp.kind, BsdfDescription::Kind::Ward);
    EXPECT_FLOAT_EQ(lamp.alphaU, 0.4f);
    expectNear(lamp.reflectance.value, Rgb(0.0f));
    expectNear(lamp.specularReflectance.value, Rgb(0.616f, 0.4752f, 0.352f));
    EXPECT_EQ(std::count_if(scene->shapes.begin(), scene->shapes.end(),
                            [](const ShapeDescription& s) { return s.areaRadiance.has_value(); }),
              2);
    EXPECT_TRUE(scene->media.empty());  // commented out in the file
    EXPECT_TRUE(
        mentions(testing::PrintToString(scene->ignored),
                 {"integrator 'sppm' (parameters photonCount, maxPasses, stepSnapshot, kNN, dualBuffer)",
                  "emitter 'area' (parameters samplingWeight)", "sensor 'perspective' (parameters focusDistance)"}));
    EXPECT_FALSE(mentions(testing::PrintToString(scene->ignored), {"rfilter"}));  // box is what happens here
}

}  // namespace
}  // namespace vrl
