// Mitsuba 0.5/0.6 XML scene parser: reads a scene file into a validated
// SceneDescription (stage 1 of parse -> description -> render scene). Meshes
// are not loaded here; an OBJ file is only checked to exist.
//
// Supported subset (everything else is a SceneError that names the file, the
// 1-based line and the element, and where useful lists the valid names):
//   <scene version="0.x.y">, <default name value>, $name in any attribute,
//   <include filename>, id/<ref id> (global ids, refs only to bsdf/medium);
//   values float, integer, boolean, string, rgb ("r, g, b" | "v" | "#rrggbb"),
//   spectrum (one uniform value), point/vector, transform (translate, rotate,
//   scale, matrix, lookat; each applied after the previous ones);
//   integrator volpath | volpath_simple | path | direct | vrl | vrlcuts | vpl;
//   sensor perspective with film hdrfilm|ldrfilm and any Mitsuba sampler;
//   shapes obj, rectangle, cube, sphere, disk; bsdfs diffuse, null, twosided;
//   emitters area (on shapes), point, spot; medium homogeneous with phase
//   isotropic | hg.
// Parameters that Mitsuba accepts but that change nothing here (e.g. film
// pixelFormat, integrator rrDepth) are accepted with a spdlog warning.
//
// Mitsuba semantics worth knowing: a perspective sensor with neither fov nor
// focalLength gets Mitsuba's 50mm focal length (46.79 degrees along the
// diagonal); a medium with no coefficients gets sigmaS = sigmaA = 1 (Mitsuba's
// own default, the "Skin1" preset, is not supported); hg's g defaults to 0.8.
#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "render/scene_description.h"

namespace vrl {

struct ParseOptions {
    // -D name=value: defines $name, overriding the scene's <default name=...>.
    // A name with no <default> in the scene is still usable.
    std::map<std::string, std::string> defines;
    // If set, every file the scene references (includes, meshes) must lie
    // inside this directory once symbolic links are resolved; a reference
    // outside it is a SceneError. Job bundles are parsed this way, so a scene
    // cannot make the coordinator or a worker read anything else.
    std::optional<std::filesystem::path> confineTo;
    // If set, called with every file the parse reads or references (the scene
    // itself, includes, meshes), in order: a client collects a job's bundle so.
    std::function<void(const std::filesystem::path&)> onFileReferenced;
};

// Parses a Mitsuba 0.5/0.6 XML scene. Throws SceneError
// ("file:line: in <element>: problem") on any problem.
SceneDescription parseMitsubaScene(const std::filesystem::path& file, const ParseOptions& options = {});

// Same, from a string. Relative paths (include, obj filename) resolve against
// `baseDirectory`; `virtualFileName` is used in error messages.
SceneDescription parseMitsubaSceneString(const std::string& xml, const std::filesystem::path& baseDirectory,
                                         const ParseOptions& options = {},
                                         const std::string& virtualFileName = "<string>");

}  // namespace vrl
