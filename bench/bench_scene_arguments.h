// A benchmark's -D defines and --resolution, read exactly as `vrl render` reads them
// (util/command_line.h: the same messages, the same film limits), so a bench refuses a
// bad value before it parses the scene or traces a light.
#pragma once

#include "render/description/scene_description.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "util/command_line.h"

#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl::bench {

struct SceneArguments {
    ParseOptions parseOptions;  // with the defines
    int width = 0, height = 0;
};

// The parsed arguments, or nullopt after printing the error to stderr (the caller exits 2).
inline std::optional<SceneArguments> parseSceneArguments(const std::vector<std::string>& defines,
                                                         const std::string& resolution) {
    SceneArguments arguments;
    try {
        arguments.parseOptions.defines = util::parseDefines(defines);
        std::tie(arguments.width, arguments.height) = util::parseResolution(resolution, kMaxFilmSide, kMaxFilmPixels);
    } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "%s\n", e.what());
        return std::nullopt;
    }
    return arguments;
}

}  // namespace vrl::bench
