// VrlSurfaceEstimator: the contribution of one short VRL to a surface point x
// that the camera sees (part (c), medium-to-surface: light that scattered in
// the medium, on the VRL, and then reaches a visible surface; Novak et al. 2012
// shade surfaces with the same VRLs).
//
// The VRL (origin o, unit direction d, length L, flux Phi, medium m) lights x
// from every point v(t) = o + t d, t in [0, L]:
//   L_c = integral_0^L Phi sigma_s(m) f_p(d, x - v) T_r(v, x) V(v, x)
//                       f_s(x, wo, wi) |cos(wi, n_s)| / |x - v|^2 dt,   wi = (v - x) / |v - x|.
// (No T_r along the VRL: a short VRL ends at a sampled collision, which replaces
// it in expectation, vrl.h.) With Delta = d.(x - o) the foot of x on the VRL's
// line and h the distance from x to that line, |x - v(t)|^2 = h^2 + (t - Delta)^2.
// Equiangular sampling of t from x (the angle theta = atan((t - Delta) / h)
// uniform in [theta_A, theta_B] = [atan(-Delta / h), atan((L - Delta) / h)]):
//   p(t) = h / ((theta_B - theta_A) (h^2 + (t - Delta)^2)),
// so the 1/|x - v|^2 cancels and one sample is
//   Phi sigma_s f_p f_s |cos| T_r V (theta_B - theta_A) / h,
// where (theta_B - theta_A) / h = integral_0^L dt / |x - v(t)|^2 <= L / d^2, d
// the distance from x to the VRL segment (the fact the cluster bound uses).
// Degenerate cases, with their exact limits:
//   - zero length: the integral is 0.
//   - x on the VRL's line (h -> 0): the angle span shrinks with h and the ratio
//     tends to 1/|Delta| - 1/|Delta - L| when x lies outside the segment; the
//     floor on h (1e-7 of the scale) keeps the pdf proper. On the segment itself
//     the integral diverges (a VRL ending at x); the floor keeps it finite.
//   - VRL parallel to the surface: nothing special in the sampling; the cosine
//     is that of each sampled direction (0 in the surface's plane).
// One VRL is one sample per call (samplesPerVrl averages several). The BSDF is
// evaluated with its non-Dirac lobes only (Bsdf::eval): Dirac lobes at x stay in
// part (a), which path-traces them (transport_parts.h).
#pragma once

#include "render/core/rng.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/vrl.h"

namespace vrl {

class Scene;

class VrlSurfaceEstimator {
public:
    VrlSurfaceEstimator(const Scene& scene, int samplesPerVrl);

    // One estimate of the radiance the VRL sends through x towards the camera
    // path (already multiplied by the path's throughput up to x).
    Rgb contribution(const Vrl& vrl, const CameraPathSurface& x, Rng& rng) const;

private:
    Rgb sampleOnce(const Vrl& vrl, const CameraPathSurface& x, Rng& rng) const;

    const Scene& scene_;
    int samplesPerVrl_;
};

}  // namespace vrl
