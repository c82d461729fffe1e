// Tests for the Mitsuba 0.5/0.6 XML parser: every supported element and value
// form loads with the right numbers, and every rejected input is a SceneError
// naming the file, the line and the offending name (plus a valid alternative).
#include "render/mitsuba_parser.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <memory>
#include <ostream>
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
    return scene.shapes.at(0).bsdf.value().reflectance;
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
    expectNear(scene.shapes[0].bsdf->reflectance, Rgb(0.25f, 0.5f, 0.25f));
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
    expectNear(scene.shapes[0].bsdf->reflectance, Rgb(0.8f, 0.1f, 0.1f));
    EXPECT_FALSE(scene.shapes[0].bsdf->twoSided);
    expectNear(scene.shapes[1].bsdf->reflectance, Rgb(0.3f));
    EXPECT_TRUE(scene.shapes[1].bsdf->twoSided);
    expectNear(scene.shapes[2].bsdf->reflectance, Rgb(0.8f, 0.1f, 0.1f));
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
    expectNear(scene.shapes[1].bsdf->reflectance, Rgb(0.2f));
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
    expectNear(mesh.bsdf->reflectance, Rgb(0.7f));
    expectNear(mesh.areaRadiance.value(), Rgb(8.0f));  // $spp from the including file
    EXPECT_EQ(mesh.where.line, 4);
    EXPECT_EQ(scene.shapes[1].exteriorMedium, 0);
    EXPECT_EQ(scene.shapes[1].where.line, 24);
}

TEST(MitsubaParser, IncludeFromStringResolvesAgainstBaseDirectory) {
    const SceneDescription scene =
        parse({"<include filename=\"include/materials.xml\"/>", "<shape type=\"cube\"><ref id=\"white\"/></shape>"});
    expectNear(scene.shapes.at(0).bsdf->reflectance, Rgb(0.7f));
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
    {"TextureNotSupported",
     {"<bsdf type=\"diffuse\" id=\"b\">", "<texture name=\"reflectance\" type=\"bitmap\"/>", "</bsdf>"},
     3,
     {"texture", "not supported yet"}},
    // Unknown plugin types.
    {"UnknownIntegrator", {"<integrator type=\"bdpt\"/>"}, 2, {"bdpt", "volpath", "vrlcuts"}},
    {"UnknownSensor", {"<sensor type=\"orthographic\"/>"}, 2, {"orthographic", "perspective"}},
    {"UnknownFilm", {"<sensor type=\"perspective\">", "<film type=\"mfilm\"/>", "</sensor>"}, 3, {"mfilm", "hdrfilm"}},
    {"UnknownSampler",
     {"<sensor type=\"perspective\">", "<sampler type=\"magic\"/>", "</sensor>"},
     3,
     {"magic", "independent"}},
    {"UnknownShape", {"<shape type=\"serialized\"/>"}, 2, {"serialized", "obj", "rectangle"}},
    {"UnknownBsdf", {"<bsdf type=\"dielectric\" id=\"glass\"/>"}, 2, {"dielectric", "diffuse", "twosided"}},
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
    {"WavelengthSpectrum",
     {"<shape type=\"cube\"><emitter type=\"area\">", "<spectrum name=\"radiance\" value=\"400:0, 500:80, 600:156\"/>",
      "</emitter></shape>"},
     3,
     {"wavelength", "not supported yet", "<rgb"}},
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

}  // namespace
}  // namespace vrl
