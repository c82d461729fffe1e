// SurfaceVpl: a virtual point light on a surface (Keller 1997's instant
// radiosity light, as VPL methods deposit it), here for one purpose only: the
// light that a camera segment's medium point x1 receives from a surface vertex
// x2 that reflects by a non-Dirac lobe (part (b)'s medium-then-surface paths,
// transport_parts.h). Light tracing (light_tracer.h) deposits one where a light
// path meets a surface that is not purely specular, before it samples the BSDF
// there: the vertex's hit record, the direction the path arrives in, the flux
// arriving (the throughput, already divided by the number of light paths; the
// BSDF is applied when the VPL is connected, surface_vpl_estimator.h) and the
// medium it arrives through. 84 bytes.
#pragma once

#include "render/core/geometry.h"
#include "render/core/rgb.h"

#include <cstdint>

namespace vrl {

struct SurfaceVpl {
    // The surface vertex (SurfaceHit's fields, without the ray distance).
    Vec3 position;
    Vec3 geometricNormal;  // unit, the shape's front side
    Vec3 shadingNormal;    // unit, on the same side
    Vec2 uv{0.0f, 0.0f};
    uint32_t shape = 0;
    uint32_t triangle = 0;
    float scale = 1.0f;  // offsets scale with it (SurfaceHit::scale)
    Vec3 direction;      // unit: the direction the light path travels in as it arrives
    Rgb flux{0.0f};      // W arriving, divided by the number of light paths
    int32_t medium = -1;  // the medium the path arrives through (-1: none)
};

}  // namespace vrl
