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
//       With surface VPLs (vrl, vrl-lightcuts), the light that x2 reflects by a
//       non-Dirac lobe towards x1's non-Dirac lobes comes instead from the surface
//       VPLs, with the inverse square clamped at distance R
//       (surface_vpl_estimator.h): per camera sample, at that sample's x1, a
//       stochastic cut of kSurfaceVplSamples VPLs drawn down their tree in
//       proportion to their bound (surface_vpl_lightcuts_estimator.h), unbiased. Per sample, not
//       once per pixel: the sample's own x1 averages the pixel's footprint as the
//       path tracer does (once per pixel, a pixel half on a lamp's bright inside
//       came out either bright or dark). The path-traced part keeps x2's
//       emission, its Dirac lobes, the reflection of an x2 whose lobe is narrow
//       (reflectsBroadly) and, for x2 within R of x1, the share the clamp
//       leaves out (PathStart::surfaceVplRadius);
//   (b) x1 in a medium, x2 not in a medium: single scattering from the lights
//       (a point of the camera segment sampled equiangularly towards a light,
//       next-event estimation there) plus light reflected by surfaces (a point
//       sampled in proportion to transmittance, a direction by the phase
//       function, path-traced from the surface it reaches, no emission there).
//       With surface VPLs (vrl, vrl-lightcuts: surface_vpl.h), the light that
//       x2 reflects by a non-Dirac lobe comes instead from every surface VPL,
//       or a cut over them (surface_vpl_lightcuts_estimator.h), against each camera segment,
//       once per pixel; the path-traced part keeps the Dirac lobes at x2
//       (PathStart::diracAtFirstSurfaceOnly), the complement;
//   (c) x1 on a surface, x2 in a medium: VRL-lit surfaces: every VRL
//       (VrlSurfaceEstimator), a cut through the VRL tree (surface_lightcuts_estimator.h)
//       or a stochastic cut (stochastic_lightcuts_estimator.h) at x1; once per pixel with
//       jittered rays, the VRLs are interleaved over 2 x 2 points x1 of the
//       pixel instead (interleaved_points.h; vrl-stochastic, per camera
//       sample, keeps the sample's own x1); the VPL methods path-trace it
//       (their lights are points);
//   (d) x1 and x2 in media: every VRL (--method vrl), a cut (vrl-lightcuts) or
//       a stochastic cut (vrl-stochastic) against each camera segment, or VPLs
//       gathered at distance samples (vpl, vpl-lightcuts).
// The four sets are disjoint and cover every path, so the parts add up to the
// reference path tracer's image. Camera paths continue through purely specular
// surfaces (camera_segment.h): parts (b)-(d) shade every medium segment of that
// path, and (a), (c) take the first other surface it reaches. With a finite
// maxDepth, the specular bounces count towards it in (a), (b); parts (c), (d)
// do not know each VRL's depth and ignore them (a warning says so).
#pragma once

#include "render/integrators/path_tracer.h"
#include "render/integrators/pixel_footprint.h"
#include "render/integrators/transport_parts.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/cuts/vpl_lightcuts_estimator.h"
#include "render/lightcuts/cuts/stochastic_lightcuts_estimator.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"
#include "render/lightcuts/cuts/surface_lightcuts_estimator.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"
#include "render/vrl/interleaved_points.h"
#include "render/vrl/vrl.h"
#include "render/vrl/vrl_estimator.h"
#include "render/vrl/vrl_surface_estimator.h"

#include <array>
#include <memory>
#include <span>

namespace vrl {

struct TransportIntegratorSettings {
    TransportSelection transports;
    int maxDepth = -1;
    int vrlSamples = 1;  // (u, v) samples per VRL and camera segment
    CutSettings cut;     // used when a light tree is given
    // The lights are VPLs: (d) is VPL Lightcuts over the tree, or plain VPLs without one.
    bool vpls = false;
    int vplDistanceSamples = kDefaultVplDistanceSamples;  // distance samples per camera segment (VPLs)
    // With a tree: (c), (d) by stochastic cuts (stochastic_lightcuts_estimator.h) of cut.stochasticCutSize nodes.
    bool stochastic = false;
    // (b)'s surface VPLs by a cut over their tree (vrl-lightcuts), else every VPL; part
    // (a) samples them down that tree in both.
    bool surfaceVplCut = false;
    // Part (c) once per film square (virtualLightParts' `pixel`): the VRLs interleaved over
    // side x side stratified points of the square (interleaved_points.h); 1: at the camera
    // ray's own surface point. The renderer takes kInterleavedPointsSide with jittered
    // rays, 1 at pixel centres.
    int surfacePointsSide = 1;
};


class TransportIntegrator {
public:
    // Parts (c), (d) sum every VRL of `vrls`, or, when `tree` is given, walk Lightcuts over it.
    // With `surfaceVpls` (and part (b) selected), (b)'s non-Dirac surface light comes from
    // them: a cut when they hold a tree, else every VPL.
    TransportIntegrator(const Scene& scene, const VrlSet& vrls, const TransportIntegratorSettings& settings,
                  const LightTree* tree = nullptr, const SurfaceVplLights* surfaceVpls = nullptr);

    // The path-sampled parts for one camera ray, one sample each: (a), (b), and
    // for the VPL methods (c). The other entries are zero.
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
    bool surfaceVplsLight() const { return surfaceVpls_ != nullptr && surfaceVplsSingle_; }
    // Part (a)'s light from non-Dirac reflections at x2 comes from surface VPLs
    // (samplePathParts), with the inverse square clamped at this radius.
    bool surfaceVplsLightSurfaces() const { return surfaceVplRadius_ > 0.0f; }
    float surfaceVplRadius() const { return surfaceVplRadius_; }

    // Part (c) is estimated from VRLs (not path-sampled).
    bool vrlLitSurfaces() const { return !settings_.vpls; }
    // Whether the renderer evaluates virtualLightParts once per camera sample
    // (with that sample's random stream and ray, averaged like (a), (b)) rather
    // than once per pixel (with the pixel's own stream (seed, pixel, ~0), in the
    // first sample pass only, so (c), (d) do not depend on the sample count):
    // true for stochastic cuts, whose (c), (d) are Monte Carlo estimates.
    bool virtualLightsPerSample() const { return stochastic_ != nullptr; }

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
    const VrlSet& vrls_;
    TransportIntegratorSettings settings_;
    VolumetricPathTracer tracer_;
    VrlEstimator estimator_;
    std::unique_ptr<VrlLanes> plainLanes_;  // plain VRLs only
    VrlSurfaceEstimator surfaceEstimator_;
    const LightTree* tree_;
    std::unique_ptr<DirectionCones> cones_;  // vrl-lightcuts with an HG medium: shared by both cuts' bounds
    std::unique_ptr<LeafSegments> leaves_;   // vrl-lightcuts: shared by both cuts' bounds
    std::unique_ptr<LightcutsEstimator> lightcuts_;
    std::unique_ptr<SurfaceLightcutsEstimator> surfaceLightcuts_;
    std::unique_ptr<StochasticLightcutsEstimator> stochastic_;
    std::unique_ptr<VplLightcutsEstimator> vplLightcuts_;
    std::unique_ptr<VplEstimator> plainVpls_;
    const SurfaceVplLights* surfaceVpls_ = nullptr;  // set only when part (a) or (b) takes light from them
    bool surfaceVplsSingle_ = false;                 // part (b) does
    float surfaceVplRadius_ = 0.0f;                  // > 0: part (a) does (surfaceVplRadius)
    SurfaceVplEstimator surfaceVplEstimator_;
    std::unique_ptr<SurfaceVplLightcutsEstimator> surfaceVplLightcuts_;
};

}  // namespace vrl
