// VolumetricPathTracer: the reference estimator. Unidirectional path tracing
// through homogeneous media (free-flight sampling with spectral MIS) and the
// surface models of bsdf.h, with next-event estimation at every medium vertex and
// every surface vertex with a non-Dirac lobe, and emission counted only where NEE
// cannot reach it (camera rays, rays that only crossed null boundaries, and rays
// leaving a sampled Dirac lobe). Unbiased for every light in the scene subset.
//
// Path length follows Mitsuba's maxDepth: a path of k scattering vertices has
// k+1 segments; 1 = directly visible emitters, 2 = + direct lighting and single
// scattering, -1 = unlimited (Russian roulette ends paths, unbiased).
#pragma once

#include "render/core/rng.h"
#include "render/scene/scene.h"

namespace vrl {

struct PathTracerSettings {
    int maxDepth = -1;
    int rouletteDepth = 5;  // scattering vertices before Russian roulette starts
    // Count only paths whose first two camera-side vertices lie in a medium
    // (the paths VRLs estimate); everything else is dropped.
    bool onlyMediumToMedium = false;
};

// Where a path starts, for estimators that hand part of a path to the tracer.
struct PathStart {
    int vertices = 0;  // scattering vertices already on the path (camera side)
    // Cross the first segment (up to the first non-null surface) with its exact
    // transmittance, sampling no medium collision on it.
    bool firstSegmentTransmittanceOnly = false;
    bool emissionOnFirstHit = true;  // count an emitter hit at the end of that segment
    // The first segment continues through purely specular bounces (glass, mirrors):
    // the camera path of the VRL decomposition (camera_segment.h).
    bool throughSpecular = false;
    // What may follow the surface vertex that ends the first segment (x1), when
    // it leaves by a non-Dirac lobe: the split of surface light between part (a)
    // and the VRL-lit part (c) (transport_parts.h).
    //   Any: everything (the reference path tracer).
    //   NotInMedium: the next segment is crossed with its exact transmittance,
    //     no medium vertex on it (part (a): (c) has the paths whose x2 is in a medium).
    //   InMedium: only paths whose next vertex x2 is a medium vertex count: no
    //     emission or NEE at x1, a Dirac lobe or a segment that reaches a surface
    //     unscattered ends the path (the reference for part (c) alone).
    enum class AfterFirstSurface { Any, NotInMedium, InMedium };
    AfterFirstSurface afterFirstSurface = AfterFirstSurface::Any;
};

class VolumetricPathTracer {
public:
    VolumetricPathTracer(const Scene& scene, PathTracerSettings settings) : scene_(scene), settings_(settings) {}

    // Radiance arriving at ray.origin from ray.direction; the ray starts in `medium`.
    Rgb radiance(Ray ray, int medium, Rng& rng, const PathStart& start = {}) const;

private:
    const Scene& scene_;
    PathTracerSettings settings_;
};

// Next-event estimation from `point` (offset from `surface` when given) in
// `medium`: picks an emitter by power, samples it, and returns the incident
// radiance times transmittance over the sampling pdf, with its direction.
struct DirectLighting {
    Vec3 direction;
    Rgb radianceOverPdf{0.0f};
};
DirectLighting sampleDirectLighting(const Scene& scene, const Vec3& point, const SurfaceHit* surface, int medium,
                                    Rng& rng);

}  // namespace vrl
