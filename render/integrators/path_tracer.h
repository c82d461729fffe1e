// VolumetricPathTracer: the reference estimator. Unidirectional path tracing
// through homogeneous media (free-flight sampling with spectral MIS:
// homogeneous_medium.h) and the surface models of bsdf.h, with next-event
// estimation at every medium vertex and every surface vertex with a non-Dirac
// lobe. Emission counts with weight 1 where NEE cannot reach it (camera rays,
// rays that only crossed null boundaries, rays leaving a sampled Dirac lobe). At
// a medium vertex, and at a surface vertex with a non-Dirac lobe, an area light is
// found by both strategies: NEE (density p_light = emitter choice x sampleDirect's
// solid-angle pdf) and the phase- or BSDF-sampled ray that reaches the light
// without a medium collision (density p_dir = the phase function, or Bsdf::pdf of
// the non-Dirac lobes as sample() draws them); each counts with the power
// heuristic p^2 / (p_light^2 + p_dir^2), so the weights of a path sum to 1 (Veach
// 1997 §9.2; pbrt-v4 VolPathIntegrator). The directional strategy's density in
// the weights includes the chance that its ray crosses the media to the light
// unscattered (the average over channels of the transmittance, as free-flight
// sampling passes; 1 where the segment is crossed by transmittance alone), so
// that where the segment to the light has optical depth ~1 its coin-flip
// pass-through weighs less. NEE alone from a medium vertex carries 1 / d^2 next to
// an emitting surface, whose variance is unbounded (in PathTracerFurnace's chromatic
// case its standard errors ran up to 10x those with MIS, and missed the answer for
// some seeds); the phase strategy caps it (its density is bounded). On
// glossy surfaces MIS is far quieter than NEE alone (0.01-0.5x). In the glossy test room with thick
// media it is not clearly better: both estimators are heavy-tailed there, and NEE
// alone measured 0.6k and 510k of per-path variance at 2048 and 4096 paths per
// pixel, MIS 1.7k and 1.6k. Point and spot lights (Dirac) keep NEE alone, weight
// 1. PathTracerSettings::lightMis = false is NEE alone everywhere. Unbiased for
// every light in the scene subset.
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
    // Multiple importance sampling of NEE and BSDF (or phase) sampling at surface and
    // medium vertices; false is the NEE-only estimator (same expectation, more variance
    // on glossy surfaces and next to emitting surfaces), kept to compare the two.
    bool lightMis = true;
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
    // Only paths that leave x1 by a Dirac lobe (glass, mirrors, a plastic's coating)
    // count from x1 on: no NEE at x1, a non-Dirac sample there ends the path. With
    // firstSegmentTransmittanceOnly and emissionOnFirstHit, the complement of light
    // tracing connected to the camera (light_tracing_reference.h).
    bool diracAtFirstSurfaceOnly = false;
    // Part (a) with surface VPLs (transport_integrator.h): R > 0 hands the light that
    // x2 reflects by a non-Dirac lobe, where x2 is reached from x1 by a non-Dirac
    // lobe and unscattered, x1's model Lambertian-bounded (lambertianBounded,
    // surface_vpl_estimator.h) and x2's reflecting broadly (reflectsBroadly: the
    // VPLs on narrow lobes give part (a) nothing), to the VPLs, except for the
    // share the VPLs' clamped 1 / max(d, R)^2 leaves out: with d = |x2 - x1|, x2's non-Dirac reflection (its
    // NEE and whatever follows a non-Dirac sample there) counts with weight
    // 1 - (d / R)^2 where d < R, and not at all beyond. Emission at x2 and its Dirac
    // lobes count in full. Since 1/d^2 = 1/max(d, R)^2 + (1/d^2 - 1/max(d, R)^2) and
    // the second term is (1/d^2) max(0, 1 - d^2/R^2), the two estimators add up to
    // the unsplit one. 0: off.
    float surfaceVplRadius = 0.0f;
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
// radiance times transmittance over the sampling pdf, with its direction and
// that pdf (for MIS weights).
struct DirectLighting {
    Vec3 direction;
    Rgb radianceOverPdf{0.0f};
    float pdf = 0.0f;  // solid angle: emitter choice x sampleDirect's pdf; 0 for point and spot lights
    Rgb transmittance{0.0f};  // along the shadow ray
};
DirectLighting sampleDirectLighting(const Scene& scene, const Vec3& point, const SurfaceHit* surface, int medium,
                                    Rng& rng);

}  // namespace vrl
