// SceneDescription: the parsed, validated form of a Mitsuba 0.5/0.6 XML scene,
// before any geometry is loaded or acceleration structure built (stage 2 of
// parse -> description -> render scene). Plain data; every field has the
// Mitsuba default. Quantities are in the scene's units; angles in degrees as
// in the XML. Index fields refer into SceneDescription's vectors, -1 = none.
#pragma once

#include "render/geometry.h"
#include "render/rgb.h"
#include "render/scene_error.h"
#include "render/transform.h"

#include <filesystem>
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

// bsdf type="diffuse" | "null", optionally wrapped in "twosided".
struct BsdfDescription {
    enum class Kind { Diffuse, Null };
    Kind kind = Kind::Diffuse;
    Rgb reflectance{0.5f};
    bool twoSided = false;
};

struct ShapeDescription {
    enum class Kind { Obj, Rectangle, Cube, Sphere, Disk };
    Kind kind = Kind::Rectangle;
    std::filesystem::path filename;  // obj: resolved, absolute or relative to the cwd
    Transform toWorld;
    Vec3 center{0.0f};    // sphere
    float radius = 1.0f;  // sphere
    bool flipNormals = false;
    bool faceNormals = false;  // obj: ignore vertex normals
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
};

}  // namespace vrl
