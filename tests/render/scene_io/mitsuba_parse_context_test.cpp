// Tests for what one Mitsuba scene parse keeps in common
// (render/scene_io/mitsuba/mitsuba_parse_context.cpp, and the XML loading of
// xml_values.cpp): global ids, the report of what is accepted without effect
// (one line per plugin kind, logged once), and errors that name the file and
// line (malformed XML, line counting, undefined $names, the root element,
// hostile nesting). The table of rejected inputs: mitsuba_error_cases_test.cpp.
#include "tests/render/scene_io/mitsuba_test_support.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace vrl {
namespace {

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

TEST(MitsubaParserErrors, DefineWithoutDefaultIsNotNeededWhenUnused) {
    ParseOptions options;
    options.defines = {{"unused", "1"}};
    EXPECT_NO_THROW(parseMitsubaSceneString(sceneXml({}), fixtureDir(), options));
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
