// render/integrators/: whole-image estimators: the reference volumetric path tracer
// and the four-part transport integrator that the virtual-light methods share.
//
// TransportIntegrator: the image as the sum of four transport parts
// (transport_parts.h), split by the camera path's first two vertices x1, x2
// (x1: the first vertex past null boundaries and, on the camera path of
// camera_segment.h, past purely specular bounces):
//   (a) x1 on a surface, x2 not in a medium: path-traced from x1, with the
//       camera segment's exact transmittance and the segment after x1 crossed
//       with its exact transmittance too (no medium vertex: (c) has those).
//       With surface VPLs (vrl, vrl-lightcuts; SurfaceVplLight, surface_vpl_light.h),
//       the light that x2 reflects by a non-Dirac lobe towards x1's non-Dirac lobes
//       comes instead from the surface VPLs, with the inverse square clamped at distance R
//       (surface_vpl_estimator.h): per camera sample, at that sample's x1, a
//       stochastic cut of kSurfaceVplSamples VPLs drawn down their tree in
//       proportion to their bound (surface_vpl_lightcuts_estimator.h), unbiased. Per sample, not
//       once per pixel: the sample's own x1 averages the pixel's footprint as the
//       path tracer does (one x1 per pixel would leave a pixel that straddles a
//       bright edge all bright or all dark). The path-traced part keeps x2's
//       emission, its Dirac lobes, the reflection of an x2 whose lobe is narrow
//       (reflectsBroadly) and, for x2 within R of x1, the share the clamp
//       leaves out (PathStart::surfaceVplRadius);
//   (b) x1 in a medium, x2 not in a medium: single scattering from the lights
//       (a point of the camera segment sampled equiangularly towards a light,
//       next-event estimation there) plus light reflected by surfaces (a point
//       sampled in proportion to transmittance, a direction by the phase
//       function, path-traced from the surface it reaches, no emission there).
//       With surface VPLs (vrl, vrl-lightcuts: surface_vpl.h), the light that
//       x2 reflects by a non-Dirac lobe comes instead from every surface VPL
//       (PlainSurfaceVplLight), or a cut over them (SurfaceVplCutLight,
//       surface_vpl_lightcuts_estimator.h), against each camera segment, once per pixel; the path-traced part keeps the Dirac lobes at x2
//       (PathStart::diracAtFirstSurfaceOnly), the complement;
//   (c) x1 on a surface, x2 in a medium: VRL-lit surfaces (a SurfaceGatherer,
//       surface_gatherer.h): every VRL (VrlSurfaceEstimator), a cut through the VRL
//       tree (surface_lightcuts_estimator.h) or a stochastic cut
//       (stochastic_lightcuts_estimator.h) at x1; once per pixel with
//       jittered rays, the VRLs are interleaved over 2 x 2 points x1 of the
//       pixel instead (interleaved_points.h; vrl-stochastic, per camera
//       sample, keeps the sample's own x1); the VPL methods path-trace it
//       (their lights are points);
//   (d) x1 and x2 in media (a MediumGatherer, medium_gatherer.h): every VRL
//       (--method vrl), a cut (vrl-lightcuts) or a stochastic cut (vrl-stochastic)
//       against each camera segment, or VPLs gathered at distance samples (vpl,
//       vpl-lightcuts).
// Which estimator takes (c), (d) and the surface VPLs' light is the method's
// PartEstimators (part_estimators.h); makeGatherers (gatherers.h) builds them once.
// The four sets are disjoint and cover every path, so the parts add up to the
// reference path tracer's image. Camera paths continue through purely specular
// surfaces (camera_segment.h): parts (b)-(d) shade every medium segment of that
// path, and (a), (c) take the first other surface it reaches. With a finite
// maxDepth, the specular bounces count towards it in (a), (b); parts (c), (d)
// do not know each VRL's depth and ignore them (a warning says so).
#pragma once

#include "render/integrators/gatherers.h"
#include "render/integrators/part_estimators.h"
#include "render/integrators/path_tracer.h"
#include "render/integrators/pixel_footprint.h"
#include "render/integrators/transport_parts.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/surface_vpl_lights.h"
#include "render/vrl/interleaved_points.h"
#include "render/vrl/vpl_estimator.h"
#include "render/vrl/vrl.h"

#include <array>
#include <span>

namespace vrl {

struct TransportIntegratorSettings {
    TransportSelection transports;
    int maxDepth = -1;
    int vrlSamples = 1;  // (u, v) samples per VRL and camera segment
    CutSettings cut;     // used by the cut kinds
    // The estimator of each virtual-light part (the method table's row, render_method.h);
    // a cut kind without a tree takes its plain kind (makeGatherers).
    PartEstimators estimators;
    int vplDistanceSamples = kDefaultVplDistanceSamples;  // distance samples per camera segment (VPLs)
    // Part (c) once per film square (virtualLightParts' `pixel`): the VRLs interleaved over
    // side x side stratified points of the square (interleaved_points.h); 1: at the camera
    // ray's own surface point. The renderer takes kInterleavedPointsSide with jittered
    // rays, 1 at pixel centres.
    int surfacePointsSide = 1;
};

class TransportIntegrator {
public:
    // Parts (c), (d) from the VRLs (or VPLs) of `vrls`, or of `tree` for the cut kinds,
    // by the estimators settings.estimators names. With `surfaceVpls` (and a surface-VPL
    // kind), (b)'s non-Dirac surface light comes from them, and (a)'s share where they
    // hold a tree.
    TransportIntegrator(const Scene& scene, const VrlSet& vrls, const TransportIntegratorSettings& settings,
                        const LightTree* tree = nullptr, const SurfaceVplLights* surfaceVpls = nullptr);

    // The path-sampled parts for one camera ray, one sample each: (a), (b), and
    // (c) where it is path-sampled (the VPL methods). The other entries are zero.
    std::array<Rgb, 4> samplePathParts(const Ray& cameraRay, Rng& rng) const;

    // The virtual-light parts for one camera ray: (c) at the surface the camera
    // path reaches (VRL methods) and (d) along its medium segments, each from every
    // light or a cut, with the cuts' counters. The cuts measure their error against
    // the pixel: `pathLuminance` is the luminance of its path-sampled parts (a), (b)
    // (0: against the cut's parts alone); (d)'s cut adds its own total, (c)'s its own
    // and (d)'s, the surface VPLs' cut its own, (d)'s and (c)'s.
    // singleSurface: (b)'s light from surface VPLs (zero without them).
    struct VirtualLightParts {
        Rgb mediumSurface{0.0f}, multiple{0.0f}, singleSurface{0.0f};
    };
    // `pixel`: the film square the call stands for, when it is evaluated once for it
    // (once per pixel, or per shading point): (c) then interleaves its VRLs over
    // settings.surfacePointsSide^2 points of the square (interleaved_points.h), one
    // representative per class of coherent points, with its textures' mean over its
    // class's strata (pixel_footprint.h), or with one point
    // (side 1), the ray's own, its textures averaged over the square. Null: the ray's
    // own point and lookups.
    VirtualLightParts virtualLightParts(const Ray& cameraRay, Rng& rng, CutStatistics* multipleStatistics = nullptr,
                                        CutStatistics* surfaceStatistics = nullptr, float pathLuminance = 0.0f,
                                        CutStatistics* surfaceVplStatistics = nullptr,
                                        const FilmSquare* pixel = nullptr) const;

    // Part (b)'s non-Dirac surface light comes from surface VPLs (virtualLightParts' singleSurface).
    bool surfaceVplsLight() const { return surfaceVplsSingle_; }
    // Part (a)'s light from non-Dirac reflections at x2 comes from surface VPLs
    // (samplePathParts), with the inverse square clamped at this radius.
    bool surfaceVplsLightSurfaces() const { return surfaceVplRadius_ > 0.0f; }
    float surfaceVplRadius() const { return surfaceVplRadius_; }

    // Part (c) is estimated from VRLs (not path-sampled).
    bool vrlLitSurfaces() const { return settings_.estimators.vrlLitSurfaces(); }
    // Whether virtualLightParts is meant to be evaluated once per camera sample
    // (with that sample's random stream and ray, averaged like (a), (b)) rather
    // than once per pixel (with the pixel's own stream (seed, pixel, ~0), in the
    // first sample pass only, so (c), (d) do not depend on the sample count):
    // true for stochastic cuts, whose (c), (d) are Monte Carlo estimates.
    bool virtualLightsPerSample() const { return settings_.estimators.perSample(); }

private:
    Rgb singleScattering(const CameraSegment& segment, Rng& rng) const;
    Rgb mediumToSurface(const CameraSegment& segment, Rng& rng) const;
    // Part (a)'s light from the surface VPLs at this camera sample's x1.
    Rgb surfaceVplsAtSurface(const Ray& cameraRay, Rng& rng) const;
    // (c) over `points` (a cut takes its bounds at one of them: SurfaceLightcutsEstimator::cutPoint).
    Rgb vrlLitSurface(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                      float otherLuminance) const;
    // (c) over surfacePointsSide^2 stratified points of `square`, from streams keyed by pixelKey.
    Rgb interleavedSurface(const FilmSquare& square, uint64_t pixelKey, CutStatistics& statistics,
                           float otherLuminance) const;
    // The point's BSDF takes its textures' mean over `squares` (a point the camera sees
    // directly; squares whose rays miss its plane are left out).
    void averageTextures(CameraPathSurface& x, std::span<const FilmSquare> squares) const;

    const Scene& scene_;
    TransportIntegratorSettings settings_;
    VolumetricPathTracer tracer_;
    Gatherers gatherers_;            // (d), (c) and the surface VPLs, as settings_.estimators name them
    bool surfaceVplsSingle_ = false;  // part (b) takes light from the surface VPLs
    float surfaceVplRadius_ = 0.0f;   // > 0: part (a) does (surfaceVplRadius)
};

}  // namespace vrl
