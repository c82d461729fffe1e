// Tests for what one Mitsuba scene parse keeps in common
// (render/scene_io/mitsuba/mitsuba_parse_context.cpp, and the XML loading of
// xml_values.cpp): global ids, the report of what is accepted without effect
// (one line per plugin kind, logged once), and errors that name the file and
// line (malformed XML, line counting, undefined $names, the root element,
// hostile nesting). The table of rejected inputs: mitsuba_error_cases_test.cpp.
#include "tests/render/scene_io/mitsuba_test_support.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace vrl {
namespace {

// The message of the SceneError that parsing `file` throws; "" if none.
std::string errorOfFile(const std::filesystem::path& file) {
    try {
        parseMitsubaScene(file);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

using mitsuba_test::fixtureDir;
using mitsuba_test::sceneXml;
using mitsuba_test::parse;
using mitsuba_test::errorOf;
using mitsuba_test::mentions;
using mitsuba_test::expectNear;
using mitsuba_test::LogCapture;
using mitsuba_test::SceneFiles;

// ---------------------------------------------------------------- ids

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

// ---------------------------------------------------------------- "report once"

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

// -D defines: a name is used if the scene (with its includes) declares it with
// <default> or mentions $name anywhere, even in an attribute never read; any
// other -D is an error listing the names the scene does use.
TEST(MitsubaParserDefines, DefineUsedByADefaultOnly) {
    ParseOptions options;
    options.defines = {{"spp", "3"}};
    EXPECT_NO_THROW(parse({"<default name=\"spp\" value=\"4\"/>"}, options));
}

TEST(MitsubaParserDefines, DefineUsedByADollarNameOnly) {
    ParseOptions options;
    options.defines = {{"depth", "3"}};
    EXPECT_EQ(parse({"<integrator type=\"path\"><integer name=\"maxDepth\" value=\"$depth\"/></integrator>"}, options)
                  .integrator.maxDepth,
              3);
    // Mitsuba's longest-prefix rule: $res0 uses "res" when no "res0" is defined.
    options.defines = {{"res", "7"}};
    EXPECT_EQ(parse({"<integrator type=\"path\"><integer name=\"maxDepth\" value=\"$res0\"/></integrator>"}, options)
                  .integrator.maxDepth,
              70);
}

TEST(MitsubaParserDefines, DefineUsedInAnIncludedFile) {
    const SceneFiles files({"stand-in.txt"});
    {
        std::ofstream out(files / "part.xml");
        out << "<scene version=\"0.5.0\"><integrator type=\"path\"><integer name=\"maxDepth\" value=\"$depth\"/>"
               "</integrator><default name=\"fromInclude\" value=\"1\"/></scene>\n";
    }
    ParseOptions options;
    options.defines = {{"depth", "4"}, {"fromInclude", "2"}};
    EXPECT_EQ(files.parse({"<include filename=\"part.xml\"/>"}, options).integrator.maxDepth, 4);
}

TEST(MitsubaParserDefines, UnusedDefineIsAnErrorListingTheUsedNames) {
    ParseOptions options;
    options.defines = {{"sigmaS", "2"}};
    const std::string message = errorOf(sceneXml({"<default name=\"albedo\" value=\"0.5\"/>",
                                                  "<default name=\"sigmaT\" value=\"1\"/>",
                                                  "<medium type=\"homogeneous\" id=\"m\">",
                                                  "  <rgb name=\"sigmaT\" value=\"$sigmaT\"/>",
                                                  "  <rgb name=\"albedo\" value=\"$albedo\"/></medium>"}),
                                        options);
    EXPECT_TRUE(mentions(message, {"bad.xml: -D sigmaS=2: the scene uses no $sigmaS and has no <default "
                                   "name=\"sigmaS\">; names it uses: albedo, sigmaT"}))
        << message;
    options.defines = {{"unused", "1"}};
    EXPECT_TRUE(mentions(errorOf(sceneXml({}), options), {"-D unused=1", "it uses no $names"}));
}

// A scene or included file over kMaxSceneFileBytes is refused before it is
// read (the files here are sparse: no disk space is used).
TEST(MitsubaParserErrors, SceneFilesOverTheSizeCapAreRefusedUnread) {
    const SceneFiles files({"stand-in.txt"});
    std::ofstream(files / "huge.xml") << "<scene version=\"0.5.0\"/>\n";
    std::filesystem::resize_file(files / "huge.xml", kMaxSceneFileBytes + 1);
    const std::string size = std::to_string(kMaxSceneFileBytes + 1), cap = std::to_string(kMaxSceneFileBytes);
    try {
        parseMitsubaScene(files / "huge.xml");
        ADD_FAILURE() << "a scene file over the cap was read";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"scene file", "huge.xml", size + " bytes", "limit of " + cap})) << e.what();
    }
    try {
        files.parse({"<include filename=\"huge.xml\"/>"});
        ADD_FAILURE() << "an included file over the cap was read";
    } catch (const SceneError& e) {
        EXPECT_TRUE(mentions(e.what(), {"test.xml:2", "included file", "huge.xml", size + " bytes", "limit of " + cap}))
            << e.what();
    }
    // At the cap exactly, the file is read (and here fails as XML, not for its size).
    std::filesystem::resize_file(files / "huge.xml", kMaxSceneFileBytes);
    EXPECT_FALSE(mentions(errorOfFile(files / "huge.xml"), {"limit of"}));
}

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
