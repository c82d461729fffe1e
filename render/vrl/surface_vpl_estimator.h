// SurfaceVplEstimator: the light one surface VPL (surface_vpl.h) sends into a
// camera segment, scattered towards the camera there (and, below the segment
// estimator, the light it sends to a camera path's surface point, part (a)'s
// share): part (b)'s paths whose
// first vertex x1 lies on the camera segment, in the medium, and whose second
// vertex x2 is a surface vertex that reflects by a non-Dirac lobe
// (transport_parts.h). It is the dual of part (c) (vrl_surface_estimator.h):
// there a VRL lights a surface point, here a surface point lights a segment.
//
// The VPL sits at y on a surface, with the light path arriving in direction
// w_in with flux Phi (BSDF not applied). The camera segment starts at o, runs
// along unit d for length S in medium m, and carries throughput beta (the
// camera path's before it). Each point u(t) = o + t d receives from y
//   L_b' = beta integral_0^S T_m(t) sigma_s(m) f_p(w, -d) T_r(y, u) V(y, u)
//                 Phi f_s(y; -w_in -> w) / |u - y|^2 dt,      w = (u - y) / |u - y|,
// where f_s is evaluated in importance mode (the adjoint BSDF with the
// shading-normal correction, as light tracing connects a surface vertex to the
// camera, light_tracing_reference.h) and includes the cosine at y. With
// Delta = d.(y - o) the foot of y on the segment's line and h the distance from y
// to it, |u(t) - y|^2 = h^2 + (t - Delta)^2. Equiangular sampling of t from y
// (sampleEquiangular, the angle uniform in [theta_A, theta_B]):
//   p(t) = h / ((theta_B - theta_A) (h^2 + (t - Delta)^2)),
// so the 1/|u - y|^2 cancels and one sample is
//   beta T_m(t) sigma_s f_p T_r V Phi f_s (theta_B - theta_A) / h,
// where (theta_B - theta_A) / h = integral_0^S dt / |u(t) - y|^2 <= min(S / d_s^2, pi / d_l),
// d_s the distance from y to the segment and d_l to its line (the facts the
// cluster bound of surface_vpl_lightcuts_estimator.h uses).
// Degenerate cases:
//   - zero-length segment: 0.
//   - y on the segment's line (h -> 0; only where the camera segment ends on
//     the VPL's surface at y itself, a set of measure zero): the angle span
//     shrinks with h and (theta_B - theta_A)/h tends to 1/|Delta| - 1/|Delta - S|
//     for y outside the segment; sampleEquiangular floors h, so the pdf stays
//     proper and the estimate finite. (Near it, a VPL beside the segment's end
//     contributes ~ 1/distance: the expectation is finite, as for VPLs in
//     general; no clamping.)
//   - a direction w behind a reflecting surface: f_s = 0.
// The visibility ray leaves y from an offset origin; the stretch it skips gets
// its transmittance back (as in vrl_surface_estimator.cpp). One VPL is one
// sample per call.
#pragma once

#include "render/core/rng.h"
#include "render/scene/scene.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/surface_vpl.h"

#include <optional>

namespace vrl {

// Part (a)'s split applies at points x1 whose non-Dirac part is Lambertian
// (diffuse, smooth plastic: Bsdf::lambertianBound).
inline bool lambertianBounded(const Bsdf& bsdf) {
    return bsdf.kind() == BsdfDescription::Kind::Diffuse || bsdf.kind() == BsdfDescription::Kind::Plastic;
}

// Part (a) takes a VPL's light (its point contribution, below) only where the VPL's
// model reflects broadly: Lambertian-bounded, or a glossy lobe of roughness at least
// kBroadLobeRoughness. A narrow lobe sends the VPL's light into a small cone, and the
// few points in it see a spike, so narrow-lobed VPLs (staircase's rough plastic, alpha
// 0.1 and 0.2) add noise, while broad ones (veach-lamp's Ward reflector, alpha 0.4)
// remove it: the threshold sits between them (the measurements behind it are in
// docs/measurements/2026-12-07-tuning-constants.md). The
// path tracer carries x2's reflection in full where x2's model is narrow
// (PathStart::surfaceVplRadius), so the split stays unbiased whatever the threshold.
inline constexpr float kBroadLobeRoughness = 0.25f;
inline bool reflectsBroadly(const Bsdf& bsdf) {
    return lambertianBounded(bsdf) || bsdf.glossyRoughness() >= kBroadLobeRoughness;
}

// The VPL's vertex as the hit record the scene's functions take.
inline SurfaceHit surfaceHitOf(const SurfaceVpl& vpl) {
    SurfaceHit hit;
    hit.position = vpl.position;
    hit.geometricNormal = vpl.geometricNormal;
    hit.shadingNormal = vpl.shadingNormal;
    hit.uv = vpl.uv;
    hit.shape = vpl.shape;
    hit.triangle = vpl.triangle;
    hit.scale = vpl.scale;
    return hit;
}

// A VPL at a surface hit: the light arriving along `direction` (unit, the way it
// travels) with `flux`, through `medium`. The inverse of surfaceHitOf.
inline SurfaceVpl surfaceVplAt(const SurfaceHit& hit, const Vec3& direction, const Rgb& flux, int32_t medium) {
    return {hit.position, hit.geometricNormal, hit.shadingNormal, hit.uv, hit.shape, hit.triangle, hit.scale,
            direction, flux, medium};
}

class SurfaceVplEstimator {
public:
    explicit SurfaceVplEstimator(const Scene& scene) : scene_(scene) {}

    // One estimate of the radiance the VPL sends through `segment` to the camera
    // (times segment.throughputBefore), with `flux` in place of vpl.flux (a
    // cluster's flux for a representative, surface_vpl_lightcuts_estimator.h).
    Rgb contribution(const SurfaceVpl& vpl, const Rgb& flux, const CameraSegment& segment, Rng& rng) const {
        return contribution(vpl, prepareAt(vpl), flux, segment, rng);
    }
    Rgb contribution(const SurfaceVpl& vpl, const CameraSegment& segment, Rng& rng) const {
        return contribution(vpl, vpl.flux, segment, rng);
    }
    // The same with the VPL's BSDF prepared beforehand (prepareAt): bit for bit equal.
    Rgb contribution(const SurfaceVpl& vpl, const PreparedBsdf& atVpl, const Rgb& flux, const CameraSegment& segment,
                     Rng& rng) const;

    // The VPL's BSDF prepared for the direction its light arrives from (wo = -direction):
    // all that every evaluation at y shares (shading frame, texture reads, plastic
    // Fresnel at wo), which a cut that evaluates one VPL against many camera points
    // keeps per VPL instead of repeating (SurfaceVplLightcutsEstimator).
    PreparedBsdf prepareAt(const SurfaceVpl& vpl) const {
        return scene_.shapes()[vpl.shape].bsdf.prepare(surfaceHitOf(vpl).shadingPoint(), -vpl.direction);
    }

    // Part (a)'s share (transport_integrator.h): the light the VPL sends to the camera
    // path's surface point x unscattered, reflected there by x's non-Dirac lobes,
    // with the inverse square clamped at distance R (below):
    //   Phi f_s(y; -w_in -> w) T_r(y, x) V(y, x) f_s(x; wo, -w) / max(|x - y|, R)^2,
    // w = (x - y) / |x - y|, f_s at y in importance mode and at x in radiance mode,
    // both with their cosines, times x.throughput. Deterministic: no sample is drawn.
    // The clamp makes the estimate bounded (instant radiosity's splotches near
    // corners, where 1/d^2 grows without bound, are gone); the path tracer adds the
    // rest, (1/d^2 - 1/R^2) for d < R, so the sum stays unbiased
    // (PathStart::surfaceVplRadius; after Kollig & Keller 2004's bias compensation).
    // 0 where x coincides with y, for a grazing or back-facing direction at either end,
    // unless x's model is Lambertian-bounded (lambertianBounded): a glossy x stays
    // with the path tracer, since it sees the VPLs in its lobe as spikes (staircase's
    // glossy floor: part (a)'s noise x2.4), and unless the VPL's model reflects
    // broadly (reflectsBroadly): VPLs on broad glossy lobes do take part, since they
    // carry veach-lamp's light from its reflector to the walls.
    Rgb contribution(const SurfaceVpl& vpl, const Rgb& flux, const CameraPathSurface& x, float radius) const {
        return contribution(vpl, prepareAt(vpl), flux, x, radius);
    }
    Rgb contribution(const SurfaceVpl& vpl, const PreparedBsdf& atVpl, const Rgb& flux, const CameraPathSurface& x,
                     float radius) const;

    // A bound on f_s(y; -w_in -> w) over every w (cosine included) for VPLs on
    // surfaces whose non-Dirac part is Lambertian (Bsdf::lambertianBound): rho/pi
    // times the importance-mode correction |w_in.n_s| / |w_in.n_g|, which depends
    // on w_in only (Veach 1997 §5.3: f_adj = f |w.n_g| |w_in.n_s| / (|w_in.n_g| |w.n_s|),
    // and f |w.n_s| <= rho/pi |w.n_s|). Empty for glossy lobes.
    std::optional<Rgb> reflectionBound(const SurfaceVpl& vpl) const;

private:
    const Scene& scene_;
};

}  // namespace vrl
