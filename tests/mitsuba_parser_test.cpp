// Tests for the Mitsuba 0.5/0.6 XML parser: every supported element and value
// form loads with the right numbers, and every rejected input is a SceneError
// naming the file, the line and the offending name (plus a valid alternative).
#include "render/mitsuba_parser.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>
#include <stdlib.h>  // mkdtemp

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl {
namespace {

constexpr float kTolerance = 1e-5f;

std::filesystem::path fixtureDir() { return std::filesystem::path(VRL_TEST_DATA_DIR) / "scenes/parser"; }

// A scene whose first line is <scene version="0.5.0">, then `lines` (so lines[i] is on line i + 2).
std::string sceneXml(std::initializer_list<std::string> lines) {
    std::string xml = "<scene version=\"0.5.0\">\n";
    for (const std::string& line : lines) xml += line + "\n";
    return xml + "</scene>\n";
}

SceneDescription parse(std::initializer_list<std::string> lines, const ParseOptions& options = {}) {
    return parseMitsubaSceneString(sceneXml(lines), fixtureDir(), options, "test.xml");
}

// The message of the SceneError that parsing `xml` (named bad.xml) throws; "" (and a failure) if none.
std::string errorOf(const std::string& xml, const ParseOptions& options = {}) {
    try {
        parseMitsubaSceneString(xml, fixtureDir(), options, "bad.xml");
    } catch (const SceneError& e) {
        return e.what();
    }
    ADD_FAILURE() << "expected a SceneError for:\n" << xml;
    return "";
}

::testing::AssertionResult mentions(const std::string& text, std::initializer_list<std::string> words) {
    for (const std::string& word : words)
        if (text.find(word) == std::string::npos)
            return ::testing::AssertionFailure() << "'" << word << "' is missing from: " << text;
    return ::testing::AssertionSuccess();
}

void expectNear(const Vec3& actual, const Vec3& expected) {
    EXPECT_NEAR(actual.x, expected.x, kTolerance);
    EXPECT_NEAR(actual.y, expected.y, kTolerance);
    EXPECT_NEAR(actual.z, expected.z, kTolerance);
}

// Routes spdlog's default logger into a buffer for the lifetime of the object.
class LogCapture {
public:
    LogCapture()
        : sink_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(128)), previous_(spdlog::default_logger()) {
        spdlog::set_default_logger(std::make_shared<spdlog::logger>("parser-test-capture", sink_));
    }
    ~LogCapture() { spdlog::set_default_logger(previous_); }
    std::string text() const {
        std::string out;
        for (const std::string& line : sink_->last_formatted()) out += line;
        return out;
    }

private:
    std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
    std::shared_ptr<spdlog::logger> previous_;
};

// ---------------------------------------------------------------- scene, integrator

TEST(MitsubaParser, EmptySceneKeepsDefaultsAndRecordsVersion) {
    LogCapture log;
    const SceneDescription scene = parseMitsubaSceneString("<scene version=\"0.6.0\"/>", fixtureDir(), {}, "empty.xml");
    EXPECT_EQ(scene.version, "0.6.0");
    EXPECT_EQ(scene.file, std::filesystem::path("empty.xml"));
    EXPECT_EQ(scene.sensor.width, 768);
    EXPECT_EQ(scene.sensor.height, 576);
    EXPECT_EQ(scene.sensor.sampleCount, 4);
    EXPECT_FLOAT_EQ(scene.sensor.fov, 45.0f);
    EXPECT_EQ(scene.integrator.type, "volpath");
    EXPECT_EQ(scene.integrator.maxDepth, -1);
    EXPECT_TRUE(scene.shapes.empty());
    EXPECT_TRUE(scene.emitters.empty());
    EXPECT_TRUE(scene.media.empty());
    EXPECT_TRUE(mentions(log.text(), {"no <sensor>"}));
}

TEST(MitsubaParser, IntegratorTypesAreKeptAsWritten) {
    for (const std::string type : {"volpath", "volpath_simple", "path", "direct", "vrl", "vrlcuts", "vpl"}) {
        const SceneDescription scene = parse({"<integrator type=\"" + type + "\"/>"});
        EXPECT_EQ(scene.integrator.type, type);
    }
}

TEST(MitsubaParser, IntegratorMaxDepthAndLocation) {
    const SceneDescription scene =
        parse({"", "<integrator type=\"path\">", "  <integer name=\"maxDepth\" value=\"7\"/>", "</integrator>"});
    EXPECT_EQ(scene.integrator.maxDepth, 7);
    EXPECT_EQ(scene.integrator.where.line, 3);
    EXPECT_EQ(scene.integrator.where.file, "test.xml");
    EXPECT_EQ(
        parse({"<integrator type=\"path\"><integer name=\"maxDepth\" value=\"-1\"/></integrator>"}).integrator.maxDepth,
        -1);
}

TEST(MitsubaParser, IntegratorIgnoredParametersWarn) {
    LogCapture log;
    const SceneDescription scene = parse({"<integrator type=\"volpath\">", "  <integer name=\"rrDepth\" value=\"5\"/>",
                                          "  <boolean name=\"strictNormals\" value=\"true\"/>",
                                          "  <boolean name=\"hideEmitters\" value=\"false\"/>", "</integrator>"});
    EXPECT_EQ(scene.integrator.type, "volpath");
    EXPECT_TRUE(mentions(log.text(), {"rrDepth", "strictNormals", "hideEmitters"}));
}

// ---------------------------------------------------------------- sensor, film, sampler

TEST(MitsubaParser, SensorFilmAndSampler) {
    const SceneDescription scene = parse({
        "<sensor type=\"perspective\">",
        "  <float name=\"fov\" value=\"39.5\"/>",
        "  <string name=\"fovAxis\" value=\"smaller\"/>",
        "  <float name=\"nearClip\" value=\"0.5\"/>",
        "  <float name=\"farClip\" value=\"250\"/>",
        "  <transform name=\"toWorld\"><translate x=\"1\" y=\"2\" z=\"3\"/></transform>",
        "  <sampler type=\"independent\"><integer name=\"sampleCount\" value=\"1024\"/></sampler>",
        "  <film type=\"hdrfilm\">",
        "    <integer name=\"width\" value=\"320\"/>",
        "    <integer name=\"height\" value=\"200\"/>",
        "  </film>",
        "</sensor>",
    });
    const SensorDescription& sensor = scene.sensor;
    EXPECT_FLOAT_EQ(sensor.fov, 39.5f);
    EXPECT_EQ(sensor.fovAxis, SensorDescription::FovAxis::Smaller);
    EXPECT_FLOAT_EQ(sensor.nearClip, 0.5f);
    EXPECT_FLOAT_EQ(sensor.farClip, 250.0f);
    expectNear(sensor.toWorld.applyPoint(Vec3(0.0f)), Vec3(1, 2, 3));
    EXPECT_EQ(sensor.sampleCount, 1024);
    EXPECT_EQ(sensor.width, 320);
    EXPECT_EQ(sensor.height, 200);
    EXPECT_EQ(sensor.medium, -1);
    EXPECT_EQ(sensor.where.line, 2);
}

TEST(MitsubaParser, SensorFovAxisValues) {
    const std::pair<std::string, SensorDescription::FovAxis> cases[] = {
        {"x", SensorDescription::FovAxis::X},
        {"y", SensorDescription::FovAxis::Y},
        {"diagonal", SensorDescription::FovAxis::Diagonal},
        {"smaller", SensorDescription::FovAxis::Smaller},
        {"larger", SensorDescription::FovAxis::Larger},
    };
    for (const auto& [text, axis] : cases) {
        const SceneDescription scene = parse({"<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/>",
                                              "<string name=\"fovAxis\" value=\"" + text + "\"/></sensor>"});
        EXPECT_EQ(scene.sensor.fovAxis, axis) << text;
        EXPECT_FLOAT_EQ(scene.sensor.fov, 30.0f);
    }
}

TEST(MitsubaParser, SensorWithoutFovUsesMitsubaFocalLength) {
    // Mitsuba: 50mm on 36x24mm film, along the diagonal: 2 atan(sqrt(36^2 + 24^2) / 100).
    const SceneDescription byDefault = parse({"<sensor type=\"perspective\"/>"});
    EXPECT_NEAR(byDefault.sensor.fov, 46.7930f, 1e-3f);
    EXPECT_EQ(byDefault.sensor.fovAxis, SensorDescription::FovAxis::Diagonal);
    const SceneDescription wide =
        parse({"<sensor type=\"perspective\"><string name=\"focalLength\" value=\"35mm\"/></sensor>"});
    EXPECT_NEAR(wide.sensor.fov, 63.4400f, 1e-3f);
}

TEST(MitsubaParser, FilmAndSamplerIgnoredParametersWarn) {
    LogCapture log;
    const SceneDescription scene = parse({
        "<sensor type=\"perspective\">",
        "  <film type=\"ldrfilm\" id=\"film\">",
        "    <integer name=\"width\" value=\"16\"/><integer name=\"height\" value=\"8\"/>",
        "    <string name=\"fileFormat\" value=\"png\"/><string name=\"pixelFormat\" value=\"rgb\"/>",
        "    <float name=\"gamma\" value=\"2.2\"/><boolean name=\"banner\" value=\"false\"/>",
        "    <rfilter type=\"gaussian\"/>",
        "  </film>",
        "  <sampler type=\"sobol\"><integer name=\"sampleCount\" value=\"16\"/><integer name=\"scramble\" "
        "value=\"3\"/></sampler>",
        "</sensor>",
    });
    EXPECT_EQ(scene.sensor.width, 16);
    EXPECT_EQ(scene.sensor.height, 8);
    EXPECT_EQ(scene.sensor.sampleCount, 16);
    EXPECT_TRUE(mentions(log.text(), {"fileFormat", "pixelFormat", "gamma", "banner", "filter", "scramble"}));
}

TEST(MitsubaParser, AllSamplerTypesAreAccepted) {
    for (const std::string type : {"independent", "ldsampler", "stratified", "halton", "sobol"}) {
        const SceneDescription scene = parse({"<sensor type=\"perspective\"><sampler type=\"" + type +
                                              "\"><integer name=\"sampleCount\" value=\"9\"/></sampler></sensor>"});
        EXPECT_EQ(scene.sensor.sampleCount, 9) << type;
    }
}

TEST(MitsubaParser, SensorMediumNestedOrReferenced) {
    const SceneDescription nested =
        parse({"<sensor type=\"perspective\">",
               "<medium type=\"homogeneous\"><float name=\"scale\" value=\"2\"/></medium>", "</sensor>"});
    ASSERT_EQ(nested.media.size(), 1u);
    EXPECT_EQ(nested.sensor.medium, 0);
    const SceneDescription referenced =
        parse({"<medium type=\"homogeneous\" id=\"a\"/>", "<medium type=\"homogeneous\" id=\"b\"/>",
               "<sensor type=\"perspective\"><ref id=\"b\"/></sensor>"});
    EXPECT_EQ(referenced.sensor.medium, 1);
}

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

// ---------------------------------------------------------------- $name substitution

TEST(MitsubaParser, DefaultsAreSubstitutedEverywhere) {
    const SceneDescription scene = parse({
        "<default name=\"spp\" value=\"64\"/>",
        "<default name=\"r\" value=\"0.25\"/>",
        "<default name=\"kind\" value=\"sphere\"/>",
        "<sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sampleCount\" "
        "value=\"$spp\"/></sampler></sensor>",
        "<shape type=\"$kind\"><float name=\"radius\" value=\"1$r\"/>",  // embedded in a longer string: "10.25"
        "  <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"$r, 0.5, $r\"/></bsdf></shape>",
    });
    EXPECT_EQ(scene.sensor.sampleCount, 64);
    ASSERT_EQ(scene.shapes.size(), 1u);
    EXPECT_EQ(scene.shapes[0].kind, ShapeDescription::Kind::Sphere);
    EXPECT_FLOAT_EQ(scene.shapes[0].radius, 10.25f);
    expectNear(scene.shapes[0].bsdf->reflectance.value, Rgb(0.25f, 0.5f, 0.25f));
}

TEST(MitsubaParser, CommandLineDefinesOverrideDefaults) {
    ParseOptions options;
    options.defines = {{"spp", "5"}, {"depth", "3"}};  // "depth" has no <default>: still usable
    const SceneDescription scene = parse(
        {
            "<default name=\"spp\" value=\"64\"/>",
            "<integrator type=\"path\"><integer name=\"maxDepth\" value=\"$depth\"/></integrator>",
            "<sensor type=\"perspective\"><sampler type=\"independent\"><integer name=\"sampleCount\" "
            "value=\"$spp\"/></sampler></sensor>",
        },
        options);
    EXPECT_EQ(scene.sensor.sampleCount, 5);
    EXPECT_EQ(scene.integrator.maxDepth, 3);
}

TEST(MitsubaParser, LongestDefinedNameWins) {
    const SceneDescription scene = parse({
        "<default name=\"res\" value=\"10\"/>",
        "<default name=\"resx\" value=\"32\"/>",
        "<sensor type=\"perspective\"><film type=\"hdrfilm\">",
        "  <integer name=\"width\" value=\"$resx\"/><integer name=\"height\" value=\"$res\"/>",
        "</film></sensor>",
    });
    EXPECT_EQ(scene.sensor.width, 32);
    EXPECT_EQ(scene.sensor.height, 10);
}

TEST(MitsubaParser, FirstDefaultWins) {
    const SceneDescription scene = parse({
        "<default name=\"d\" value=\"2\"/>",
        "<default name=\"d\" value=\"9\"/>",
        "<integrator type=\"path\"><integer name=\"maxDepth\" value=\"$d\"/></integrator>",
    });
    EXPECT_EQ(scene.integrator.maxDepth, 2);
}

// ---------------------------------------------------------------- bsdfs, refs, ids

TEST(MitsubaParser, BsdfKindsAndTwoSided) {
    const SceneDescription scene = parse({
        "<bsdf type=\"diffuse\" id=\"red\"><rgb name=\"reflectance\" value=\"0.8, 0.1, 0.1\"/></bsdf>",
        "<bsdf type=\"twosided\" id=\"wall\"><bsdf type=\"diffuse\"><rgb name=\"reflectance\" "
        "value=\"0.3\"/></bsdf></bsdf>",
        "<shape type=\"rectangle\"><ref id=\"red\"/></shape>",
        "<shape type=\"rectangle\"><ref name=\"bsdf\" id=\"wall\"/></shape>",
        "<shape type=\"rectangle\"><bsdf type=\"twosided\"><ref id=\"red\"/></bsdf></shape>",
        "<shape type=\"rectangle\"><bsdf type=\"null\"/></shape>",
        "<shape type=\"rectangle\"/>",
    });
    ASSERT_EQ(scene.shapes.size(), 5u);
    EXPECT_EQ(scene.shapes[0].bsdf->kind, BsdfDescription::Kind::Diffuse);
    expectNear(scene.shapes[0].bsdf->reflectance.value, Rgb(0.8f, 0.1f, 0.1f));
    EXPECT_FALSE(scene.shapes[0].bsdf->twoSided);
    expectNear(scene.shapes[1].bsdf->reflectance.value, Rgb(0.3f));
    EXPECT_TRUE(scene.shapes[1].bsdf->twoSided);
    expectNear(scene.shapes[2].bsdf->reflectance.value, Rgb(0.8f, 0.1f, 0.1f));
    EXPECT_TRUE(scene.shapes[2].bsdf->twoSided);
    EXPECT_EQ(scene.shapes[3].bsdf->kind, BsdfDescription::Kind::Null);
    EXPECT_FALSE(scene.shapes[4].bsdf.has_value());
}

TEST(MitsubaParser, IdsAreGlobalEvenWhenNested) {
    const SceneDescription scene = parse({
        "<shape type=\"sphere\">",
        "  <bsdf type=\"diffuse\" id=\"inner\"><rgb name=\"reflectance\" value=\"0.2\"/></bsdf>",
        "  <medium type=\"homogeneous\" name=\"interior\" id=\"smoke\"><rgb name=\"sigmaS\" value=\"3\"/>",
        "    <rgb name=\"sigmaA\" value=\"4\"/></medium>",
        "</shape>",
        "<shape type=\"cube\"><ref id=\"inner\"/><ref name=\"exterior\" id=\"smoke\"/></shape>",
    });
    ASSERT_EQ(scene.media.size(), 1u);
    EXPECT_EQ(scene.media[0].id, "smoke");
    expectNear(scene.media[0].sigmaS, Rgb(3.0f));
    EXPECT_EQ(scene.shapes[0].interiorMedium, 0);
    EXPECT_EQ(scene.shapes[1].exteriorMedium, 0);
    EXPECT_EQ(scene.shapes[1].interiorMedium, -1);
    expectNear(scene.shapes[1].bsdf->reflectance.value, Rgb(0.2f));
}

// ---------------------------------------------------------------- shapes and emitters

TEST(MitsubaParser, ShapeKinds) {
    const SceneDescription scene = parse({
        "<shape type=\"obj\"><string name=\"filename\" value=\"tiny.obj\"/>",
        "  <boolean name=\"faceNormals\" value=\"true\"/><boolean name=\"flipNormals\" value=\"true\"/>",
        "  <transform name=\"toWorld\"><scale value=\"2\"/></transform></shape>",
        "<shape type=\"rectangle\"/>",
        "<shape type=\"cube\"><boolean name=\"flipNormals\" value=\"true\"/></shape>",
        "<shape type=\"sphere\"><point name=\"center\" x=\"1\" y=\"2\" z=\"3\"/><float name=\"radius\" "
        "value=\"0.5\"/></shape>",
        "<shape type=\"disk\"><transform name=\"toWorld\"><translate z=\"1\"/></transform></shape>",
    });
    ASSERT_EQ(scene.shapes.size(), 5u);
    const ShapeDescription& obj = scene.shapes[0];
    EXPECT_EQ(obj.kind, ShapeDescription::Kind::Obj);
    EXPECT_EQ(obj.filename, (fixtureDir() / "tiny.obj").lexically_normal());
    EXPECT_TRUE(obj.faceNormals);
    EXPECT_TRUE(obj.flipNormals);
    expectNear(obj.toWorld.applyPoint(Vec3(1, 1, 1)), Vec3(2, 2, 2));
    EXPECT_EQ(obj.where.line, 2);
    EXPECT_EQ(scene.shapes[1].kind, ShapeDescription::Kind::Rectangle);
    EXPECT_FALSE(scene.shapes[1].flipNormals);
    EXPECT_EQ(scene.shapes[2].kind, ShapeDescription::Kind::Cube);
    EXPECT_TRUE(scene.shapes[2].flipNormals);
    EXPECT_EQ(scene.shapes[3].kind, ShapeDescription::Kind::Sphere);
    expectNear(scene.shapes[3].center, Vec3(1, 2, 3));
    EXPECT_FLOAT_EQ(scene.shapes[3].radius, 0.5f);
    EXPECT_EQ(scene.shapes[4].kind, ShapeDescription::Kind::Disk);
    expectNear(scene.shapes[4].toWorld.applyPoint(Vec3(0.0f)), Vec3(0, 0, 1));
}

TEST(MitsubaParser, AreaEmitterAndMediaOnShape) {
    const SceneDescription scene = parse({
        "<medium type=\"homogeneous\" id=\"outside\"/>",
        "<shape type=\"sphere\">",
        "  <emitter type=\"area\"><rgb name=\"radiance\" value=\"10, 20, 30\"/></emitter>",
        "  <medium type=\"homogeneous\" name=\"interior\"><float name=\"sigmaS\" value=\"2\"/><float name=\"sigmaA\" "
        "value=\"0\"/></medium>",
        "  <ref name=\"exterior\" id=\"outside\"/>",
        "</shape>",
        "<shape type=\"cube\"><emitter type=\"area\"><spectrum name=\"radiance\" value=\"100\"/></emitter></shape>",
    });
    ASSERT_EQ(scene.shapes.size(), 2u);
    ASSERT_TRUE(scene.shapes[0].areaRadiance.has_value());
    expectNear(*scene.shapes[0].areaRadiance, Rgb(10, 20, 30));
    EXPECT_EQ(scene.shapes[0].interiorMedium, 1);
    EXPECT_EQ(scene.shapes[0].exteriorMedium, 0);
    expectNear(scene.media[1].sigmaS, Rgb(2.0f));
    expectNear(scene.media[1].sigmaA, Rgb(0.0f));
    expectNear(*scene.shapes[1].areaRadiance, Rgb(100.0f));
}

TEST(MitsubaParser, PointEmitter) {
    const SceneDescription scene = parse({
        "<medium type=\"homogeneous\" id=\"m\"/>",
        "<emitter type=\"point\"><point name=\"position\" x=\"1\" y=\"2\" z=\"3\"/>",
        "  <rgb name=\"intensity\" value=\"5, 6, 7\"/><ref id=\"m\"/></emitter>",
        "<emitter type=\"point\"><transform name=\"toWorld\"><translate x=\"-1\"/></transform></emitter>",
    });
    ASSERT_EQ(scene.emitters.size(), 2u);
    const EmitterDescription& point = scene.emitters[0];
    EXPECT_EQ(point.kind, EmitterDescription::Kind::Point);
    expectNear(point.toWorld.applyPoint(Vec3(0.0f)), Vec3(1, 2, 3));
    expectNear(point.intensity, Rgb(5, 6, 7));
    EXPECT_EQ(point.medium, 0);
    EXPECT_EQ(point.where.line, 3);
    expectNear(scene.emitters[1].toWorld.applyPoint(Vec3(0.0f)), Vec3(-1, 0, 0));
    expectNear(scene.emitters[1].intensity, Rgb(1.0f));
    EXPECT_EQ(scene.emitters[1].medium, -1);
}

TEST(MitsubaParser, SpotEmitterBeamWidthDefaultsToThreeQuartersOfCutoff) {
    const SceneDescription scene = parse({
        "<emitter type=\"spot\"><float name=\"cutoffAngle\" value=\"40\"/><spectrum name=\"intensity\" value=\"3\"/>",
        "  <transform name=\"toWorld\"><lookat origin=\"0, 5, 0\" target=\"0, 0, 0\" up=\"0, 0, "
        "1\"/></transform></emitter>",
        "<emitter type=\"spot\"/>",
        "<emitter type=\"spot\"><float name=\"cutoffAngle\" value=\"30\"/><float name=\"beamWidth\" "
        "value=\"10\"/></emitter>",
    });
    ASSERT_EQ(scene.emitters.size(), 3u);
    EXPECT_EQ(scene.emitters[0].kind, EmitterDescription::Kind::Spot);
    EXPECT_FLOAT_EQ(scene.emitters[0].cutoffAngle, 40.0f);
    EXPECT_FLOAT_EQ(scene.emitters[0].beamWidth, 30.0f);
    expectNear(scene.emitters[0].intensity, Rgb(3.0f));
    expectNear(scene.emitters[0].toWorld.applyVector(Vec3(0, 0, 1)), Vec3(0, -1, 0));
    EXPECT_FLOAT_EQ(scene.emitters[1].cutoffAngle, 20.0f);
    EXPECT_FLOAT_EQ(scene.emitters[1].beamWidth, 15.0f);
    EXPECT_FLOAT_EQ(scene.emitters[2].beamWidth, 10.0f);
}

// ---------------------------------------------------------------- media

TEST(MitsubaParser, MediumSigmaSAndSigmaAWithScale) {
    const SceneDescription scene =
        parse({"<medium type=\"homogeneous\" id=\"m\">",
               "  <rgb name=\"sigmaS\" value=\"1, 2, 3\"/><rgb name=\"sigmaA\" value=\"0.5\"/>",
               "  <float name=\"scale\" value=\"0.5\"/></medium>"});
    ASSERT_EQ(scene.media.size(), 1u);
    expectNear(scene.media[0].sigmaS, Rgb(0.5f, 1.0f, 1.5f));
    expectNear(scene.media[0].sigmaA, Rgb(0.25f));
    EXPECT_EQ(scene.media[0].phase.kind, PhaseDescription::Kind::Isotropic);
    EXPECT_EQ(scene.media[0].where.line, 2);
}

TEST(MitsubaParser, MediumSigmaTAndAlbedo) {
    // sigmaS = albedo * sigmaT, sigmaA = sigmaT - sigmaS, both times scale.
    const SceneDescription scene =
        parse({"<medium type=\"homogeneous\" id=\"m\">",
               "  <rgb name=\"sigmaT\" value=\"2, 4, 8\"/><rgb name=\"albedo\" value=\"0.25, 0.5, 1\"/>",
               "  <float name=\"scale\" value=\"3\"/></medium>"});
    expectNear(scene.media[0].sigmaS, Rgb(1.5f, 6.0f, 24.0f));
    expectNear(scene.media[0].sigmaA, Rgb(4.5f, 6.0f, 0.0f));
}

TEST(MitsubaParser, MediumWithoutCoefficientsUsesOnes) {
    LogCapture log;
    const SceneDescription scene = parse({"<medium type=\"homogeneous\" id=\"m\"/>"});
    expectNear(scene.media[0].sigmaS, Rgb(1.0f));
    expectNear(scene.media[0].sigmaA, Rgb(1.0f));
    EXPECT_TRUE(mentions(log.text(), {"sigmaS = sigmaA = 1"}));
}

TEST(MitsubaParser, PhaseFunctions) {
    const SceneDescription scene = parse({
        "<medium type=\"homogeneous\" id=\"a\"><phase type=\"hg\"><float name=\"g\" value=\"-0.3\"/></phase></medium>",
        "<medium type=\"homogeneous\" id=\"b\"><phase type=\"hg\"/></medium>",
        "<medium type=\"homogeneous\" id=\"c\"><phase type=\"isotropic\"/></medium>",
    });
    EXPECT_EQ(scene.media[0].phase.kind, PhaseDescription::Kind::HenyeyGreenstein);
    EXPECT_FLOAT_EQ(scene.media[0].phase.g, -0.3f);
    EXPECT_FLOAT_EQ(scene.media[1].phase.g, 0.8f);  // Mitsuba's default
    EXPECT_EQ(scene.media[2].phase.kind, PhaseDescription::Kind::Isotropic);
}

// ---------------------------------------------------------------- bsdf plugins

// The bsdf of the first shape of a scene whose body is `bsdf` inside a <shape>.
BsdfDescription shapeBsdf(const std::string& bsdf) {
    const SceneDescription scene = parse({"<shape type=\"cube\">" + bsdf + "</shape>"});
    return scene.shapes.at(0).bsdf.value();
}

void expectConstant(const ColorDescription& color, const Rgb& value) {
    EXPECT_EQ(color.texture, -1);
    expectNear(color.value, value);
}

TEST(MitsubaParserBsdf, DielectricDefaultsAreMitsubas) {
    const BsdfDescription glass = shapeBsdf("<bsdf type=\"dielectric\"/>");
    EXPECT_EQ(glass.kind, BsdfDescription::Kind::Dielectric);
    EXPECT_FLOAT_EQ(glass.intIOR, 1.5046f);    // bk7
    EXPECT_FLOAT_EQ(glass.extIOR, 1.000277f);  // air
    expectConstant(glass.specularReflectance, Rgb(1.0f));
    expectConstant(glass.specularTransmittance, Rgb(1.0f));
    EXPECT_FALSE(glass.twoSided);
}

TEST(MitsubaParserBsdf, DielectricExplicitValuesAndNamedIors) {
    const BsdfDescription glass = shapeBsdf(
        "<bsdf type=\"dielectric\"><string name=\"intIOR\" value=\"Water\"/><float name=\"extIOR\" value=\"1.1\"/>"
        "<rgb name=\"specularReflectance\" value=\"0.9\"/><rgb name=\"specularTransmittance\" value=\"0.8, 0.7, "
        "0.6\"/></bsdf>");
    EXPECT_FLOAT_EQ(glass.intIOR, 1.333f);
    EXPECT_FLOAT_EQ(glass.extIOR, 1.1f);
    expectConstant(glass.specularReflectance, Rgb(0.9f));
    expectConstant(glass.specularTransmittance, Rgb(0.8f, 0.7f, 0.6f));
}

TEST(MitsubaParserBsdf, EveryNamedIorHasMitsubasValue) {
    const std::pair<std::string, float> table[] = {
        {"vacuum", 1.0f},      {"helium", 1.000036f},        {"hydrogen", 1.000132f},
        {"air", 1.000277f},    {"carbon dioxide", 1.00045f}, {"water", 1.3330f},
        {"acetone", 1.36f},    {"ethanol", 1.361f},          {"carbon tetrachloride", 1.461f},
        {"glycerol", 1.4729f}, {"benzene", 1.501f},          {"silicone oil", 1.52045f},
        {"bromine", 1.661f},   {"water ice", 1.31f},         {"fused quartz", 1.458f},
        {"pyrex", 1.470f},     {"acrylic glass", 1.49f},     {"polypropylene", 1.49f},
        {"bk7", 1.5046f},      {"sodium chloride", 1.544f},  {"amber", 1.55f},
        {"pet", 1.5750f},      {"diamond", 2.419f},
    };
    for (const auto& [name, value] : table) {
        const BsdfDescription bsdf = shapeBsdf("<bsdf type=\"roughdielectric\"><string name=\"extIOR\" value=\"" +
                                               name + "\"/><float name=\"intIOR\" value=\"3\"/></bsdf>");
        EXPECT_FLOAT_EQ(bsdf.extIOR, value) << name;
    }
}

TEST(MitsubaParserBsdf, RoughDielectricDistributionsAndRoughness) {
    const BsdfDescription byDefault = shapeBsdf("<bsdf type=\"roughdielectric\"/>");
    EXPECT_EQ(byDefault.kind, BsdfDescription::Kind::RoughDielectric);
    EXPECT_EQ(byDefault.distribution, MicrofacetKind::Beckmann);
    EXPECT_FLOAT_EQ(byDefault.alphaU, 0.1f);
    EXPECT_FLOAT_EQ(byDefault.alphaV, 0.1f);
    const BsdfDescription ggx = shapeBsdf(
        "<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"GGX\"/>"
        "<float name=\"alphaU\" value=\"0.05\"/><float name=\"alphaV\" value=\"0.3\"/></bsdf>");
    EXPECT_EQ(ggx.distribution, MicrofacetKind::GGX);
    EXPECT_FLOAT_EQ(ggx.alphaU, 0.05f);
    EXPECT_FLOAT_EQ(ggx.alphaV, 0.3f);
    for (const std::string name : {"phong", "as"}) {  // "as": Mitsuba 0.5's alias
        const BsdfDescription phong =
            shapeBsdf("<bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"" + name +
                      "\"/><float name=\"alpha\" value=\"0.2\"/></bsdf>");
        EXPECT_EQ(phong.distribution, MicrofacetKind::Phong) << name;
        EXPECT_FLOAT_EQ(phong.alphaU, 0.2f);
        EXPECT_FLOAT_EQ(phong.alphaV, 0.2f);
    }
}

TEST(MitsubaParserBsdf, ConductorDefaultsToCopper) {
    const BsdfDescription metal = shapeBsdf("<bsdf type=\"conductor\"/>");
    EXPECT_EQ(metal.kind, BsdfDescription::Kind::Conductor);
    const BsdfDescription defaults;
    expectNear(metal.eta, defaults.eta);
    expectNear(metal.k, defaults.k);
    expectNear(metal.eta, Rgb(0.200438f, 0.924033f, 1.10221f));
    expectNear(metal.k, Rgb(3.91295f, 2.45285f, 2.14219f));
    EXPECT_FLOAT_EQ(metal.extEta, 1.000277f);
    expectConstant(metal.specularReflectance, Rgb(1.0f));
}

TEST(MitsubaParserBsdf, ConductorPresets) {
    struct Preset {
        std::string name;
        Rgb eta, k;
    };
    // Mitsuba's data/ior spectra in linear sRGB (the staircase scene spells out Au and Al).
    const Preset presets[] = {
        {"none", Rgb(0.0f), Rgb(1.0f)},
        {"Cu", Rgb(0.200438f, 0.924033f, 1.10221f), Rgb(3.91295f, 2.45285f, 2.14219f)},
        {"Au", Rgb(0.143119f, 0.374957f, 1.44248f), Rgb(3.98316f, 2.38572f, 1.60322f)},
        {"Ag", Rgb(0.155265f, 0.116723f, 0.138381f), Rgb(4.82834f, 3.12225f, 2.14695f)},
        {"Al", Rgb(1.65746f, 0.880369f, 0.521229f), Rgb(9.22387f, 6.26952f, 4.837f)},
        {"Cr", Rgb(4.36968f, 2.9167f, 1.6547f), Rgb(5.20643f, 4.23136f, 3.75495f)},
    };
    for (const Preset& preset : presets) {
        const BsdfDescription metal =
            shapeBsdf("<bsdf type=\"roughconductor\"><string name=\"material\" value=\"" + preset.name + "\"/></bsdf>");
        SCOPED_TRACE(preset.name);
        EXPECT_EQ(metal.kind, BsdfDescription::Kind::RoughConductor);
        expectNear(metal.eta, preset.eta);
        expectNear(metal.k, preset.k);
    }
    EXPECT_NO_THROW(shapeBsdf("<bsdf type=\"conductor\"><string name=\"material\" value=\"NONE\"/></bsdf>"));
}

TEST(MitsubaParserBsdf, ConductorExplicitEtaKAndExtEta) {
    const BsdfDescription metal = shapeBsdf(
        "<bsdf type=\"roughconductor\"><string name=\"material\" value=\"Au\"/>"
        "<rgb name=\"eta\" value=\"2.8656, 2.11918, 1.94008\"/><rgb name=\"k\" value=\"3.03233 2.05611 1.61629\"/>"
        "<string name=\"extEta\" value=\"water\"/><rgb name=\"specularReflectance\" value=\"0.5\"/>"
        "<string name=\"distribution\" value=\"ggx\"/><float name=\"alpha\" value=\"0.3\"/></bsdf>");
    expectNear(metal.eta, Rgb(2.8656f, 2.11918f, 1.94008f));  // eta and k override the preset
    expectNear(metal.k, Rgb(3.03233f, 2.05611f, 1.61629f));
    EXPECT_FLOAT_EQ(metal.extEta, 1.333f);  // kept apart: the model divides eta and k by it
    expectConstant(metal.specularReflectance, Rgb(0.5f));
    EXPECT_EQ(metal.distribution, MicrofacetKind::GGX);
    EXPECT_FLOAT_EQ(metal.alphaU, 0.3f);
}

TEST(MitsubaParserBsdf, PlasticDefaultsAndValues) {
    const BsdfDescription byDefault = shapeBsdf("<bsdf type=\"plastic\"/>");
    EXPECT_EQ(byDefault.kind, BsdfDescription::Kind::Plastic);
    EXPECT_FLOAT_EQ(byDefault.intIOR, 1.49f);  // polypropylene
    EXPECT_FLOAT_EQ(byDefault.extIOR, 1.000277f);
    expectConstant(byDefault.reflectance, Rgb(0.5f));
    expectConstant(byDefault.specularReflectance, Rgb(1.0f));
    EXPECT_FALSE(byDefault.nonlinear);
    const BsdfDescription rough = shapeBsdf(
        "<bsdf type=\"roughplastic\"><float name=\"alpha\" value=\"0.2\"/><string name=\"distribution\" "
        "value=\"ggx\"/><float name=\"intIOR\" value=\"1.5\"/><float name=\"extIOR\" value=\"1\"/>"
        "<boolean name=\"nonlinear\" value=\"true\"/><rgb name=\"diffuseReflectance\" value=\"0.578596\"/>"
        "<spectrum name=\"specularReflectance\" value=\"0.9\"/></bsdf>");
    EXPECT_EQ(rough.kind, BsdfDescription::Kind::RoughPlastic);
    EXPECT_FLOAT_EQ(rough.intIOR, 1.5f);
    EXPECT_FLOAT_EQ(rough.extIOR, 1.0f);
    EXPECT_TRUE(rough.nonlinear);
    EXPECT_EQ(rough.distribution, MicrofacetKind::GGX);
    EXPECT_FLOAT_EQ(rough.alphaU, 0.2f);
    EXPECT_FLOAT_EQ(rough.alphaV, 0.2f);
    expectConstant(rough.reflectance, Rgb(0.578596f));
    expectConstant(rough.specularReflectance, Rgb(0.9f));
}

TEST(MitsubaParserBsdf, WardDefaultsAndValues) {
    const BsdfDescription byDefault = shapeBsdf("<bsdf type=\"ward\"/>");
    EXPECT_EQ(byDefault.kind, BsdfDescription::Kind::Ward);
    EXPECT_EQ(byDefault.wardVariant, BsdfDescription::WardVariant::Balanced);
    EXPECT_FLOAT_EQ(byDefault.alphaU, 0.1f);
    EXPECT_FLOAT_EQ(byDefault.alphaV, 0.1f);
    expectConstant(byDefault.reflectance, Rgb(0.5f));
    expectConstant(byDefault.specularReflectance, Rgb(0.2f));
    const BsdfDescription lamp = shapeBsdf(
        "<bsdf type=\"ward\"><string name=\"variant\" value=\"ward-duer\"/><float name=\"alpha\" value=\"0.4\"/>"
        "<float name=\"alphaV\" value=\"0.6\"/><spectrum name=\"diffuseReflectance\" value=\"0\"/>"
        "<rgb name=\"specularReflectance\" value=\"0.61600 0.47520 0.35200\"/></bsdf>");
    EXPECT_EQ(lamp.wardVariant, BsdfDescription::WardVariant::WardDuer);
    EXPECT_FLOAT_EQ(lamp.alphaU, 0.4f);  // from alpha
    EXPECT_FLOAT_EQ(lamp.alphaV, 0.6f);  // alphaV overrides alpha
    expectConstant(lamp.reflectance, Rgb(0.0f));
    expectConstant(lamp.specularReflectance, Rgb(0.616f, 0.4752f, 0.352f));
    EXPECT_EQ(shapeBsdf("<bsdf type=\"ward\"><string name=\"variant\" value=\"ward\"/></bsdf>").wardVariant,
              BsdfDescription::WardVariant::Ward);
}

TEST(MitsubaParserBsdf, TwoSidedKeepsTheNestedModel) {
    const BsdfDescription metal = shapeBsdf(
        "<bsdf type=\"twosided\"><bsdf type=\"conductor\"><string name=\"material\" value=\"Au\"/>"
        "</bsdf></bsdf>");
    EXPECT_EQ(metal.kind, BsdfDescription::Kind::Conductor);
    EXPECT_TRUE(metal.twoSided);
    expectNear(metal.eta, Rgb(0.143119f, 0.374957f, 1.44248f));
}

TEST(MitsubaParserBsdf, NullBsdf) { EXPECT_EQ(shapeBsdf("<bsdf type=\"null\"/>").kind, BsdfDescription::Kind::Null); }

TEST(MitsubaParserBsdf, UnknownTypeListsEveryValidType) {
    const std::string message = errorOf(sceneXml({"<bsdf type=\"velvet\" id=\"v\"/>"}));
    EXPECT_TRUE(mentions(message, {"bad.xml:2:", "<bsdf type=\"velvet\" id=\"v\">", "'velvet'", "diffuse", "dielectric",
                                   "roughdielectric", "conductor", "roughconductor", "plastic", "roughplastic", "ward",
                                   "twosided", "bumpmap", "null"}));
}

TEST(MitsubaParserBsdf, SampleVisibleIsAcceptedAndReported) {
    const SceneDescription scene = parse({
        "<bsdf type=\"roughconductor\" id=\"a\"><boolean name=\"sampleVisible\" value=\"false\"/></bsdf>",
        "<bsdf type=\"roughconductor\" id=\"b\"><boolean name=\"sampleVisible\" value=\"true\"/></bsdf>",
    });
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_TRUE(mentions(scene.ignored[0], {"roughconductor", "sampleVisible"}));
}

// ---------------------------------------------------------------- textures

// A temporary directory holding stand-ins for the files a scene references
// (the parser only checks that they exist); scenes parsed from it resolve
// relative file names against it.
class SceneFiles {
public:
    explicit SceneFiles(std::initializer_list<std::string> files) {
        std::string pattern = (std::filesystem::temp_directory_path() / "vrl-parser-test-XXXXXX").string();
        if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
        directory_ = pattern;
        for (const std::string& file : files) {
            std::filesystem::create_directories((directory_ / file).parent_path());
            std::ofstream(directory_ / file) << "stand-in\n";
        }
    }
    ~SceneFiles() {
        std::error_code error;
        std::filesystem::remove_all(directory_, error);
    }
    SceneFiles(const SceneFiles&) = delete;
    SceneFiles& operator=(const SceneFiles&) = delete;

    const std::filesystem::path& directory() const { return directory_; }
    std::filesystem::path operator/(const std::string& file) const { return (directory_ / file).lexically_normal(); }
    SceneDescription parse(std::initializer_list<std::string> lines, const ParseOptions& options = {}) const {
        return parseMitsubaSceneString(sceneXml(lines), directory_, options, "test.xml");
    }

private:
    std::filesystem::path directory_;
};

TEST(MitsubaParserTexture, NestedBitmapWithDefaults) {
    const SceneFiles files({"textures/wood.jpg"});
    const SceneDescription scene = files.parse({
        "<shape type=\"cube\"><bsdf type=\"diffuse\">",
        "  <texture name=\"reflectance\" type=\"bitmap\"><string name=\"filename\" value=\"textures/wood.jpg\"/>",
        "  </texture>",
        "</bsdf></shape>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    const TextureDescription& texture = scene.textures[0];
    EXPECT_EQ(texture.filename, files / "textures/wood.jpg");
    EXPECT_EQ(texture.wrapU, TextureDescription::Wrap::Repeat);
    EXPECT_EQ(texture.wrapV, TextureDescription::Wrap::Repeat);
    EXPECT_FLOAT_EQ(texture.uscale, 1.0f);
    EXPECT_FLOAT_EQ(texture.vscale, 1.0f);
    EXPECT_FLOAT_EQ(texture.uoffset, 0.0f);
    EXPECT_FLOAT_EQ(texture.voffset, 0.0f);
    EXPECT_FALSE(texture.gamma.has_value());
    EXPECT_EQ(texture.where.line, 3);
    const ColorDescription& reflectance = scene.shapes.at(0).bsdf->reflectance;
    EXPECT_EQ(reflectance.texture, 0);
    expectNear(reflectance.value, Rgb(1.0f));
}

TEST(MitsubaParserTexture, BitmapParameters) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"a.png\"/>",
        "  <string name=\"wrapMode\" value=\"clamp\"/><string name=\"wrapModeV\" value=\"black\"/>",
        "  <float name=\"gamma\" value=\"-1\"/><float name=\"uvscale\" value=\"4\"/><float name=\"vscale\" "
        "value=\"2\"/>",
        "  <float name=\"uoffset\" value=\"0.25\"/><float name=\"voffset\" value=\"-0.5\"/>",
        "  <string name=\"channel\" value=\"rgb\"/><string name=\"filterType\" value=\"ewa\"/>",
        "  <float name=\"maxAnisotropy\" value=\"8\"/><boolean name=\"cache\" value=\"false\"/>",
        "</texture>",
        "<bsdf type=\"diffuse\" id=\"d\"><ref name=\"reflectance\" id=\"t\"/></bsdf>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    const TextureDescription& texture = scene.textures[0];
    EXPECT_EQ(texture.wrapU, TextureDescription::Wrap::Clamp);
    EXPECT_EQ(texture.wrapV, TextureDescription::Wrap::Zero);
    ASSERT_TRUE(texture.gamma.has_value());
    EXPECT_FLOAT_EQ(*texture.gamma, -1.0f);
    EXPECT_FLOAT_EQ(texture.uscale, 4.0f);  // from uvscale
    EXPECT_FLOAT_EQ(texture.vscale, 2.0f);  // vscale overrides uvscale
    EXPECT_FLOAT_EQ(texture.uoffset, 0.25f);
    EXPECT_FLOAT_EQ(texture.voffset, -0.5f);
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_TRUE(mentions(scene.ignored[0], {"texture 'bitmap'", "filterType", "maxAnisotropy", "cache"}));
}

TEST(MitsubaParserTexture, GammaZeroMeansAutomatic) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<bsdf type=\"diffuse\" id=\"d\"><texture name=\"reflectance\" type=\"bitmap\">",
        "<string name=\"filename\" value=\"a.png\"/><float name=\"gamma\" value=\"0\"/></texture></bsdf>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    EXPECT_FALSE(scene.textures[0].gamma.has_value());
}

TEST(MitsubaParserTexture, ReferencedTexturesAreGlobalAndStoredOnce) {
    const SceneFiles files({"wood.jpg", "fabric.jpg"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"wood\"><string name=\"filename\" value=\"wood.jpg\"/></texture>",
        "<bsdf type=\"plastic\" id=\"floor\"><ref name=\"diffuseReflectance\" id=\"wood\"/></bsdf>",
        "<bsdf type=\"twosided\" id=\"stairs\"><bsdf type=\"roughplastic\">",
        "  <ref name=\"diffuseReflectance\" id=\"wood\"/>",
        "  <texture name=\"specularReflectance\" type=\"bitmap\" id=\"cloth\">",
        "    <string name=\"filename\" value=\"fabric.jpg\"/></texture>",
        "</bsdf></bsdf>",
        // The same file declared again with the same mapping is shared.
        "<bsdf type=\"ward\" id=\"w\"><texture name=\"specularReflectance\" type=\"bitmap\">",
        "  <string name=\"filename\" value=\"wood.jpg\"/></texture><ref name=\"diffuseReflectance\" id=\"cloth\"/>",
        "</bsdf>",
        "<shape type=\"cube\"><ref id=\"floor\"/></shape>",
        "<shape type=\"cube\"><ref id=\"stairs\"/></shape>",
        "<shape type=\"cube\"><ref id=\"w\"/></shape>",
    });
    ASSERT_EQ(scene.textures.size(), 2u);
    EXPECT_EQ(scene.textures[0].filename, files / "wood.jpg");
    EXPECT_EQ(scene.textures[1].filename, files / "fabric.jpg");
    EXPECT_EQ(scene.shapes[0].bsdf->reflectance.texture, 0);
    EXPECT_EQ(scene.shapes[1].bsdf->reflectance.texture, 0);
    EXPECT_EQ(scene.shapes[1].bsdf->specularReflectance.texture, 1);
    EXPECT_TRUE(scene.shapes[1].bsdf->twoSided);
    EXPECT_EQ(scene.shapes[2].bsdf->specularReflectance.texture, 0);
    EXPECT_EQ(scene.shapes[2].bsdf->reflectance.texture, 1);
}

TEST(MitsubaParserTexture, DifferentMappingsOfOneFileAreDistinct) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<bsdf type=\"plastic\" id=\"p\">",
        "<texture name=\"diffuseReflectance\" type=\"bitmap\"><string name=\"filename\" value=\"a.png\"/></texture>",
        "<texture name=\"specularReflectance\" type=\"bitmap\"><string name=\"filename\" value=\"a.png\"/>",
        "<float name=\"uscale\" value=\"2\"/></texture>",
        "</bsdf>",
    });
    EXPECT_EQ(scene.textures.size(), 2u);
}

TEST(MitsubaParserTexture, ScaleTexture) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"base\"><string name=\"filename\" value=\"a.png\"/></texture>",
        "<shape type=\"cube\"><bsdf type=\"diffuse\"><texture name=\"reflectance\" type=\"scale\">",
        "  <rgb name=\"scale\" value=\"0.5, 0.25, 1\"/>",
        "  <texture type=\"scale\"><float name=\"scale\" value=\"0.5\"/><ref id=\"base\"/></texture>",
        "</texture></bsdf></shape>",
    });
    ASSERT_EQ(scene.textures.size(), 1u);
    const ColorDescription& reflectance = scene.shapes.at(0).bsdf->reflectance;
    EXPECT_EQ(reflectance.texture, 0);
    expectNear(reflectance.value, Rgb(0.25f, 0.125f, 0.5f));
}

TEST(MitsubaParserTexture, UnusedTexturesAreNotStored) {
    const SceneFiles files({"a.png"});
    const SceneDescription scene =
        files.parse({"<texture type=\"bitmap\" id=\"unused\"><string name=\"filename\" value=\"a.png\"/></texture>"});
    EXPECT_TRUE(scene.textures.empty());
}

TEST(MitsubaParserTexture, TextureFilesAreReportedAndConfined) {
    const SceneFiles files({"a.png"});
    std::vector<std::filesystem::path> referenced;
    ParseOptions options;
    options.onFileReferenced = [&](const std::filesystem::path& path) { referenced.push_back(path); };
    options.confineTo = files.directory();
    files.parse({"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"a.png\"/></texture>"}, options);
    ASSERT_EQ(referenced.size(), 1u);
    EXPECT_EQ(referenced[0], files / "a.png");
    options.confineTo = files.directory() / "elsewhere";
    try {
        files.parse({"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"a.png\"/></texture>"},
                    options);
        ADD_FAILURE() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"a.png", "outside the scene bundle"}));
    }
}

TEST(MitsubaParserTexture, BumpMapIsApproximatedByItsNestedBsdf) {
    const SceneFiles files({"bump.png"});
    const SceneDescription scene = files.parse({
        "<shape type=\"cube\">", "  <bsdf type=\"bumpmap\">",
        "    <texture name=\"map\" type=\"bitmap\"><string name=\"filename\" value=\"bump.png\"/></texture>",
        "    <bsdf type=\"roughconductor\" id=\"metal\"><string name=\"material\" value=\"Al\"/></bsdf>", "  </bsdf>",
        "</shape>",
        "<shape type=\"cube\"><ref id=\"metal\"/></shape>",  // the nested id names the bsdf without the bump map
    });
    ASSERT_EQ(scene.shapes.size(), 2u);
    const BsdfDescription& bumped = *scene.shapes[0].bsdf;
    EXPECT_EQ(bumped.kind, BsdfDescription::Kind::RoughConductor);
    expectNear(bumped.eta, Rgb(1.65746f, 0.880369f, 0.521229f));
    ASSERT_EQ(bumped.approximations.size(), 1u);
    EXPECT_TRUE(
        mentions(bumped.approximations[0], {"bumpmap at test.xml:3", "bump map ignored", "unperturbed normal"}));
    ASSERT_EQ(scene.approximations.size(), 1u);
    EXPECT_EQ(scene.approximations[0], bumped.approximations[0]);
    EXPECT_EQ(scene.shapes[1].bsdf->kind, BsdfDescription::Kind::RoughConductor);
    EXPECT_TRUE(scene.shapes[1].bsdf->approximations.empty());
    EXPECT_TRUE(scene.textures.empty());  // the displacement map is checked, not stored
}

TEST(MitsubaParserTexture, UnusedBumpMapAddsNoSceneApproximation) {
    const SceneFiles files({"bump.png"});
    const SceneDescription scene = files.parse({
        "<texture type=\"bitmap\" id=\"bumps\"><string name=\"filename\" value=\"bump.png\"/></texture>",
        "<bsdf type=\"bumpmap\" id=\"bumpy\"><ref id=\"bumps\"/>",
        "  <bsdf type=\"twosided\"><bsdf type=\"diffuse\"/></bsdf></bsdf>",
        "<bsdf type=\"twosided\" id=\"wrapped\"><ref id=\"bumpy\"/></bsdf>",
    });
    EXPECT_TRUE(scene.approximations.empty());
    const SceneDescription used = files.parse({
        "<texture type=\"bitmap\" id=\"bumps\"><string name=\"filename\" value=\"bump.png\"/></texture>",
        "<bsdf type=\"bumpmap\" id=\"bumpy\"><ref id=\"bumps\"/><bsdf type=\"diffuse\"/></bsdf>",
        "<shape type=\"cube\"><ref id=\"bumpy\"/></shape>",
        "<shape type=\"cube\"><bsdf type=\"twosided\"><ref id=\"bumpy\"/></bsdf></shape>",
    });
    EXPECT_EQ(used.approximations.size(), 1u);  // one line although two shapes use it
    EXPECT_TRUE(used.shapes[1].bsdf->twoSided);
    EXPECT_EQ(used.shapes[1].bsdf->approximations.size(), 1u);
}

// ---------------------------------------------------------------- serialized shapes

TEST(MitsubaParserShape, Serialized) {
    const SceneFiles files({"meshes/room.serialized"});
    const SceneDescription scene = files.parse({
        "<bsdf type=\"diffuse\" id=\"white\"/>",
        "<shape type=\"serialized\" id=\"room\">",
        "  <string name=\"filename\" value=\"meshes/room.serialized\"/>",
        "  <integer name=\"shapeIndex\" value=\"5\"/>",
        "  <boolean name=\"faceNormals\" value=\"true\"/><boolean name=\"flipNormals\" value=\"true\"/>",
        "  <transform name=\"toWorld\"><translate x=\"2\"/></transform>",
        "  <ref name=\"bsdf\" id=\"white\"/>",
        "</shape>",
        "<shape type=\"serialized\"><string name=\"filename\" value=\"meshes/room.serialized\"/></shape>",
    });
    ASSERT_EQ(scene.shapes.size(), 2u);
    const ShapeDescription& room = scene.shapes[0];
    EXPECT_EQ(room.kind, ShapeDescription::Kind::Serialized);
    EXPECT_EQ(room.filename, files / "meshes/room.serialized");
    EXPECT_EQ(room.shapeIndex, 5);
    EXPECT_TRUE(room.faceNormals);
    EXPECT_TRUE(room.flipNormals);
    expectNear(room.toWorld.applyPoint(Vec3(0.0f)), Vec3(2, 0, 0));
    EXPECT_EQ(room.bsdf->kind, BsdfDescription::Kind::Diffuse);
    EXPECT_EQ(room.where.line, 3);
    EXPECT_EQ(scene.shapes[1].shapeIndex, 0);  // Mitsuba's default
    EXPECT_FALSE(scene.shapes[1].faceNormals);
    EXPECT_TRUE(scene.ignored.empty());
}

TEST(MitsubaParserShape, SerializedMaxSmoothAngleIsReportedOnce) {
    const SceneFiles files({"m.serialized"});
    LogCapture log;
    const SceneDescription scene = files.parse({
        "<shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/>",
        "  <float name=\"maxSmoothAngle\" value=\"30\"/></shape>",
        "<shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/>",
        "  <integer name=\"shapeIndex\" value=\"1\"/><float name=\"maxSmoothAngle\" value=\"45\"/></shape>",
    });
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_TRUE(mentions(scene.ignored[0], {"shape 'serialized'", "maxSmoothAngle"}));
    const std::string text = log.text();
    const auto first = text.find("maxSmoothAngle");
    ASSERT_NE(first, std::string::npos);
    EXPECT_EQ(text.find("maxSmoothAngle", first + 1), std::string::npos) << text;  // logged once
    EXPECT_TRUE(mentions(text, {"warning", "test.xml:2"}));
}

// ---------------------------------------------------------------- integrators and "report once"

TEST(MitsubaParserIntegrator, EveryMitsubaIntegratorIsAcceptedAndRecorded) {
    for (const std::string type : {"ao", "bdpt", "photonmapper", "ppm", "sppm", "pssmlt", "mlt", "erpt", "ptracer",
                                   "vpl", "adaptive", "irrcache", "multichannel", "field"}) {
        const SceneDescription scene = parse({"<integrator type=\"" + type + "\"/>"});
        EXPECT_EQ(scene.integrator.type, type);
        ASSERT_EQ(scene.ignored.size(), 1u) << type;
        EXPECT_TRUE(mentions(scene.ignored[0], {"integrator '" + type + "'", "--method"}));
    }
    for (const std::string type : {"volpath", "volpath_simple", "path", "direct", "vrl", "vrlcuts"})
        EXPECT_TRUE(parse({"<integrator type=\"" + type + "\"/>"}).ignored.empty()) << type;
}

TEST(MitsubaParserIntegrator, ForeignIntegratorParametersAreListedAndMaxDepthRead) {
    LogCapture log;
    const SceneDescription scene = parse({
        "<default name=\"method\" value=\"sppm\"/>",
        "<default name=\"photonCount\" value=\"100000\"/>",
        "<integrator type=\"$method\">",
        "  <integer name=\"maxDepth\" value=\"6\"/>",
        "  <integer name=\"photonCount\" value=\"$photonCount\"/>",
        "  <integer name=\"maxPasses\" value=\"100\"/>",
        "  <float name=\"initialRadius\" value=\"0\"/>",
        "  <boolean name=\"dualBuffer\" value=\"false\"/>",
        "</integrator>",
    });
    EXPECT_EQ(scene.integrator.type, "sppm");
    EXPECT_EQ(scene.integrator.maxDepth, 6);
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_EQ(scene.ignored[0],
              "integrator 'sppm' (parameters photonCount, maxPasses, initialRadius, dualBuffer): rendering uses "
              "--method; only maxDepth is read");
    EXPECT_TRUE(mentions(log.text(), {"test.xml:4", "sppm", "photonCount"}));
    // -D method=... picks another one.
    ParseOptions options;
    options.defines = {{"method", "bdpt"}};
    EXPECT_EQ(
        parse({"<default name=\"method\" value=\"sppm\"/>", "<integrator type=\"$method\"/>"}, options).integrator.type,
        "bdpt");
}

TEST(MitsubaParserIntegrator, NestedIntegratorsOfMetaIntegrators) {
    const SceneDescription scene = parse({
        "<integrator type=\"adaptive\"><float name=\"maxError\" value=\"0.05\"/>",
        "  <integrator type=\"irrcache\"><integrator type=\"path\"><integer name=\"maxDepth\" value=\"3\"/>",
        "  </integrator></integrator>",
        "</integrator>",
    });
    EXPECT_EQ(scene.integrator.type, "adaptive");
    EXPECT_EQ(scene.integrator.maxDepth, 3);  // the wrapped integrator's
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_TRUE(mentions(scene.ignored[0],
                         {"integrator 'adaptive'", "maxError", "integrator 'irrcache'", "irrcache.integrator 'path'"}));
}

TEST(MitsubaParserIntegrator, OwnIntegratorsIgnoredParametersAreRecorded) {
    const SceneDescription scene = parse({"<integrator type=\"volpath\"><integer name=\"rrDepth\" value=\"5\"/>",
                                          "<integer name=\"version\" value=\"3\"/></integrator>"});
    ASSERT_EQ(scene.ignored.size(), 1u);
    EXPECT_EQ(scene.ignored[0], "integrator 'volpath' (parameters rrDepth, version): no effect in this renderer");
}

TEST(MitsubaParserReport, EachIgnoredKindIsOneLineLoggedOnce) {
    const SceneFiles files({"a.png", "b.png"});
    LogCapture log;
    const SceneDescription scene = files.parse({
        "<sensor type=\"perspective\"><float name=\"focusDistance\" value=\"3\"/>",
        "  <sampler type=\"sobol\"><integer name=\"sampleCount\" value=\"4\"/></sampler>",
        "  <film type=\"ldrfilm\"><float name=\"gamma\" value=\"2.2\"/><rfilter type=\"tent\"/></film>",
        "</sensor>",
        "<bsdf type=\"diffuse\" id=\"a\"><texture name=\"reflectance\" type=\"bitmap\">",
        "  <string name=\"filename\" value=\"a.png\"/><string name=\"filterType\" "
        "value=\"trilinear\"/></texture></bsdf>",
        "<bsdf type=\"diffuse\" id=\"b\"><texture name=\"reflectance\" type=\"bitmap\">",
        "  <string name=\"filename\" value=\"b.png\"/><string name=\"filterType\" value=\"nearest\"/></texture></bsdf>",
        "<bsdf type=\"diffuse\" id=\"c\"><texture name=\"reflectance\" type=\"bitmap\">",
        "  <string name=\"filename\" value=\"b.png\"/><float name=\"maxAnisotropy\" value=\"4\"/></texture></bsdf>",
    });
    const std::vector<std::string> expected = {
        "sampler 'sobol': camera samples are independent random numbers (sampleCount is used)",
        "film 'ldrfilm' (parameters gamma): the result is a linear-RGB high-dynamic-range image; output settings "
        "have no effect",
        "rfilter 'tent': reconstruction filter: pixels are box-filtered (each averages its own samples)",
        "sensor 'perspective' (parameters focusDistance): a pinhole camera with an instantaneous shutter: no "
        "depth of field or motion blur",
        "texture 'bitmap' (parameters filterType, maxAnisotropy): lookups are bilinear on the full-resolution "
        "image (no mip-map filtering)",
    };
    EXPECT_EQ(scene.ignored, expected);
    const std::string text = log.text();
    for (const std::string& line : expected) {
        const auto first = text.find(line);
        EXPECT_NE(first, std::string::npos) << line;
        EXPECT_EQ(text.find(line, first + 1), std::string::npos) << line;
    }
    const auto filterType = text.find("filterType");
    EXPECT_EQ(text.find("filterType", filterType + 1), std::string::npos) << text;
}

TEST(MitsubaParser, LookAtSpellingsAgreeAndTranslateDefaultsToZero) {
    const Transform lower = shapeTransform("<lookat origin=\"1, 2, 3\" target=\"0, 0, 0\" up=\"0, 1, 0\"/>");
    const Transform camel = shapeTransform("<lookAt origin=\"1 2 3\" target=\"0 0 0\" up=\"0 1 0\"/>");
    for (const Vec3& p : {Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})
        expectNear(lower.applyPoint(p), camel.applyPoint(p));
    expectNear(shapeTransform("<translate y=\"2\"/>").applyPoint(Vec3(1.0f)), Vec3(1, 3, 1));  // x, z are 0
}

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

// ---------------------------------------------------------------- files and includes

TEST(MitsubaParser, ParsesFileWithIncludes) {
    const std::filesystem::path file = fixtureDir() / "main.xml";
    const SceneDescription scene = parseMitsubaScene(file);
    EXPECT_EQ(scene.file, file);
    EXPECT_EQ(scene.version, "0.6.0");
    EXPECT_EQ(scene.integrator.maxDepth, 4);
    EXPECT_EQ(scene.sensor.sampleCount, 8);
    EXPECT_EQ(scene.sensor.width, 64);
    EXPECT_EQ(scene.sensor.medium, 0);
    ASSERT_EQ(scene.media.size(), 1u);
    EXPECT_EQ(scene.media[0].id, "fog");
    EXPECT_TRUE(mentions(scene.media[0].where.file, {"materials.xml"}));
    EXPECT_EQ(scene.media[0].where.line, 6);
    ASSERT_EQ(scene.shapes.size(), 2u);
    const ShapeDescription& mesh = scene.shapes[0];  // from include/mesh_shape.xml
    EXPECT_EQ(mesh.kind, ShapeDescription::Kind::Obj);
    EXPECT_EQ(mesh.filename, (fixtureDir() / "tiny.obj").lexically_normal());
    expectNear(mesh.bsdf->reflectance.value, Rgb(0.7f));
    expectNear(mesh.areaRadiance.value(), Rgb(8.0f));  // $spp from the including file
    EXPECT_EQ(mesh.where.line, 4);
    EXPECT_EQ(scene.shapes[1].exteriorMedium, 0);
    EXPECT_EQ(scene.shapes[1].where.line, 24);
}

TEST(MitsubaParser, IncludeFromStringResolvesAgainstBaseDirectory) {
    const SceneDescription scene =
        parse({"<include filename=\"include/materials.xml\"/>", "<shape type=\"cube\"><ref id=\"white\"/></shape>"});
    expectNear(scene.shapes.at(0).bsdf->reflectance.value, Rgb(0.7f));
}

TEST(MitsubaParser, ErrorInsideIncludedFileNamesThatFile) {
    try {
        parseMitsubaScene(fixtureDir() / "include_error.xml");
        FAIL() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"broken.xml:5:", "radius_typo", "radius"})) << e.what();
        EXPECT_EQ(e.where().line, 5);
    }
}

TEST(MitsubaParser, IncludeCycleIsAnError) {
    try {
        parseMitsubaScene(fixtureDir() / "cycle_a.xml");
        FAIL() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"cycle_b.xml:3:", "cycle", "cycle_a.xml"})) << e.what();
    }
}

TEST(MitsubaParser, MissingSceneFile) {
    try {
        parseMitsubaScene(fixtureDir() / "does_not_exist.xml");
        FAIL() << "expected a SceneError";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"does_not_exist.xml", "cannot find"})) << e.what();
    }
}

// ---------------------------------------------------------------- errors with a file, line and key word

TEST(MitsubaParserErrors, MalformedXmlReportsPugixmlMessageAndLine) {
    EXPECT_TRUE(mentions(errorOf("<scene version=\"0.5.0\">\n<shape type=\"cube\">\n</scene>\n"),
                         {"bad.xml:3:", "malformed XML", "mismatch"}));
}

TEST(MitsubaParserErrors, LineNumbersCountCrLfFiles) {
    EXPECT_TRUE(mentions(errorOf("<scene version=\"0.5.0\">\r\n\r\n<shape type=\"cone\"/>\r\n</scene>\r\n"),
                         {"bad.xml:3:", "cone", "sphere"}));
}

TEST(MitsubaParserErrors, LineNumbersWithByteOrderMark) {
    EXPECT_TRUE(mentions(errorOf("\xEF\xBB\xBF<scene version=\"0.5.0\">\n<shape type=\"cone\"/>\n</scene>\n"),
                         {"bad.xml:2:", "cone"}));
}

TEST(MitsubaParserErrors, UndefinedParameterIsNamed) {
    EXPECT_TRUE(mentions(
        errorOf(sceneXml({"<default name=\"spp\" value=\"4\"/>",
                          "<integrator type=\"path\"><integer name=\"maxDepth\" value=\"$depth\"/></integrator>"})),
        {"bad.xml:3:", "$depth"}));
}

TEST(MitsubaParserErrors, DefineWithoutDefaultIsNotNeededWhenUnused) {
    ParseOptions options;
    options.defines = {{"unused", "1"}};
    EXPECT_NO_THROW(parseMitsubaSceneString(sceneXml({}), fixtureDir(), options));
}

struct ErrorCase {
    std::string name;
    std::vector<std::string> lines;  // scene body; lines[i] is on line i + 2
    int line;                        // expected line of the error
    std::vector<std::string> words;  // must all appear in what()
};

void PrintTo(const ErrorCase& c, std::ostream* out) { *out << c.name; }

class MitsubaParserErrorCases : public ::testing::TestWithParam<ErrorCase> {};

TEST_P(MitsubaParserErrorCases, ReportFileLineAndName) {
    const ErrorCase& c = GetParam();
    std::string xml = "<scene version=\"0.5.0\">\n";
    for (const std::string& line : c.lines) xml += line + "\n";
    xml += "</scene>\n";
    try {
        parseMitsubaSceneString(xml, fixtureDir(), {}, "bad.xml");
        FAIL() << "expected a SceneError for:\n" << xml;
    } catch (const SceneError& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.where().line, c.line) << what;
        EXPECT_EQ(e.where().file, "bad.xml");
        EXPECT_NE(what.find("bad.xml:" + std::to_string(c.line) + ":"), std::string::npos) << what;
        for (const std::string& word : c.words) EXPECT_NE(what.find(word), std::string::npos) << word << " | " << what;
    }
}

const ErrorCase kErrorCases[] = {
    // Structure.
    {"UnknownElementInScene", {"<shap type=\"cube\"/>"}, 2, {"<shap>", "shape", "integrator"}},
    {"UnknownElementInPlugin",
     {"<sensor type=\"perspective\">", "<flaot name=\"fov\" value=\"3\"/>", "</sensor>"},
     3,
     {"<flaot>", "float", "film"}},
    {"UnknownElementInTransform",
     {"<shape type=\"cube\"><transform name=\"toWorld\">", "<translat x=\"1\"/>", "</transform></shape>"},
     3,
     {"translat", "translate"}},
    {"UnknownAttribute", {"<shape type=\"cube\" typo=\"1\"/>"}, 2, {"typo", "type"}},
    {"MissingRequiredAttributeName", {"<shape type=\"sphere\">", "<float value=\"1\"/>", "</shape>"}, 3, {"'name'"}},
    {"MissingRequiredAttributeType", {"<shape/>"}, 2, {"'type'"}},
    {"MissingRotateAngle",
     {"<shape type=\"cube\"><transform name=\"toWorld\">", "<rotate x=\"1\"/>", "</transform></shape>"},
     3,
     {"'angle'"}},
    {"MissingIncludeFilename", {"<include/>"}, 2, {"'filename'"}},
    {"TwoSensors", {"<sensor type=\"perspective\"/>", "<sensor type=\"perspective\"/>"}, 3, {"one <sensor>", "line 2"}},
    {"TwoIntegrators", {"<integrator type=\"path\"/>", "<integrator type=\"path\"/>"}, 3, {"one <integrator>"}},
    {"TextureWithoutFilename",
     {"<bsdf type=\"diffuse\" id=\"b\">", "<texture name=\"reflectance\" type=\"bitmap\"/>", "</bsdf>"},
     3,
     {"texture", "filename"}},
    // Unknown plugin types.
    {"UnknownIntegrator", {"<integrator type=\"magic\"/>"}, 2, {"magic", "volpath", "vrlcuts", "sppm"}},
    {"UnknownSensor", {"<sensor type=\"orthographic\"/>"}, 2, {"orthographic", "perspective"}},
    {"UnknownFilm", {"<sensor type=\"perspective\">", "<film type=\"mfilm\"/>", "</sensor>"}, 3, {"mfilm", "hdrfilm"}},
    {"UnknownSampler",
     {"<sensor type=\"perspective\">", "<sampler type=\"magic\"/>", "</sensor>"},
     3,
     {"magic", "independent"}},
    {"UnknownShape", {"<shape type=\"ply\"/>"}, 2, {"ply", "obj", "rectangle", "serialized"}},
    {"UnknownBsdf",
     {"<bsdf type=\"velvet\" id=\"cloth\"/>"},
     2,
     {"velvet", "diffuse", "dielectric", "roughconductor", "plastic", "ward", "twosided", "bumpmap", "null"}},
    {"UnknownEmitter", {"<emitter type=\"envmap\"/>"}, 2, {"envmap", "point", "spot"}},
    {"UnknownMedium", {"<medium type=\"heterogeneous\"/>"}, 2, {"heterogeneous", "homogeneous"}},
    {"UnknownPhase",
     {"<medium type=\"homogeneous\">", "<phase type=\"rayleigh\"/>", "</medium>"},
     3,
     {"rayleigh", "hg"}},
    {"TopLevelAreaEmitter", {"<emitter type=\"area\"/>"}, 2, {"attach area emitters to a shape"}},
    {"PointEmitterOnShape", {"<shape type=\"cube\">", "<emitter type=\"point\"/>", "</shape>"}, 3, {"point", "area"}},
    // Parameters.
    {"UnknownParameter",
     {"<sensor type=\"perspective\">", "<float name=\"fvo\" value=\"30\"/>", "</sensor>"},
     3,
     {"'fvo'", "fov", "nearClip"}},
    {"UnknownIntegratorParameter",
     {"<integrator type=\"volpath\">", "<integer name=\"samplesPerPass\" value=\"5\"/>", "</integrator>"},
     3,
     {"'samplesPerPass'", "maxDepth", "rrDepth"}},
    {"WrongTypedParameter",
     {"<sensor type=\"perspective\">", "<integer name=\"fov\" value=\"30\"/>", "</sensor>"},
     3,
     {"'fov'", "<float>", "<integer>"}},
    {"ParameterOfNullBsdf",
     {"<bsdf type=\"null\" id=\"n\">", "<rgb name=\"reflectance\" value=\"1\"/>", "</bsdf>"},
     3,
     {"'reflectance'", "no parameters"}},
    {"DuplicateParameter",
     {"<shape type=\"sphere\">", "<float name=\"radius\" value=\"1\"/>", "<float name=\"radius\" value=\"2\"/>",
      "</shape>"},
     4,
     {"'radius'", "twice", "line 3"}},
    {"UnsupportedFilmCrop",
     {"<sensor type=\"perspective\"><film type=\"hdrfilm\">", "<integer name=\"cropWidth\" value=\"3\"/>",
      "</film></sensor>"},
     3,
     {"cropWidth", "not supported yet"}},
    {"MediumPresetNotSupported",
     {"<medium type=\"homogeneous\">", "<string name=\"material\" value=\"Ketchup\"/>", "</medium>"},
     3,
     {"material", "not supported"}},
    // Numbers.
    {"UnparsableFloat",
     {"<shape type=\"sphere\">", "<float name=\"radius\" value=\"1.5x\"/>", "</shape>"},
     3,
     {"1.5x", "radius"}},
    {"UnparsableInteger",
     {"<integrator type=\"path\">", "<integer name=\"maxDepth\" value=\"4.5\"/>", "</integrator>"},
     3,
     {"4.5", "maxDepth"}},
    {"NotABoolean",
     {"<shape type=\"cube\">", "<boolean name=\"flipNormals\" value=\"yes\"/>", "</shape>"},
     3,
     {"yes", "true"}},
    {"NanFloat",
     {"<shape type=\"sphere\">", "<float name=\"radius\" value=\"nan\"/>", "</shape>"},
     3,
     {"finite", "nan"}},
    {"InfInRgb",
     {"<shape type=\"cube\"><emitter type=\"area\">", "<rgb name=\"radiance\" value=\"1, inf, 1\"/>",
      "</emitter></shape>"},
     3,
     {"finite", "inf"}},
    {"InfInMatrix",
     {"<shape type=\"cube\"><transform name=\"toWorld\">", "<matrix value=\"1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 inf\"/>",
      "</transform></shape>"},
     3,
     {"finite"}},
    {"HugeFloat",
     {"<shape type=\"sphere\">", "<float name=\"radius\" value=\"1e39\"/>", "</shape>"},
     3,
     {"out of range"}},
    {"RgbWithTwoValues",
     {"<shape type=\"cube\"><bsdf type=\"diffuse\">", "<rgb name=\"reflectance\" value=\"0.1, 0.2\"/>",
      "</bsdf></shape>"},
     3,
     {"one or three"}},
    {"MatrixWithFifteenNumbers",
     {"<shape type=\"cube\"><transform name=\"toWorld\">", "<matrix value=\"1 0 0 0 0 1 0 0 0 0 1 0 0 0 0\"/>",
      "</transform></shape>"},
     3,
     {"16 numbers", "15"}},
    {"ProjectiveMatrix",
     {"<shape type=\"cube\"><transform name=\"toWorld\">", "<matrix value=\"1 0 0 0 0 1 0 0 0 0 1 0 0 0 1 1\"/>",
      "</transform></shape>"},
     3,
     {"0 0 0 1", "affine"}},
    {"SingularTransform",
     {"<shape type=\"cube\">", "<transform name=\"toWorld\"><scale x=\"0\"/></transform>", "</shape>"},
     3,
     {"singular"}},
    {"DegenerateLookAt",
     {"<sensor type=\"perspective\"><transform name=\"toWorld\">",
      "<lookat origin=\"1, 1, 1\" target=\"1, 1, 1\" up=\"0, 1, 0\"/>", "</transform></sensor>"},
     3,
     {"origin and target"}},
    // Value ranges.
    {"NegativeSigmaS",
     {"<medium type=\"homogeneous\">", "<rgb name=\"sigmaS\" value=\"1, -1, 1\"/>",
      "<rgb name=\"sigmaA\" value=\"1\"/>", "</medium>"},
     3,
     {"sigmaS", "non-negative"}},
    {"NegativeSigmaT",
     {"<medium type=\"homogeneous\">", "<rgb name=\"albedo\" value=\"0.5\"/>", "<rgb name=\"sigmaT\" value=\"-2\"/>",
      "</medium>"},
     4,
     {"sigmaT", "non-negative"}},
    {"AlbedoAboveOne",
     {"<medium type=\"homogeneous\">", "<rgb name=\"sigmaT\" value=\"1\"/>",
      "<rgb name=\"albedo\" value=\"0.5, 1.2, 0.5\"/>", "</medium>"},
     4,
     {"albedo", "[0, 1]"}},
    {"MixedCoefficientPairs",
     {"<medium type=\"homogeneous\">", "<rgb name=\"sigmaS\" value=\"1\"/>", "<rgb name=\"sigmaT\" value=\"1\"/>",
      "</medium>"},
     2,
     {"sigmaS", "sigmaT"}},
    {"HalfACoefficientPair",
     {"<medium type=\"homogeneous\">", "<rgb name=\"sigmaS\" value=\"1\"/>", "</medium>"},
     2,
     {"'sigmaA' is missing"}},
    {"NegativeMediumScale",
     {"<medium type=\"homogeneous\">", "<float name=\"scale\" value=\"-1\"/>", "</medium>"},
     3,
     {"scale", "non-negative"}},
    {"NegativeReflectance",
     {"<bsdf type=\"diffuse\" id=\"d\">", "<rgb name=\"reflectance\" value=\"-0.1\"/>", "</bsdf>"},
     3,
     {"reflectance", "non-negative"}},
    {"NegativeIntensity",
     {"<emitter type=\"point\">", "<rgb name=\"intensity\" value=\"1, 1, -1\"/>", "</emitter>"},
     3,
     {"intensity", "non-negative"}},
    {"NegativeRadiance",
     {"<shape type=\"cube\"><emitter type=\"area\">", "<spectrum name=\"radiance\" value=\"-3\"/>",
      "</emitter></shape>"},
     3,
     {"radiance", "non-negative"}},
    {"FovZero",
     {"<sensor type=\"perspective\">", "<float name=\"fov\" value=\"0\"/>", "</sensor>"},
     3,
     {"fov", "(0, 180)"}},
    {"FovTooLarge", {"<sensor type=\"perspective\">", "<float name=\"fov\" value=\"180\"/>", "</sensor>"}, 3, {"fov"}},
    {"UnknownFovAxis",
     {"<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/>", "<string name=\"fovAxis\" value=\"z\"/>",
      "</sensor>"},
     3,
     {"fovAxis", "'z'", "diagonal"}},
    {"FovAndFocalLength",
     {"<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/>",
      "<string name=\"focalLength\" value=\"50mm\"/>", "</sensor>"},
     3,
     {"fov", "focalLength"}},
    {"NearClipNotBelowFarClip",
     {"<sensor type=\"perspective\"><float name=\"nearClip\" value=\"10\"/>", "<float name=\"farClip\" value=\"5\"/>",
      "</sensor>"},
     2,
     {"nearClip", "farClip"}},
    {"FilmWidthZero",
     {"<sensor type=\"perspective\"><film type=\"hdrfilm\">", "<integer name=\"width\" value=\"0\"/>",
      "</film></sensor>"},
     3,
     {"width", "16384"}},
    {"FilmHeightTooLarge",
     {"<sensor type=\"perspective\"><film type=\"hdrfilm\">", "<integer name=\"height\" value=\"16385\"/>",
      "</film></sensor>"},
     3,
     {"height", "16384"}},
    {"FilmTooManyPixels",
     {"<sensor type=\"perspective\">", "<film type=\"hdrfilm\">", "<integer name=\"width\" value=\"16384\"/>",
      "<integer name=\"height\" value=\"16384\"/>", "</film></sensor>"},
     3,
     {"16384 x 16384", "limit"}},
    {"SampleCountZero",
     {"<sensor type=\"perspective\"><sampler type=\"independent\">", "<integer name=\"sampleCount\" value=\"0\"/>",
      "</sampler></sensor>"},
     3,
     {"sampleCount"}},
    {"SampleCountTooLarge",
     {"<sensor type=\"perspective\"><sampler type=\"independent\">",
      "<integer name=\"sampleCount\" value=\"1048577\"/>", "</sampler></sensor>"},
     3,
     {"sampleCount", "1048576"}},
    {"MaxDepthZero",
     {"<integrator type=\"path\">", "<integer name=\"maxDepth\" value=\"0\"/>", "</integrator>"},
     3,
     {"maxDepth", "-1"}},
    {"RadiusZero",
     {"<shape type=\"sphere\">", "<float name=\"radius\" value=\"0\"/>", "</shape>"},
     3,
     {"radius", "positive"}},
    {"HgGOutOfRange",
     {"<medium type=\"homogeneous\"><phase type=\"hg\">", "<float name=\"g\" value=\"1\"/>", "</phase></medium>"},
     3,
     {"g", "(-1, 1)"}},
    {"SpotBeamWiderThanCutoff",
     {"<emitter type=\"spot\"><float name=\"cutoffAngle\" value=\"20\"/>", "<float name=\"beamWidth\" value=\"30\"/>",
      "</emitter>"},
     3,
     {"beamWidth", "cutoffAngle"}},
    {"PointPositionAndToWorld",
     {"<emitter type=\"point\"><transform name=\"toWorld\"/>", "<point name=\"position\" x=\"1\"/>", "</emitter>"},
     3,
     {"position", "toWorld"}},
    // Files, ids and references.
    {"MissingObjFile",
     {"<shape type=\"obj\">", "<string name=\"filename\" value=\"meshes/missing.obj\"/>", "</shape>"},
     3,
     {"missing.obj", "cannot find"}},
    {"ObjWithoutFilename", {"<shape type=\"obj\"/>"}, 2, {"filename"}},
    {"MissingIncludedFile", {"<include filename=\"nowhere.xml\"/>"}, 2, {"nowhere.xml"}},
    {"DuplicateId",
     {"<bsdf type=\"diffuse\" id=\"x\"/>", "<medium type=\"homogeneous\" id=\"x\"/>"},
     3,
     {"duplicate id 'x'", "bad.xml:2"}},
    {"UnknownRefId",
     {"<bsdf type=\"diffuse\" id=\"white\"/>", "<medium type=\"homogeneous\" id=\"fog\"/>", "<shape type=\"cube\">",
      "<ref id=\"whte\"/>", "</shape>"},
     5,
     {"'whte'", "white", "fog"}},
    {"RefUsedBeforeDeclaration",
     {"<shape type=\"cube\">", "<ref id=\"later\"/>", "</shape>", "<bsdf type=\"diffuse\" id=\"later\"/>"},
     3,
     {"'later'"}},
    {"RefToBsdfAsMedium",
     {"<bsdf type=\"diffuse\" id=\"b\"/>", "<shape type=\"cube\">", "<ref name=\"interior\" id=\"b\"/>", "</shape>"},
     4,
     {"'b'", "<bsdf>", "<medium>"}},
    {"RefToMediumWithoutName",
     {"<medium type=\"homogeneous\" id=\"m\"/>", "<shape type=\"cube\">", "<ref id=\"m\"/>", "</shape>"},
     4,
     {"interior", "exterior"}},
    {"RefToShape",
     {"<shape type=\"cube\" id=\"box\"/>", "<shape type=\"cube\">", "<ref id=\"box\"/>", "</shape>"},
     4,
     {"'box'", "<shape>"}},
    {"NestedMediumWithoutSide",
     {"<shape type=\"cube\">", "<medium type=\"homogeneous\"/>", "</shape>"},
     3,
     {"interior", "exterior"}},
    {"TwoBsdfsOnShape",
     {"<shape type=\"cube\">", "<bsdf type=\"diffuse\"/>", "<bsdf type=\"null\"/>", "</shape>"},
     4,
     {"only one bsdf"}},
    {"TwoSidedNull",
     {"<bsdf type=\"twosided\" id=\"t\">", "<bsdf type=\"null\"/>", "</bsdf>"},
     3,
     {"twosided", "null"}},
    {"TwoSidedEmpty", {"<bsdf type=\"twosided\" id=\"t\"/>"}, 2, {"twosided", "<bsdf>"}},
    {"TwoSidedDielectric",
     {"<bsdf type=\"twosided\" id=\"t\">", "<bsdf type=\"dielectric\"/>", "</bsdf>"},
     3,
     {"twosided", "dielectric", "transmission"}},
    // Bsdf parameters (files named in textures use tiny.obj: only existence is checked).
    {"UnsupportedMitsubaBsdf", {"<bsdf type=\"coating\" id=\"c\"/>"}, 2, {"coating", "not supported", "plastic"}},
    {"NegativeAlpha",
     {"<bsdf type=\"roughconductor\" id=\"m\">", "<float name=\"alpha\" value=\"-0.1\"/>", "</bsdf>"},
     3,
     {"<float name=\"alpha\">", "'alpha'", "roughconductor", "positive"}},
    {"ZeroAlphaU",
     {"<bsdf type=\"roughdielectric\" id=\"g\">", "<float name=\"alphaU\" value=\"0\"/>",
      "<float name=\"alphaV\" value=\"0.2\"/>", "</bsdf>"},
     3,
     {"'alphaU'", "positive"}},
    {"AlphaAndAlphaU",
     {"<bsdf type=\"roughconductor\" id=\"m\"><float name=\"alpha\" value=\"0.1\"/>",
      "<float name=\"alphaU\" value=\"0.2\"/>", "<float name=\"alphaV\" value=\"0.2\"/>", "</bsdf>"},
     3,
     {"alpha", "alphaU", "not both"}},
    {"AlphaUWithoutAlphaV",
     {"<bsdf type=\"roughconductor\" id=\"m\">", "<float name=\"alphaU\" value=\"0.2\"/>", "</bsdf>"},
     3,
     {"alphaU", "alphaV"}},
    {"AnisotropicRoughPlastic",
     {"<bsdf type=\"roughplastic\" id=\"p\"><float name=\"alphaU\" value=\"0.1\"/>",
      "<float name=\"alphaV\" value=\"0.3\"/>", "</bsdf>"},
     3,
     {"roughplastic", "isotropic"}},
    {"UnknownDistribution",
     {"<bsdf type=\"roughplastic\" id=\"p\">", "<string name=\"distribution\" value=\"blinn\"/>", "</bsdf>"},
     3,
     {"<string name=\"distribution\">", "'blinn'", "beckmann", "ggx", "phong"}},
    {"UnknownIorName",
     {"<bsdf type=\"dielectric\" id=\"g\">", "<string name=\"intIOR\" value=\"glass\"/>", "</bsdf>"},
     3,
     {"<string name=\"intIOR\">", "'glass'", "water", "bk7", "diamond"}},
    {"NegativeIor",
     {"<bsdf type=\"plastic\" id=\"p\">", "<float name=\"extIOR\" value=\"-1\"/>", "</bsdf>"},
     3,
     {"'extIOR'", "positive"}},
    {"RoughDielectricWithEqualIors",
     {"<bsdf type=\"roughdielectric\" id=\"g\"><float name=\"intIOR\" value=\"1.2\"/>",
      "<float name=\"extIOR\" value=\"1.2\"/></bsdf>"},
     2,
     {"intIOR", "extIOR", "differ"}},
    {"UnknownConductorMaterial",
     {"<bsdf type=\"conductor\" id=\"m\">", "<string name=\"material\" value=\"Unobtainium\"/>", "</bsdf>"},
     3,
     {"'Unobtainium'", "Cu", "Au", "Ag", "Al", "Cr", "none"}},
    {"NegativeConductorEta",
     {"<bsdf type=\"conductor\" id=\"m\">", "<rgb name=\"eta\" value=\"0.2, -1, 0.3\"/>", "</bsdf>"},
     3,
     {"'eta'", "non-negative"}},
    {"UnknownWardVariant",
     {"<bsdf type=\"ward\" id=\"w\">", "<string name=\"variant\" value=\"ashikhmin\"/>", "</bsdf>"},
     3,
     {"'ashikhmin'", "ward-duer", "balanced"}},
    {"NegativeSpecularReflectance",
     {"<bsdf type=\"plastic\" id=\"p\">", "<rgb name=\"specularReflectance\" value=\"-0.5\"/>", "</bsdf>"},
     3,
     {"specularReflectance", "non-negative"}},
    {"IorAsRgb",
     {"<bsdf type=\"dielectric\" id=\"g\">", "<rgb name=\"intIOR\" value=\"1.5\"/>", "</bsdf>"},
     3,
     {"'intIOR'", "<float>", "<string>"}},
    {"BumpMapWithoutTexture",
     {"<bsdf type=\"bumpmap\" id=\"b\">", "<bsdf type=\"diffuse\"/>", "</bsdf>"},
     2,
     {"bumpmap", "texture"}},
    {"BumpMapWithoutBsdf",
     {"<bsdf type=\"bumpmap\" id=\"b\"><texture type=\"bitmap\">",
      "<string name=\"filename\" value=\"tiny.obj\"/></texture></bsdf>"},
     2,
     {"bumpmap", "<bsdf>"}},
    // Textures.
    {"MissingTextureFile",
     {"<bsdf type=\"diffuse\" id=\"d\"><texture name=\"reflectance\" type=\"bitmap\">",
      "<string name=\"filename\" value=\"textures/missing.png\"/>", "</texture></bsdf>"},
     3,
     {"missing.png", "cannot find the texture file"}},
    {"UnknownTextureType",
     {"<bsdf type=\"diffuse\" id=\"d\">", "<texture name=\"reflectance\" type=\"checkerboard\"/>", "</bsdf>"},
     3,
     {"checkerboard", "bitmap", "scale"}},
    {"TextureForNonTextureParameter",
     {"<bsdf type=\"conductor\" id=\"m\">",
      "<texture name=\"eta\" type=\"bitmap\"><string name=\"filename\" value=\"tiny.obj\"/></texture>", "</bsdf>"},
     3,
     {"'eta'", "cannot be a texture", "specularReflectance"}},
    {"TexturedRoughness",
     {"<bsdf type=\"roughconductor\" id=\"m\">",
      "<texture name=\"alpha\" type=\"bitmap\"><string name=\"filename\" value=\"tiny.obj\"/></texture>", "</bsdf>"},
     3,
     {"'alpha'", "roughness", "<float>"}},
    {"TextureWithoutName",
     {"<bsdf type=\"diffuse\" id=\"d\">",
      "<texture type=\"bitmap\"><string name=\"filename\" value=\"tiny.obj\"/></texture>", "</bsdf>"},
     3,
     {"name=", "reflectance"}},
    {"TextureAndValueForOneParameter",
     {"<bsdf type=\"diffuse\" id=\"d\"><rgb name=\"reflectance\" value=\"0.5\"/>",
      "<texture name=\"reflectance\" type=\"bitmap\"><string name=\"filename\" value=\"tiny.obj\"/></texture>",
      "</bsdf>"},
     3,
     {"'reflectance'", "twice", "line 2"}},
    {"UnknownWrapMode",
     {"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"tiny.obj\"/>",
      "<string name=\"wrapModeU\" value=\"wrap\"/>", "</texture>"},
     3,
     {"'wrap'", "repeat", "mirror", "clamp", "zero", "one"}},
    {"TextureChannel",
     {"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"tiny.obj\"/>",
      "<string name=\"channel\" value=\"r\"/>", "</texture>"},
     3,
     {"channel", "'r'", "rgb"}},
    {"UnknownFilterType",
     {"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"tiny.obj\"/>",
      "<string name=\"filterType\" value=\"bicubic\"/>", "</texture>"},
     3,
     {"'bicubic'", "ewa", "trilinear", "nearest"}},
    {"NegativeTextureGamma",
     {"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"tiny.obj\"/>",
      "<float name=\"gamma\" value=\"-2\"/>", "</texture>"},
     3,
     {"gamma", "-1"}},
    {"ScaleTextureWithoutTexture",
     {"<texture type=\"scale\" id=\"s\">", "<float name=\"scale\" value=\"0.5\"/>", "</texture>"},
     2,
     {"scale", "<texture>"}},
    {"RefToTextureAsShapeBsdf",
     {"<texture type=\"bitmap\" id=\"t\"><string name=\"filename\" value=\"tiny.obj\"/></texture>",
      "<shape type=\"cube\">", "<ref id=\"t\"/>", "</shape>"},
     4,
     {"'t'", "<texture>", "<bsdf>"}},
    {"RefToBsdfAsTexture",
     {"<bsdf type=\"diffuse\" id=\"white\"/>", "<bsdf type=\"diffuse\" id=\"d\">",
      "<ref name=\"reflectance\" id=\"white\"/>", "</bsdf>"},
     4,
     {"'white'", "<bsdf>", "<texture>"}},
    // Serialized shapes.
    {"MissingSerializedFile",
     {"<shape type=\"serialized\">", "<string name=\"filename\" value=\"nowhere.serialized\"/>", "</shape>"},
     3,
     {"nowhere.serialized", "cannot find"}},
    {"NegativeShapeIndex",
     {"<shape type=\"serialized\"><string name=\"filename\" value=\"tiny.obj\"/>",
      "<integer name=\"shapeIndex\" value=\"-1\"/>", "</shape>"},
     3,
     {"shapeIndex", "-1"}},
    {"FaceNormalsAndMaxSmoothAngle",
     {"<shape type=\"serialized\"><string name=\"filename\" value=\"tiny.obj\"/>",
      "<boolean name=\"faceNormals\" value=\"true\"/>", "<float name=\"maxSmoothAngle\" value=\"30\"/>", "</shape>"},
     4,
     {"faceNormals", "maxSmoothAngle"}},
    // Integrators, films.
    {"ForeignIntegratorMaxDepthAsFloat",
     {"<integrator type=\"bdpt\">", "<float name=\"maxDepth\" value=\"5\"/>", "</integrator>"},
     3,
     {"maxDepth", "<integer>"}},
    {"ForeignIntegratorMaxDepthZero",
     {"<integrator type=\"sppm\">", "<integer name=\"maxDepth\" value=\"0\"/>", "</integrator>"},
     3,
     {"maxDepth", "-1"}},
    {"NestedIntegratorOfUnknownType",
     {"<integrator type=\"adaptive\">", "<integrator type=\"magic\"/>", "</integrator>"},
     3,
     {"magic", "path"}},
    {"IntegratorInsideOwnIntegrator",
     {"<integrator type=\"path\">", "<integrator type=\"direct\"/>", "</integrator>"},
     3,
     {"<integrator>", "path"}},
    {"UnknownRfilter",
     {"<sensor type=\"perspective\"><film type=\"hdrfilm\">", "<rfilter type=\"sinc\"/>", "</film></sensor>"},
     3,
     {"sinc", "box", "gaussian", "lanczos"}},
};

std::string errorCaseName(const ::testing::TestParamInfo<ErrorCase>& info) { return info.param.name; }

INSTANTIATE_TEST_SUITE_P(MitsubaParser, MitsubaParserErrorCases, ::testing::ValuesIn(kErrorCases), errorCaseName);

TEST(MitsubaParserErrors, RootIsNotScene) {
    EXPECT_TRUE(mentions(errorOf("<?xml version=\"1.0\"?>\n<scenery version=\"0.5.0\"/>\n"),
                         {"bad.xml:2:", "<scene>", "scenery"}));
}

TEST(MitsubaParserErrors, MissingOrForeignVersion) {
    EXPECT_TRUE(mentions(errorOf("<scene>\n</scene>\n"), {"bad.xml:1:", "'version'"}));
    EXPECT_TRUE(mentions(errorOf("<scene version=\"3.0.0\">\n</scene>\n"), {"bad.xml:1:", "3.0.0", "0.5/0.6"}));
}

TEST(MitsubaParserErrors, StrayDollarSign) {
    EXPECT_TRUE(mentions(errorOf(sceneXml({"<shape type=\"sphere\"><float name=\"radius\" value=\"$\"/></shape>"})),
                         {"bad.xml:2:", "'$'"}));
}

// Found by fuzzing: nested plugins recursed without limit (a stack overflow at
// about 10,000 levels). Nesting beyond kMaxXmlDepth is a SceneError with a line.
TEST(MitsubaParserHostile, DeeplyNestedElementsAreRefused) {
    std::string xml = "<scene version=\"0.6.0\">\n";
    for (int i = 0; i < 200; ++i) xml += "<bsdf type=\"twosided\">";
    for (int i = 0; i < 200; ++i) xml += "</bsdf>";
    xml += "\n</scene>\n";
    const std::string message = errorOf(xml);
    EXPECT_NE(message.find("nested deeper than"), std::string::npos) << message;
    EXPECT_NE(message.find("bad.xml:2"), std::string::npos) << message;
    // Nesting that real scenes use still parses.
    std::string fine = "<scene version=\"0.6.0\">\n";
    for (int i = 0; i < 8; ++i) fine += "<integrator type=\"adaptive\">";
    fine += "<integrator type=\"volpath\"/>";
    for (int i = 0; i < 8; ++i) fine += "</integrator>";
    fine += "\n</scene>\n";
    EXPECT_NO_THROW(parseMitsubaSceneString(fine, fixtureDir(), {}, "fine.xml"));
}

}  // namespace
}  // namespace vrl

