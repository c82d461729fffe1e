// CameraSegment: the part of a camera ray that lies in one medium, the dual
// "long" camera ray VRLs are shaded against (Vibert et al. 2019 §3-4). Points
// on it are origin + u direction, u in [0, length]; transmittanceBefore is the
// exact transmittance from the camera to `origin` (earlier media crossed).
#pragma once

#include "render/geometry.h"
#include "render/rgb.h"

#include <vector>

namespace vrl {

class Scene;

struct CameraSegment {
    Vec3 origin;
    Vec3 direction;  // unit
    float length = 0.0f;
    int medium = -1;
    Rgb transmittanceBefore{1.0f};
};

// Walks `ray` (starting in `medium`) through null boundaries to the first
// opaque surface or the ray's end, and returns its pieces inside media, in
// order. `transmittanceToEnd` receives the transmittance over the whole walk.
std::vector<CameraSegment> cameraSegments(const Scene& scene, const Ray& ray, int medium,
                                          Rgb* transmittanceToEnd = nullptr);

}  // namespace vrl
