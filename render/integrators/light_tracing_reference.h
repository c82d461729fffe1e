// Light tracing connected to the camera, with the path tracer for the paths it
// cannot connect: an estimator of the whole image for scenes whose light
// arrives through specular surfaces (a caustic through a glass sphere), where
// unidirectional path tracing finds the light only by BSDF or phase sampling and
// its images are fireflies (the volumetric caustic's 16,384-spp path-traced
// reference: 276% relative noise). Used to build the report's references.
//
// Partition of path space by the first camera-side vertex x1 (the first real
// scattering event or non-null surface along the camera ray):
//   1. x1 scatters by a non-Dirac event (a medium collision, or a surface's
//      non-Dirac lobes): light tracing. Every light path (LightPathWalker, the
//      VRLs' own light tracer) is connected at each vertex v where it scatters,
//      medium or non-purely-specular surface, to the pinhole: v becomes x1 of a
//      camera path of depth(v) + 1 segments. The estimate of pixel j is
//          (1 / M) sum_paths sum_v  w_v f(v) T_r(v, c) V(v, c) We_j(v) / |v - c|^2
//      with M light paths, w_v the vertex weight (LightPathVertex: in a medium the
//      collision estimator's sigma_s / density, so sum_v w_v g(v) estimates the
//      volume integral of sigma_s times the incident light), f(v) the phase
//      function or the adjoint BSDF with its |cos| towards the camera (both are
//      the radiant intensity per unit weight towards the pinhole), T_r and V the
//      transmittance and visibility through null boundaries to the start of the
//      camera ray, and We_j = 1 / (A cos^3 theta) in pixel j, 0 elsewhere
//      (PerspectiveCamera::project: the box filter over the pixel's area A at
//      unit distance). Unbiased: it is the measurement integral of those paths
//      written over the volume and surface measure at x1 (dw = dA cos / d^2,
//      dV = d^2 dt dw), sampled by the light tracer's density.
//   2. x1 is an emitter seen directly, or x1 leaves by a Dirac lobe (the camera
//      sees glass or a mirror): the path tracer, with the first segment crossed by
//      its exact transmittance (no collision: those paths are part 1's) and only
//      Dirac samples at x1 (PathStart::diracAtFirstSurfaceOnly). From x2 on it is
//      the full path tracer.
// The two parts are disjoint and cover every path, so their sum is the image
// the path tracer estimates with jittered rays: both parts average over each
// pixel's area. Except where the path tracer cannot sample a path at all: light
// from a point or spot light that reaches a scattering vertex only through Dirac
// surfaces (its caustics through glass) has zero density for it and is found
// here. Light tracing's noise is spread over the image evenly and does not depend
// on how small the light is; part 2 keeps the path tracer's noise only where the
// camera sees specular surfaces.
//
// For comparison with renders through pixel centres (RenderSettings::jitter =
// false, the report's runs), an average over the pixel differs where the image
// changes within a pixel: a 5 x 4 mm light covering 1% of a pixel whose centre
// misses it reads 0 at the centre and 5,240 averaged over the volumetric
// caustic's pixel, and the glow around it falls off within a pixel (part 1 over
// whole pixels against their centres there: RMSE 0.19 of luminance, mean 0.47).
// pixelCentres traces part 2's rays through pixel centres, and
// pixelFootprint f < 1 counts part 1's connections only in the centred square of
// f x f of each pixel, with importance 1 / (f^2 A cos^3 theta) (the same
// measurement over the smaller area): its difference from the centre value
// shrinks as f (at an edge) or f^2 (where the image is smooth), its variance
// grows as 1 / f^2.
//
// Variance near the lens: a connection from a medium vertex at distance d from the
// pinhole carries 1 / d^2, so with the camera in a medium the variance grows as
// 1 / nearClip (the fog within r of the pinhole adds ~ r to a pixel's value but
// ~ 1 / nearClip - 1 / r to its variance). A render then typically misses the
// rare, large connections from the fog just in front of the lens and comes out low
// by about that fog's in-scatter, which the spread of a few renders does not show
// (light_tracing_reference_test.cpp: 9% in a dim block of a test room with
// nearClip 1e-4). The volumetric caustic's camera is 6 units in front of its lit
// box, where that fog is dim.
//
// Deterministic: light path i draws from (seed, i) and its connections are
// summed in a fixed order of chunks; camera sample s of pixel p from
// (seed', p, s). The image is bit-identical whatever the thread count.
#pragma once

#include "render/image/image.h"
#include "render/scene/scene.h"

#include <cstdint>

namespace vrl {

struct LightTracingReferenceSettings {
    uint64_t lightPaths = 0;   // part 1: light paths traced (0: part 1 left out)
    int samplesPerPixel = 0;   // part 2: jittered camera samples per pixel (0: part 2 left out)
    uint64_t seed = 0;
    int maxDepth = -1;  // Mitsuba's meaning (path_tracer.h), for both parts
    bool pixelCentres = false;  // part 2's rays through pixel centres (see above); else jittered
    float pixelFootprint = 1.0f;  // part 1: the centred fraction of each pixel's width it averages over, (0, 1];
                                  // below 1 only with pixelCentres
};

// The image (the crop window when the camera has one). Throws
// std::invalid_argument when both parts are left out, spp is negative, maxDepth is
// below -1, the footprint is outside (0, 1], or below 1 while part 2 is jittered
// (the two parts would measure different things). A connection whose value is not
// finite (none in a sound scene) is left out and counted in a warning on stderr.
Image renderLightTracingReference(const Scene& scene, const LightTracingReferenceSettings& settings);

}  // namespace vrl
