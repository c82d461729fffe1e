// Helpers shared by the Mitsuba XML parser tests (mitsuba_parser_test.cpp,
// mitsuba_bsdf_parser_test.cpp, xml_values_test.cpp, mitsuba_parse_context_test.cpp,
// mitsuba_error_cases_test.cpp, mitsuba_shared_scenes_test.cpp): scene XML
// builders, the expected-error helper, a log capture and a temporary folder of
// stand-in files. Scenes given as strings resolve relative file names against
// tests/scenes/parser (fixtureDir) unless SceneFiles parses them.
#pragma once

#include "render/scene_io/mitsuba/mitsuba_parser.h"

#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <initializer_list>
#include <memory>
#include <string>

namespace vrl::mitsuba_test {

inline constexpr float kTolerance = 1e-5f;

// tests/scenes/parser: the fixture files (tiny.obj, main.xml and its includes, ...).
std::filesystem::path fixtureDir();

// A scene whose first line is <scene version="0.5.0">, then `lines` (so lines[i] is on line i + 2).
std::string sceneXml(std::initializer_list<std::string> lines);

// sceneXml(lines) parsed as "test.xml" in fixtureDir().
SceneDescription parse(std::initializer_list<std::string> lines, const ParseOptions& options = {});

// The message of the SceneError that parsing `xml` (named bad.xml) throws; "" (and a failure) if none.
std::string errorOf(const std::string& xml, const ParseOptions& options = {});

// Success if every one of `words` occurs in `text`; otherwise names the first missing one.
::testing::AssertionResult mentions(const std::string& text, std::initializer_list<std::string> words);

// Component-wise within kTolerance (points, vectors and Rgb alike).
void expectNear(const Vec3& actual, const Vec3& expected);

// Routes spdlog's default logger into a buffer for the lifetime of the object.
class LogCapture {
public:
    LogCapture();
    ~LogCapture();
    LogCapture(const LogCapture&) = delete;
    LogCapture& operator=(const LogCapture&) = delete;
    std::string text() const;

private:
    std::shared_ptr<spdlog::sinks::ringbuffer_sink_mt> sink_;
    std::shared_ptr<spdlog::logger> previous_;
};

// A temporary directory holding stand-ins for the files a scene references
// (the parser only checks that they exist); scenes parsed from it resolve
// relative file names against it.
class SceneFiles {
public:
    explicit SceneFiles(std::initializer_list<std::string> files);
    ~SceneFiles();
    SceneFiles(const SceneFiles&) = delete;
    SceneFiles& operator=(const SceneFiles&) = delete;

    const std::filesystem::path& directory() const { return directory_; }
    std::filesystem::path operator/(const std::string& file) const { return (directory_ / file).lexically_normal(); }
    SceneDescription parse(std::initializer_list<std::string> lines, const ParseOptions& options = {}) const;

private:
    std::filesystem::path directory_;
};

}  // namespace vrl::mitsuba_test
