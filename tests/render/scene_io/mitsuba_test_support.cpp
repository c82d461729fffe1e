#include "tests/render/scene_io/mitsuba_test_support.h"

#include <stdlib.h>  // mkdtemp

#include <fstream>
#include <stdexcept>
#include <system_error>

namespace vrl::mitsuba_test {

std::filesystem::path fixtureDir() { return std::filesystem::path(VRL_TEST_DATA_DIR) / "scenes/parser"; }

std::string sceneXml(std::initializer_list<std::string> lines) {
    std::string xml = "<scene version=\"0.5.0\">\n";
    for (const std::string& line : lines) xml += line + "\n";
    return xml + "</scene>\n";
}

SceneDescription parse(std::initializer_list<std::string> lines, const ParseOptions& options) {
    return parseMitsubaSceneString(sceneXml(lines), fixtureDir(), options, "test.xml");
}

std::string errorOf(const std::string& xml, const ParseOptions& options) {
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

LogCapture::LogCapture()
    : sink_(std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(128)), previous_(spdlog::default_logger()) {
    spdlog::set_default_logger(std::make_shared<spdlog::logger>("parser-test-capture", sink_));
}

LogCapture::~LogCapture() { spdlog::set_default_logger(previous_); }

std::string LogCapture::text() const {
    std::string out;
    for (const std::string& line : sink_->last_formatted()) out += line;
    return out;
}

SceneFiles::SceneFiles(std::initializer_list<std::string> files) {
    std::string pattern = (std::filesystem::temp_directory_path() / "vrl-parser-test-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    directory_ = pattern;
    for (const std::string& file : files) {
        std::filesystem::create_directories((directory_ / file).parent_path());
        std::ofstream(directory_ / file) << "stand-in\n";
    }
}

SceneFiles::~SceneFiles() {
    std::error_code error;
    std::filesystem::remove_all(directory_, error);
}

SceneDescription SceneFiles::parse(std::initializer_list<std::string> lines, const ParseOptions& options) const {
    return parseMitsubaSceneString(sceneXml(lines), directory_, options, "test.xml");
}

}  // namespace vrl::mitsuba_test
