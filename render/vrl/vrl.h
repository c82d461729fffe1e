// render/vrl/: virtual ray lights: the VRL, the camera segments they are
// evaluated against, light tracing (which deposits them), and the one-VRL
// estimator of medium-to-medium transport.
//
// Vrl: a *short* virtual ray light (Novak et al. 2012; Vibert et al. 2019 §4):
// one segment of a light path inside a medium, from `origin` along unit
// `direction` for `length`, carrying the constant RGB flux of the path before
// the segment. Because the segment ends at a sampled (real or null) collision,
// or where the medium ends, its transmittance is replaced in expectation, so
// shading uses no T_r(v) term. 44 bytes per VRL.
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"
#include "render/vrl/surface_vpl.h"

#include <cstdint>
#include <vector>

namespace vrl {

struct Vrl {
    Vec3 origin;
    Vec3 direction;
    float length = 0.0f;
    Rgb flux{0.0f};      // W, already divided by the number of light paths
    int32_t medium = -1;  // index into Scene::media()

    Vec3 end() const { return origin + direction * length; }
};

struct VrlSet {
    std::vector<Vrl> vrls;
    // Surface VPLs of the same light paths (LightTracingSettings::surfaceVpls), flux
    // divided by surfaceVplPaths (the VRLs': by lightPaths); empty unless asked for.
    std::vector<SurfaceVpl> surfaceVpls;
    uint64_t lightPaths = 0;  // light paths traced (the flux normalisation)
    // The first light paths that deposited the surface VPLs (their flux normalisation):
    // all of them unless LightTracingSettings::surfaceVplLimit was reached.
    uint64_t surfaceVplPaths = 0;
    double tracingSeconds = 0.0;
    size_t memoryBytes() const { return vrls.capacity() * sizeof(Vrl) + surfaceVpls.capacity() * sizeof(SurfaceVpl); }
};

}  // namespace vrl
