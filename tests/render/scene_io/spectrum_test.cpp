// Tests of render/spectrum.h: the embedded CIE 1931 table (its sums and normalisation),
// Mitsuba's zero extension and E-white tint of flat spectra, the known RGB of the lajolla
// vol_cbox spectra, parser errors, and the <spectrum value="λ:v, ..."> hook in
// xml::parseColor (errors name file:line).
#include "render/scene_io/mitsuba/spectrum.h"
#include "render/scene_io/mitsuba/xml_values.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl {
namespace {

// Sums of the 1 nm CVRL ciexyz31_1 table over 360-830 nm.
constexpr double kSumX = 106.865469, kSumY = 106.856980, kSumZ = 106.892251;
// Its trapezoid integral of ȳ (the normalisation): the sum less half the end samples.
constexpr double kIntegralY = kSumY - 0.5 * (3.917e-6 + 4.5181e-7);

std::vector<SpectralSample> flat(float value, float from = 360.0f, float to = 830.0f) {
    return {{from, value}, {to, value}};
}

void expectRgbNear(const Rgb& actual, const Rgb& expected, float tolerance) {
    EXPECT_NEAR(actual.x, expected.x, tolerance) << "red";
    EXPECT_NEAR(actual.y, expected.y, tolerance) << "green";
    EXPECT_NEAR(actual.z, expected.z, tolerance) << "blue";
}

TEST(SpectrumTest, FlatSpectrumIsEqualEnergyWhite) {
    // A constant 1 integrates to the table sums (trapezoid) over ∫ȳ: Y = 1 exactly, X and Z
    // within 3e-4 of 1. Its sRGB is tinted (E white, not D65), as in Mitsuba.
    const Imath::V3f xyz = spectrumToXyz(flat(1.0f));
    EXPECT_NEAR(xyz.y, 1.0, 1e-6);
    EXPECT_NEAR(xyz.x, (kSumX - 0.5 * (1.299e-4 + 1.251141e-6)) / kIntegralY, 2e-6);
    EXPECT_NEAR(xyz.z, (kSumZ - 0.5 * 6.061e-4) / kIntegralY, 2e-6);
    expectRgbNear(spectrumToRgb(flat(1.0f)), Rgb(1.20489f, 0.94823f, 0.90927f), 2e-5f);
    // Linear in the values.
    expectRgbNear(spectrumToRgb(flat(0.25f)), spectrumToRgb(flat(1.0f)) * 0.25f, 1e-6f);
}

TEST(SpectrumTest, NarrowLineMeasuresTheColourMatchingFunctions) {
    // A unit-area triangle on 554-556 nm integrates the linearly interpolated table with
    // Simpson weights (1, 4, 1)/6; at 555 nm ȳ = 1, so Y = ~1 / ∫ȳ.
    const std::vector<SpectralSample> line{{554, 0}, {555, 1}, {556, 0}};
    const Imath::V3f xyz = spectrumToXyz(line);
    EXPECT_NEAR(xyz.y * kIntegralY, (0.9997482 + 4 * 1.0 + 0.9998567) / 6, 1e-6);
    EXPECT_NEAR(xyz.x * kIntegralY, (0.4959713 + 4 * 0.5120501 + 0.5282959) / 6, 1e-6);
    EXPECT_NEAR(xyz.z * kIntegralY, (0.006242800 + 4 * 0.005749999 + 0.005303600) / 6, 1e-7);
    // Outside 360-830 nm nothing is seen.
    EXPECT_EQ(spectrumToXyz(std::vector<SpectralSample>{{900, 0}, {901, 5}, {902, 0}}), Imath::V3f(0.0f));
}

TEST(SpectrumTest, EndsAreZeroExtendedByTheMeanSpacing) {
    // Mitsuba's zeroExtend: "500:1, 600:1" ramps to zero at 400 and 700 nm.
    const Imath::V3f extended = spectrumToXyz(std::vector<SpectralSample>{{500, 1}, {600, 1}});
    const Imath::V3f explicitRamp =
        spectrumToXyz(std::vector<SpectralSample>{{400, 0}, {500, 1}, {600, 1}, {700, 0}});
    EXPECT_NEAR(extended.x, explicitRamp.x, 1e-7);
    EXPECT_NEAR(extended.y, explicitRamp.y, 1e-7);
    EXPECT_NEAR(extended.z, explicitRamp.z, 1e-7);
    // Ends that are already zero get no ramp.
    const Imath::V3f zeroEnds = spectrumToXyz(std::vector<SpectralSample>{{500, 0}, {550, 1}, {600, 0}});
    const Imath::V3f padded =
        spectrumToXyz(std::vector<SpectralSample>{{300, 0}, {500, 0}, {550, 1}, {600, 0}, {800, 0}});
    EXPECT_NEAR(zeroEnds.y, padded.y, 1e-7);
    // The ramp matters: without it the box 500-600 nm alone has less luminance.
    EXPECT_GT(extended.y, spectrumToXyz(std::vector<SpectralSample>{{500, 0}, {500.001f, 1}, {600, 1}, {600.001f, 0}}).y);
}

// The <spectrum> values of a lajolla scene file, in document order.
std::vector<std::string> sampledSpectraIn(const std::filesystem::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string xml = text.str();
    std::vector<std::string> spectra;
    for (size_t at = xml.find("<spectrum"); at != std::string::npos; at = xml.find("<spectrum", at + 1)) {
        const size_t open = xml.find("value=\"", at) + 7, close = xml.find('"', open);
        const std::string value = xml.substr(open, close - open);
        if (value.find(':') != std::string::npos) spectra.push_back(value);
    }
    return spectra;
}

TEST(SpectrumTest, LajollaCornellBoxSpectra) {
    const auto file = std::filesystem::path(VRL_SHARED_SCENES_DIR) / "lajolla-volpath-test" / "vol_cbox.xml";
    if (!std::filesystem::exists(file)) GTEST_SKIP() << file << " is absent";
    const auto spectra = sampledSpectraIn(file);
    ASSERT_EQ(spectra.size(), 6u) << "white, white, red, green, 0.78 flat, light";
    // Computed once with this code and checked against a 940,000-step midpoint rule.
    struct Expected {
        const char* name;
        Rgb rgb;
    };
    const Expected expected[] = {{"white", {0.88589f, 0.69885f, 0.66674f}},
                                 {"white", {0.88589f, 0.69885f, 0.66674f}},
                                 {"red", {0.57014f, 0.04278f, 0.04442f}},
                                 {"green", {0.10491f, 0.37839f, 0.07625f}},
                                 {"flat 0.78", {0.93929f, 0.73972f, 0.70888f}},
                                 {"light", {207.7977f, 108.4758f, 27.7056f}}};
    for (size_t i = 0; i < spectra.size(); ++i) {
        SCOPED_TRACE(expected[i].name);
        const Rgb rgb = spectrumToRgb(parseWavelengthSpectrum(spectra[i]));
        expectRgbNear(rgb, expected[i].rgb, 2e-5f * std::max(1.0f, maxComponent(expected[i].rgb)));
    }
    // Sanity of the kind a reader would check by eye.
    const Rgb white = spectrumToRgb(parseWavelengthSpectrum(spectra[0]));
    EXPECT_GT(luminance(white), 0.70f);
    EXPECT_LT(luminance(white), 0.75f);
    EXPECT_LT(maxComponent(white) - minComponent(white), 0.25f);  // E-white tint only
    const Rgb red = spectrumToRgb(parseWavelengthSpectrum(spectra[2]));
    EXPECT_GT(red.x, 10 * red.y);
    EXPECT_GT(red.x, 10 * red.z);
    const Rgb green = spectrumToRgb(parseWavelengthSpectrum(spectra[3]));
    EXPECT_GT(green.y, 3 * green.x);
    EXPECT_GT(green.y, 3 * green.z);
}

void expectParseError(const std::string& text, const std::string& fragment) {
    try {
        parseWavelengthSpectrum(text);
        ADD_FAILURE() << "no error for '" << text << "'";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
}

TEST(SpectrumTest, ParserAcceptsCommasAndWhitespace) {
    const auto s = parseWavelengthSpectrum(" 400:0.5,404:1e-1\n408:0 ,  412:2 ");
    ASSERT_EQ(s.size(), 4u);
    EXPECT_EQ(s[1].wavelength, 404.0f);
    EXPECT_FLOAT_EQ(s[1].value, 0.1f);
    EXPECT_EQ(s[3].value, 2.0f);
}

TEST(SpectrumTest, ParserErrors) {
    expectParseError("", "at least two");
    expectParseError("400:0.5", "at least two");
    expectParseError("400:0.5, 400:0.6", "increase strictly");
    expectParseError("500:1, 400:1", "'400:1' follows '500:1'");
    expectParseError("abc:1, 500:2", "wavelength 'abc'");
    expectParseError("400:x, 500:2", "value 'x' of pair '400:x'");
    expectParseError("400:, 500:2", "value ''");
    expectParseError("400:-0.1, 500:1", "negative");
    expectParseError("400:nan, 500:1", "not finite");
    expectParseError("400:inf, 500:1", "not finite");
    expectParseError("-400:1, 500:1", "positive");
    expectParseError("0:1, 500:1", "positive");
    expectParseError("400:1e39, 500:1", "'1e39'");
    expectParseError("400:0.5:1, 500:1", "not a wavelength:value pair");
    expectParseError("400 : 0.5, 500:1", "'400' is not a wavelength:value pair");
    // The same checks guard the conversion itself.
    EXPECT_THROW(spectrumToRgb(std::vector<SpectralSample>{{500, 1}}), std::invalid_argument);
    EXPECT_THROW(spectrumToRgb(std::vector<SpectralSample>{{500, 1}, {450, 1}}), std::invalid_argument);
    EXPECT_THROW(spectrumToXyz(std::vector<SpectralSample>{{400, -1}, {500, 1}}), std::invalid_argument);
}

// parseColor on the first element of `body` inside a <scene> in file "test.xml".
Rgb colorOf(const std::string& body) {
    const xml::XmlFile file("<scene version=\"0.5.0\">\n" + body + "\n</scene>\n", "test.xml", ".");
    const xml::Defines defines;
    const xml::Element scene(file, file.root(), defines);
    return xml::parseColor(scene.children().at(0));
}

TEST(SpectrumTest, XmlSpectrumValuesAreConverted) {
    expectRgbNear(colorOf("<spectrum name=\"reflectance\" value=\"360:1, 830:1\"/>"), Rgb(1.20489f, 0.94823f, 0.90927f),
                  2e-5f);
    // A single number stays a grey (Mitsuba's uniform spectrum).
    EXPECT_EQ(colorOf("<spectrum name=\"reflectance\" value=\"0.5\"/>"), Rgb(0.5f));
}

void expectXmlError(const std::string& body, const std::string& fragment) {
    try {
        colorOf(body);
        ADD_FAILURE() << "no error for " << body;
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("test.xml:2"), std::string::npos) << message;
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    }
}

TEST(SpectrumTest, XmlSpectrumErrorsNameFileAndLine) {
    expectXmlError("<spectrum name=\"reflectance\" value=\"400:0.5, 400:0.7\"/>", "increase strictly");
    expectXmlError("<spectrum name=\"reflectance\" value=\"400:0.5\"/>", "at least two");
    expectXmlError("<spectrum name=\"reflectance\" value=\"400:0.5, 500:oops\"/>", "'oops'");
    expectXmlError("<spectrum name=\"radiance\" intent=\"illuminant\" value=\"400:1, 500:1\"/>", "intent");
}

}  // namespace
}  // namespace vrl
