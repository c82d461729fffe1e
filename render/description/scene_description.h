// SceneDescription: the parsed, validated form of a Mitsuba 0.5/0.6 XML scene,
// before any geometry is loaded or acceleration structure built (stage 2 of
// parse -> description -> render scene). Plain data; every field has the
// Mitsuba default. Quantities are in the scene's units; angles in degrees as
// in the XML. Index fields refer into SceneDescription's vectors, -1 = none.
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/core/transform.h"
#include "render/description/film_crop.h"
#include "render/description/scene_error.h"

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vrl {

struct PhaseDescription {
    enum class Kind { Isotropic, HenyeyGreenstein };
    Kind kind = Kind::Isotropic;
    float g = 0.0f;  // HG mean cosine, in (-1, 1)
};

// medium type="homogeneous". sigmaS/sigmaA already multiplied by `scale`.
struct MediumDescription {
    std::string id;
    Rgb sigmaS{1.0f};
    Rgb sigmaA{1.0f};
    PhaseDescription phase;
    SourceLocation where;
};

// texture type="bitmap": an image file mapped with the shape's uv coordinates.
struct TextureDescription {
    std::filesystem::path filename;  // resolved, absolute or relative to the cwd
    float uscale = 1.0f, vscale = 1.0f, uoffset = 0.0f, voffset = 0.0f;
    enum class Wrap { Repeat, Mirror, Clamp, Zero, One };
    Wrap wrapU = Wrap::Repeat, wrapV = Wrap::Repeat;
    // Display gamma of the stored values; absent: Mitsuba's rule (sRGB for 8/16-bit
    // integer images, linear for float images). -1 means the sRGB curve.
    std::optional<float> gamma;
    SourceLocation where;
};

// A colour parameter: a constant, or a texture (index into SceneDescription::textures)
// scaled by `value` (1 unless the scene wraps the texture in a scale).
struct ColorDescription {
    Rgb value{0.5f};
    int texture = -1;
};

// Microfacet distribution of the rough models (Mitsuba's `distribution`).
enum class MicrofacetKind { Beckmann, GGX, Phong };

// A surface model of the scene subset (Mitsuba 0.5 plugins and defaults):
//   diffuse        reflectance
//   null           invisible boundary between two media
//   dielectric     smooth glass: intIOR/extIOR, specularReflectance/Transmittance
//   roughdielectric  + distribution, alphaU/alphaV
//   conductor      smooth metal: eta/k (complex IOR relative to extEta), specularReflectance
//   roughconductor + distribution, alphaU/alphaV
//   plastic        smooth dielectric coating over a diffuse base: intIOR/extIOR,
//                  diffuseReflectance, specularReflectance, nonlinear
//   roughplastic   + distribution, alpha (isotropic)
//   ward           Ward's anisotropic glossy model (variant), diffuseReflectance,
//                  specularReflectance, alphaU/alphaV
// twosided wraps any of them (the same model on both sides); bumpmap wraps one and
// is approximated by it (listed in `approximations`).
struct BsdfDescription {
    enum class Kind { Diffuse, Null, Dielectric, RoughDielectric, Conductor, RoughConductor, Plastic, RoughPlastic, Ward };
    Kind kind = Kind::Diffuse;
    ColorDescription reflectance{Rgb(0.5f)};            // diffuse; plastic and ward: diffuseReflectance
    ColorDescription specularReflectance{Rgb(1.0f)};    // dielectric, conductor, plastic; ward (default 0.2)
    ColorDescription specularTransmittance{Rgb(1.0f)};  // dielectric
    float intIOR = 1.5046f;    // dielectric/plastic interior index (Mitsuba: bk7; plastic: polypropylene 1.49)
    float extIOR = 1.000277f;  // exterior index (air)
    Rgb eta{0.200438f, 0.924033f, 1.10221f};  // conductor, relative to extEta (Mitsuba default: Cu)
    Rgb k{3.91295f, 2.45285f, 2.14219f};
    float extEta = 1.000277f;
    MicrofacetKind distribution = MicrofacetKind::Beckmann;
    float alphaU = 0.1f, alphaV = 0.1f;  // roughness; `alpha` sets both
    bool nonlinear = false;              // plastic: account for internal scattering (Mitsuba's flag)
    enum class WardVariant { Ward, WardDuer, Balanced };
    WardVariant wardVariant = WardVariant::Balanced;
    bool twoSided = false;
    // Human-readable notes on what this model approximates (e.g. "bumpmap: the bump
    // map is ignored"); the loader reports them once and writes them into the EXR.
    std::vector<std::string> approximations;
};

struct ShapeDescription {
    enum class Kind { Obj, Rectangle, Cube, Sphere, Disk, Serialized };
    Kind kind = Kind::Rectangle;
    std::filesystem::path filename;  // obj/serialized: resolved, absolute or relative to the cwd
    int shapeIndex = 0;              // serialized: which mesh of the file
    Transform toWorld;
    Vec3 center{0.0f};    // sphere
    float radius = 1.0f;  // sphere
    bool flipNormals = false;
    bool faceNormals = false;  // obj/serialized: ignore vertex normals
    bool flipTexCoords = true;  // obj: Mitsuba's default, OBJ's v = 0 is the image's bottom row
    // Absent: Mitsuba's default (diffuse 0.5, or null if the shape separates media).
    std::optional<BsdfDescription> bsdf;
    std::optional<Rgb> areaRadiance;  // emitter type="area" attached to the shape
    int interiorMedium = -1;
    int exteriorMedium = -1;
    SourceLocation where;
};

// emitter type="point" | "spot" (area emitters live on shapes).
struct EmitterDescription {
    enum class Kind { Point, Spot };
    Kind kind = Kind::Point;
    Rgb intensity{1.0f};   // W/sr
    Transform toWorld;     // spot: emits along local +z; point: origin = position
    float cutoffAngle = 20.0f;  // spot, degrees
    float beamWidth = 15.0f;    // spot, degrees (Mitsuba default: 3/4 of cutoffAngle)
    int medium = -1;            // medium the emitter sits in, if declared
    SourceLocation where;
};

struct SensorDescription {
    Transform toWorld;  // camera looks along local +z, +y up, +x left (Mitsuba)
    float fov = 45.0f;  // degrees, along fovAxis
    enum class FovAxis { X, Y, Diagonal, Smaller, Larger };
    FovAxis fovAxis = FovAxis::X;
    float nearClip = 1e-2f;
    float farClip = 1e4f;
    int width = 768;   // film
    int height = 576;  // film
    // The window of the film that is rendered (checkFilmCrop: inside the film,
    // never the whole film); absent: the whole film.
    std::optional<FilmCrop> crop;
    int sampleCount = 4;  // sampler
    int medium = -1;      // medium containing the camera
    SourceLocation where;
};

struct IntegratorDescription {
    std::string type = "volpath";  // Mitsuba plugin name as written
    // Mitsuba's meaning: 1 = directly visible emitters only, 2 = + direct
    // illumination and single scattering, -1 = unlimited.
    int maxDepth = -1;
    SourceLocation where;
};

// Documented limits on what a scene may ask for.
inline constexpr int kMaxFilmSide = 16384;
inline constexpr long long kMaxFilmPixels = 64LL * 1024 * 1024;
inline constexpr int kMaxSampleCount = 1 << 20;

struct SceneDescription {
    std::filesystem::path file;  // the top-level XML file
    std::string version;         // scene version attribute
    SensorDescription sensor;
    IntegratorDescription integrator;
    std::vector<MediumDescription> media;
    std::vector<ShapeDescription> shapes;
    std::vector<EmitterDescription> emitters;
    std::vector<TextureDescription> textures;
    // Plugins and parameters read but without effect here (filters, samplers'
    // patterns, unknown integrators' options), one line each, for the log and metadata.
    std::vector<std::string> ignored;
    // Approximations in use (bump maps ignored, ...), one line each; also in EXR metadata.
    std::vector<std::string> approximations;
};

// The scene's approximations and ignored plugins as EXR metadata entries
// ("vrl.approximations", "vrl.ignored": lines joined by "; "; absent when none),
// so an image says what it does not model.
inline std::map<std::string, std::string> sceneNotes(const SceneDescription& scene) {
    const auto join = [](const std::vector<std::string>& lines) {
        std::string out;
        for (const auto& line : lines) out += (out.empty() ? "" : "; ") + line;
        return out;
    };
    std::map<std::string, std::string> notes;
    if (!scene.approximations.empty()) notes["vrl.approximations"] = join(scene.approximations);
    if (!scene.ignored.empty()) notes["vrl.ignored"] = join(scene.ignored);
    return notes;
}

}  // namespace vrl
