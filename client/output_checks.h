// Output checks: what `vrl render` and `vrl submit` verify about -o and
// --preview before any work is spent, so that a render never runs to 100% and
// then fails to write, and never overwrites one of its own inputs.
//
// Contract: checkOutputPaths throws std::invalid_argument (the CLI's exit 2)
// naming the path and the reason when
//   - the output is empty or an existing directory;
//   - the extension is not the format's (".exr" for -o, ".png" for --preview,
//     case-insensitive);
//   - the folder that will hold the file does not exist, is not a directory or
//     is not writable by this process (the file is written to a temporary
//     sibling and renamed, so the folder, not the file, must be writable);
//   - the output is one of `sceneInputs` (the scene and every file it
//     references), or -o and --preview name the same file.
// It reads nothing but file-system metadata, so it answers at once.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace vrl::client {

void checkOutputPaths(const std::string& output, const std::string& preview,
                      const std::vector<std::filesystem::path>& sceneInputs);
// The last rule alone, for the files a parse of the scene found once the paths
// themselves were checked: neither output is one of `sceneInputs`.
void checkOutputsAreNotInputs(const std::string& output, const std::string& preview,
                              const std::vector<std::filesystem::path>& sceneInputs);

// The scene file and every file it references (includes, meshes, textures),
// by parsing it with `defines` (cheap: meshes are not loaded). Throws SceneError.
std::vector<std::filesystem::path> sceneInputFiles(const std::filesystem::path& scene,
                                                   const std::map<std::string, std::string>& defines);

}  // namespace vrl::client
