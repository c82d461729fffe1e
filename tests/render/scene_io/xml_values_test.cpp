// Tests for the values of Mitsuba scene elements as the parser reads them
// (render/scene_io/mitsuba/xml_values.cpp): transforms (translate, rotate,
// scale, matrix, lookat, their order), rgb/spectrum/float colours, points and
// vectors, and text where none belongs.
#include "tests/render/scene_io/mitsuba_test_support.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <string>

namespace vrl {
namespace {

using mitsuba_test::parse;
using mitsuba_test::mentions;
using mitsuba_test::expectNear;
using mitsuba_test::LogCapture;

// ---------------------------------------------------------------- transforms

Transform shapeTransform(const std::string& steps) {
    const SceneDescription scene =
        parse({"<shape type=\"rectangle\"><transform name=\"toWorld\">" + steps + "</transform></shape>"});
    return scene.shapes.at(0).toWorld;
}

TEST(MitsubaParser, TransformTranslateThenRotate) {
    // (1,0,0) -> translate -> (2,0,0) -> rotate 90 about z -> (0,2,0).
    const Transform t = shapeTransform("<translate x=\"1\"/><rotate z=\"1\" angle=\"90\"/>");
    expectNear(t.applyPoint(Vec3(1, 0, 0)), Vec3(0, 2, 0));
}

TEST(MitsubaParser, TransformRotateThenTranslate) {
    // (1,0,0) -> rotate 90 about z -> (0,1,0) -> translate -> (1,1,0).
    const Transform t = shapeTransform("<rotate z=\"1\" angle=\"90\"/><translate x=\"1\"/>");
    expectNear(t.applyPoint(Vec3(1, 0, 0)), Vec3(1, 1, 0));
}

TEST(MitsubaParser, TransformValueForms) {
    expectNear(shapeTransform("<translate value=\"1, 2, 3\"/>").applyPoint(Vec3(0.0f)), Vec3(1, 2, 3));
    expectNear(shapeTransform("<rotate value=\"0 0 1\" angle=\"90\"/>").applyPoint(Vec3(1, 0, 0)), Vec3(0, 1, 0));
    expectNear(shapeTransform("<translate y=\"-2\"/>").applyPoint(Vec3(1, 1, 1)), Vec3(1, -1, 1));
}

TEST(MitsubaParser, TransformScaleDefaults) {
    expectNear(shapeTransform("<scale x=\"2\"/>").applyPoint(Vec3(1, 1, 1)), Vec3(2, 1, 1));
    expectNear(shapeTransform("<scale y=\"3\" z=\"4\"/>").applyPoint(Vec3(1, 1, 1)), Vec3(1, 3, 4));
    expectNear(shapeTransform("<scale value=\"3\"/>").applyPoint(Vec3(1, 2, 3)), Vec3(3, 6, 9));
    expectNear(shapeTransform("<scale value=\"1, 2, 3\"/>").applyPoint(Vec3(1, 1, 1)), Vec3(1, 2, 3));
}

TEST(MitsubaParser, TransformMatrixIsRowMajorForColumnVectors) {
    const Transform t = shapeTransform("<matrix value=\"0 -1 0 5  1 0 0 6  0 0 1 7  0 0 0 1\"/>");
    expectNear(t.applyPoint(Vec3(0.0f)), Vec3(5, 6, 7));
    expectNear(t.applyPoint(Vec3(1, 0, 0)), Vec3(5, 7, 7));  // x axis -> +y
    expectNear(t.applyVector(Vec3(0, 1, 0)), Vec3(-1, 0, 0));
    // Mitsuba exports write exponents with leading zeros and use commas or spaces.
    const Transform e = shapeTransform("<matrix value=\"1,0,0,1.5e-001, 0,1,0,0, 0,0,1,0, 0,0,0,1\"/>");
    expectNear(e.applyPoint(Vec3(0.0f)), Vec3(0.15f, 0, 0));
}

TEST(MitsubaParser, TransformLookAt) {
    for (const std::string tag : {"lookat", "lookAt"}) {
        const Transform t = shapeTransform("<" + tag + " origin=\"0, 0, -4\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>");
        expectNear(t.applyPoint(Vec3(0.0f)), Vec3(0, 0, -4));
        expectNear(t.applyVector(Vec3(0, 0, 1)), Vec3(0, 0, 1));  // looks along +z towards the target
        expectNear(t.applyVector(Vec3(0, 1, 0)), Vec3(0, 1, 0));  // up
        expectNear(t.applyVector(Vec3(1, 0, 0)), Vec3(1, 0, 0));  // +x = up x dir
    }
    // Without 'up' any perpendicular frame will do; the view direction must still be right.
    const Transform noUp = shapeTransform("<lookat origin=\"1, 1, 1\" target=\"1, 3, 1\"/>");
    expectNear(noUp.applyPoint(Vec3(0.0f)), Vec3(1, 1, 1));
    expectNear(noUp.applyVector(Vec3(0, 0, 1)), Vec3(0, 1, 0));
}

TEST(MitsubaParser, StrayTextIsOnlyAWarning) {
    LogCapture log;
    EXPECT_EQ(parse({"<shape type=\"cube\">oops</shape>"}).shapes.size(), 1u);
    EXPECT_TRUE(mentions(log.text(), {"test.xml:2:", "oops"}));
}

TEST(MitsubaParser, EmptyTransformIsIdentity) { EXPECT_TRUE(shapeTransform("").isIdentity()); }

// ---------------------------------------------------------------- values

Rgb diffuseReflectance(const std::string& valueElement) {
    const SceneDescription scene =
        parse({"<shape type=\"cube\"><bsdf type=\"diffuse\">" + valueElement + "</bsdf></shape>"});
    return scene.shapes.at(0).bsdf.value().reflectance.value;
}

TEST(MitsubaParser, RgbForms) {
    expectNear(diffuseReflectance("<rgb name=\"reflectance\" value=\"0.1, 0.2, 0.3\"/>"), Rgb(0.1f, 0.2f, 0.3f));
    expectNear(diffuseReflectance("<rgb name=\"reflectance\" value=\"0.1 0.2 0.3\"/>"), Rgb(0.1f, 0.2f, 0.3f));
    expectNear(diffuseReflectance("<rgb name=\"reflectance\" value=\"0.25\"/>"), Rgb(0.25f));
    expectNear(diffuseReflectance("<rgb name=\"reflectance\" value=\"#ff3300\"/>"), Rgb(1.0f, 0.2f, 0.0f));
    expectNear(diffuseReflectance("<spectrum name=\"reflectance\" value=\"0.4\"/>"), Rgb(0.4f));
    expectNear(diffuseReflectance("<float name=\"reflectance\" value=\"0.6\"/>"), Rgb(0.6f));
    expectNear(diffuseReflectance(""), Rgb(0.5f));  // Mitsuba's default
}

TEST(MitsubaParser, ReflectanceAboveOneIsOnlyAWarning) {
    LogCapture log;
    expectNear(diffuseReflectance("<rgb name=\"reflectance\" value=\"1.5, 0.5, 0.5\"/>"), Rgb(1.5f, 0.5f, 0.5f));
    EXPECT_TRUE(mentions(log.text(), {"reflectance", "exceeds 1"}));
}

TEST(MitsubaParser, PointForms) {
    const SceneDescription scene = parse({
        "<shape type=\"sphere\"><point name=\"center\" x=\"1\" z=\"3\"/></shape>",
        "<shape type=\"sphere\"><point name=\"center\" value=\"4, 5, 6\"/></shape>",
        "<shape type=\"sphere\"><vector name=\"center\" y=\"-2\"/></shape>",
    });
    expectNear(scene.shapes[0].center, Vec3(1, 0, 3));
    expectNear(scene.shapes[1].center, Vec3(4, 5, 6));
    expectNear(scene.shapes[2].center, Vec3(0, -2, 0));
}

TEST(MitsubaParser, LookAtSpellingsAgreeAndTranslateDefaultsToZero) {
    const Transform lower = shapeTransform("<lookat origin=\"1, 2, 3\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>");
    const Transform camel = shapeTransform("<lookAt origin=\"1 2 3\" target=\"0 0 0\" up=\"0 1 0\"/>");
    for (const Vec3& p : {Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})
        expectNear(lower.applyPoint(p), camel.applyPoint(p));
    expectNear(shapeTransform("<translate y=\"2\"/>").applyPoint(Vec3(1.0f)), Vec3(1, 3, 1));  // x, z are 0
}

}  // namespace
}  // namespace vrl
