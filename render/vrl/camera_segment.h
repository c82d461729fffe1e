// CameraSegment: the part of a camera path that lies in one medium, the dual
// "long" camera ray VRLs are shaded against (Vibert et al. 2019 §3-4). Points
// on it are origin + u direction, u in [0, length]. throughputBefore is the
// camera path's weight up to `origin`: the exact transmittance of the media
// crossed before, times the weights of the specular bounces (glass, mirrors)
// the camera path took on its way (Fresnel terms, coloured glass).
//
// The camera path is the camera ray continued through null boundaries and
// purely specular surfaces (Bsdf::isPurelySpecular), one Dirac lobe sampled at
// each, up to the first other surface. Its media segments are where the VRL
// decomposition's medium vertex x lies (transport_parts.h); a medium seen through
// glass or in a mirror is shaded by the same estimators.
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/scene/scene.h"

#include <optional>
#include <vector>

namespace vrl {

class Rng;

struct CameraSegment {
    Vec3 origin;
    Vec3 direction;  // unit
    float length = 0.0f;
    int medium = -1;
    Rgb throughputBefore{1.0f};
    int specularBefore = 0;  // specular bounces on the camera path before this segment
};

// Most specular bounces a camera path follows before it ends (dropping the rest).
inline constexpr int kMaxSpecularChain = 32;

// Where a camera path ends on a surface that is neither null nor (when the walk
// follows them) purely specular: the surface vertex x of part (c), VRL-lit
// surfaces (transport_parts.h).
struct CameraPathSurface {
    SurfaceHit hit;
    Vec3 wo;      // unit, from the surface back along the camera path
    int medium = -1;  // the medium the path arrives in (on wo's side)
    Rgb throughput{1.0f};  // transmittance and specular weights from the camera to the surface
    int specularBefore = 0;
    // x's BSDF prepared for wo (Bsdf::prepare): (c)'s estimator and bound evaluate it
    // against many directions. cameraPathSurface fills it.
    PreparedBsdf bsdf;
};

// A camera path's surface vertex with its BSDF prepared.
CameraPathSurface cameraPathSurface(const Scene& scene, const SurfaceHit& hit, const Vec3& wo, int medium,
                                    const Rgb& throughput, int specularBefore);

struct CameraPath {
    std::vector<CameraSegment> segments;
    std::optional<CameraPathSurface> surface;  // absent: the path escaped or was cut short
};

// Walks `ray` (starting in `medium`) through null boundaries and, when `rng` is
// given, through purely specular surfaces (sampling one lobe each, at most
// kMaxSpecularChain and stopping where maxDepth would), to the first other
// surface or the path's end, and returns its pieces inside media, in order.
// Without `rng` the walk stops at the first non-null surface.
std::vector<CameraSegment> cameraSegments(const Scene& scene, const Ray& ray, int medium, Rng* rng = nullptr,
                                          int maxDepth = -1);
// The same walk (the same random numbers), with the surface it ends on.
CameraPath cameraPath(const Scene& scene, const Ray& ray, int medium, Rng* rng = nullptr, int maxDepth = -1);

}  // namespace vrl
