// Temporary folders for tests: unique per call (random suffix), so parallel
// ctest processes never share one.
#pragma once

#include "util/random_id.h"

#include <filesystem>
#include <string>
#include <system_error>

namespace vrl::test {

// A new, empty folder "<temp>/<stem>-<random>"; the caller removes it (or keeps it for a post-mortem).
inline std::filesystem::path freshDirectory(const std::string& stem) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / (stem + "-" + util::randomHex(12));
    std::filesystem::create_directories(dir);
    return dir;
}

// A fresh folder removed with everything in it when the object goes.
class TempDir {
public:
    explicit TempDir(const std::string& stem) : path_(freshDirectory(stem)) {}
    ~TempDir() {
        std::error_code ignored;
        std::filesystem::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return path_; }
    std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

private:
    std::filesystem::path path_;
};

}  // namespace vrl::test
