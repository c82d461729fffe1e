// render/scene_io/: reading scenes from disk. mitsuba/ turns Mitsuba 0.5/0.6 XML
// into a SceneDescription (this header is its only public one); meshes/ loads OBJ,
// .serialized and analytic shapes; medium_fill.h adds smoke to a scene.
//
// Mitsuba 0.5/0.6 XML scene parser: reads a scene file into a validated
// SceneDescription (stage 1 of parse -> description -> render scene). Meshes
// and images are not loaded here; OBJ, serialized and bitmap files are only
// checked to exist.
//
// Supported subset (everything else is a SceneError that names the file, the
// 1-based line and the element, and where useful lists the valid names):
//   <scene version="0.x.y">, <default name value>, $name in any attribute
//   (a -D define the scene never uses is an error), files of at most
//   kMaxSceneFileBytes,
//   <include filename>, id/<ref id> (ids are global wherever they are nested;
//   refs name bsdfs, media and textures declared earlier);
//   values float, integer, boolean, string, rgb ("r, g, b" | "r g b" | "v" |
//   "#rrggbb"), spectrum, point/vector, transform (translate, rotate, scale,
//   matrix, lookat/lookAt; each applied after the previous ones);
//   integrators volpath | volpath_simple | path | direct | vrl | vrlcuts, and
//   every other Mitsuba 0.5/0.6 integrator (bdpt, sppm, ...) accepted with
//   only maxDepth read: the rendering method comes from --method;
//   sensor perspective with film hdrfilm | ldrfilm, any rfilter, any Mitsuba
//   sampler (all sample independently);
//   shapes obj, serialized (filename, shapeIndex), rectangle, cube, sphere, disk;
//   bsdfs diffuse, dielectric, roughdielectric, conductor, roughconductor,
//   plastic, roughplastic, ward, twosided, bumpmap (approximated: the bump
//   map is ignored), null, with Mitsuba's defaults and named IORs and
//   conductor presets (render/mitsuba_bsdf_parser.h, render/ior_table.h);
//   textures bitmap and scale, nested in a bsdf or top-level with an id;
//   emitters area (on shapes), point, spot; medium homogeneous with phase
//   isotropic | hg.
// What Mitsuba accepts but changes nothing here (rfilters, samplers' patterns,
// film output settings, other integrators' options, bitmap filtering, ...) is
// accepted, listed once per plugin kind in SceneDescription::ignored and
// logged once; approximations in use are in SceneDescription::approximations.
//
// Mitsuba semantics worth knowing: a perspective sensor with neither fov nor
// focalLength gets Mitsuba's 50mm focal length (46.79 degrees along the
// diagonal); a medium with no coefficients gets sigmaS = sigmaA = 1 (Mitsuba's
// own default, the "Skin1" preset, is not supported); hg's g defaults to 0.8;
// a <ref> to an id nested in a wrapper (e.g. a bsdf inside a bumpmap) gets
// that nested object, without the wrapper. SceneDescription::textures holds
// only textures some colour parameter uses, each distinct file + mapping once
// (a bump map's texture is checked but not stored).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "render/description/scene_description.h"

namespace vrl {

// Largest scene or included XML file the parser reads (checked before reading;
// real scenes are a few MiB at most, their geometry lives in mesh files).
inline constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t(64) << 20;

struct ParseOptions {
    // -D name=value: defines $name, overriding the scene's <default name=...>.
    // A name with no <default> in the scene is still usable, but a name the
    // scene (with its includes) neither declares with <default> nor mentions
    // as $name anywhere is a SceneError listing the names it does use: a
    // misspelled -D must not render the scene unchanged.
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
