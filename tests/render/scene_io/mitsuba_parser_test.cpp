// Tests for the Mitsuba 0.5/0.6 XML parser's scene structure
// (render/scene_io/mitsuba/mitsuba_parser.cpp): the scene element, integrators,
// sensor, film and sampler, <default> and -D substitution, shapes (serialized
// included), emitters, media, and files with includes. Values and transforms:
// xml_values_test.cpp; bsdfs and textures: mitsuba_bsdf_parser_test.cpp; ids,
// the report of ignored plugins and errors: mitsuba_parse_context_test.cpp and
// mitsuba_error_cases_test.cpp; the public scenes: mitsuba_shared_scenes_test.cpp.
#include "tests/render/scene_io/mitsuba_test_support.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>

namespace vrl {
namespace {

using mitsuba_test::fixtureDir;
using mitsuba_test::parse;
using mitsuba_test::mentions;
using mitsuba_test::expectNear;
using mitsuba_test::LogCapture;
using mitsuba_test::SceneFiles;

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
    for (const std::string type : {"volpath", "volpath_simple", "path", "direct", "vrl", "vrlcuts", "vrl-lightcuts",
                                   "vpl", "vpl-lightcuts"}) {
        const SceneDescription scene = parse({"<integrator type=\"" + type + "\"/>"});
        EXPECT_EQ(scene.integrator.type, type);
    }
}

// An integrator named after one of our methods (renderer.h) is accepted with
// its maxDepth, and neither ignored nor warned about: a job without a method renders it.
TEST(MitsubaParser, IntegratorNamingOurMethodKeepsItsDepthWithoutWarning) {
    for (const std::string type : {"path", "vrl", "vrl-lightcuts", "vpl", "vpl-lightcuts"}) {
        LogCapture log;
        const SceneDescription scene =
            parse({"<integrator type=\"" + type + "\"><integer name=\"maxDepth\" value=\"5\"/></integrator>"});
        EXPECT_EQ(scene.integrator.type, type);
        EXPECT_EQ(scene.integrator.maxDepth, 5) << type;
        EXPECT_TRUE(scene.ignored.empty()) << type;
        EXPECT_EQ(log.text().find("integrator"), std::string::npos) << type << ": " << log.text();
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

// hdrfilm's crop window (Mitsuba: offsets default to 0, the size to the film's);
// a window that is the whole film is no crop. Errors: mitsuba_error_cases_test.cpp.
TEST(MitsubaParser, FilmCropWindow) {
    const auto film = [](const std::string& crop) {
        return parse({"<sensor type=\"perspective\"><film type=\"hdrfilm\">",
                      "<integer name=\"width\" value=\"64\"/><integer name=\"height\" value=\"48\"/>", crop,
                      "</film></sensor>"})
            .sensor;
    };
    const SensorDescription all = film(
        "<integer name=\"cropOffsetX\" value=\"8\"/><integer name=\"cropOffsetY\" value=\"4\"/>"
        "<integer name=\"cropWidth\" value=\"16\"/><integer name=\"cropHeight\" value=\"12\"/>");
    EXPECT_EQ(all.width, 64);
    EXPECT_EQ(all.height, 48);
    ASSERT_TRUE(all.crop);
    EXPECT_EQ(*all.crop, (FilmCrop{8, 4, 16, 12}));
    EXPECT_EQ(all.crop->toString(), "8,4,16,12");
    const SensorDescription sizeOnly = film("<integer name=\"cropHeight\" value=\"10\"/>");
    ASSERT_TRUE(sizeOnly.crop);
    EXPECT_EQ(*sizeOnly.crop, (FilmCrop{0, 0, 64, 10}));
    EXPECT_EQ(film("<integer name=\"cropOffsetX\" value=\"60\"/><integer name=\"cropWidth\" value=\"4\"/>").crop,
              (FilmCrop{60, 0, 4, 48}));
    EXPECT_FALSE(film("<integer name=\"cropWidth\" value=\"64\"/>").crop);  // the whole film
    EXPECT_FALSE(film("").crop);
}

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

// ---------------------------------------------------------------- integrators

TEST(MitsubaParserIntegrator, EveryMitsubaIntegratorIsAcceptedAndRecorded) {
    for (const std::string type : {"ao", "bdpt", "photonmapper", "ppm", "sppm", "pssmlt", "mlt", "erpt", "ptracer",
                                   "adaptive", "irrcache", "multichannel", "field"}) {
        const SceneDescription scene = parse({"<integrator type=\"" + type + "\"/>"});
        EXPECT_EQ(scene.integrator.type, type);
        ASSERT_EQ(scene.ignored.size(), 1u) << type;
        EXPECT_TRUE(mentions(scene.ignored[0], {"integrator '" + type + "'", "--method"}));
    }
    for (const std::string type : {"volpath", "volpath_simple", "path", "direct", "vrl", "vrlcuts", "vrl-lightcuts",
                                   "vpl", "vpl-lightcuts"})
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

}  // namespace
}  // namespace vrl
