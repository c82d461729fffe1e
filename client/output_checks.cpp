#include "client/output_checks.h"

#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "util/strings.h"

#include <unistd.h>

#include <stdexcept>

namespace vrl::client {

namespace fs = std::filesystem;

namespace {

// Two paths name the same file (existing files by identity, others by their normalised absolute form).
bool sameFile(const fs::path& a, const fs::path& b) {
    std::error_code error;
    if (fs::exists(a, error) && fs::exists(b, error)) return fs::equivalent(a, b, error);
    return fs::weakly_canonical(fs::absolute(a), error) == fs::weakly_canonical(fs::absolute(b), error);
}

void checkOne(const std::string& flag, const std::string& path, const std::string& extension) {
    auto fail = [&](const std::string& reason) {
        throw std::invalid_argument(flag + " '" + path + "': " + reason);
    };
    if (path.empty()) fail("the path is empty");
    const fs::path file(path);
    if (util::toLower(file.extension().string()) != extension)
        fail("the file name must end in " + extension + " (the format written)");
    std::error_code error;
    if (fs::is_directory(file, error)) fail("is a directory; give a file name ending in " + extension);
    const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
    if (!fs::exists(folder, error)) fail("the folder '" + folder.string() + "' does not exist");
    if (!fs::is_directory(folder, error)) fail("'" + folder.string() + "' is not a folder");
    if (access(folder.c_str(), W_OK | X_OK) != 0) fail("the folder '" + folder.string() + "' is not writable");
}

}  // namespace

void checkOutputsAreNotInputs(const std::string& output, const std::string& preview,
                              const std::vector<fs::path>& sceneInputs) {
    for (const auto& input : sceneInputs) {
        if (sameFile(output, input))
            throw std::invalid_argument("-o '" + output + "' is the scene's input file '" + input.string() +
                                        "'; writing the image there would destroy it");
        if (!preview.empty() && sameFile(preview, input))
            throw std::invalid_argument("--preview '" + preview + "' is the scene's input file '" + input.string() +
                                        "'; writing the preview there would destroy it");
    }
}

void checkOutputPaths(const std::string& output, const std::string& preview,
                      const std::vector<fs::path>& sceneInputs) {
    checkOutputsAreNotInputs(output, preview, sceneInputs);
    checkOne("-o", output, ".exr");
    if (!preview.empty()) {
        checkOne("--preview", preview, ".png");
        if (sameFile(output, preview)) throw std::invalid_argument("-o and --preview name the same file '" + output + "'");
    }
}

std::vector<fs::path> sceneInputFiles(const fs::path& scene, const std::map<std::string, std::string>& defines) {
    ParseOptions options;
    options.defines = defines;
    std::vector<fs::path> files;
    options.onFileReferenced = [&](const fs::path& file) { files.push_back(file); };
    (void)parseMitsubaScene(scene, options);
    return files;
}

}  // namespace vrl::client
