// Lightcuts over surface VPLs (surface_vpl.h) for a camera segment: part (b)'s
// medium-then-surface light (SurfaceVplEstimator) by a cut instead of every VPL.
//
// The tree is a point-cluster LightTree (LightTreeSettings::points) over proxy
// lights, one per VPL k at its position, whose "flux" is the VPL's intensity
// bound I_k = Phi_k (x) F_k, F_k a bound on its BSDF times cosine over every
// outgoing direction (SurfaceVplEstimator::reflectionBound); node C carries
// I_C = sum of I_k below. Leaf k is VPL k (the tree keeps the input order, so
// the VPL list and the proxies share indices).
//
// Estimate of a node: its representative VPL r's one-sample estimate with flux
// I_C / F_r, channel by channel (= Phi_r I_C / I_r where Phi_r > 0; a channel in
// which r carries no flux still estimates the cluster's): linear in I_C, and
// exactly VPL r's own estimate at a leaf where F_r > 0 (where F_r = 0 the
// estimate is 0 either way), cut_walk.h's contract. VPL k draws from
// vrlStream(streamKey, k) in plain and cut shading alike.
//
// Bound (proof). For every VPL k of node C (box B) and any sample t of a
// segment (o, d, S, medium m, throughput beta), the estimate is
//   beta T_m(t) sigma_s f_p T_r V Phi_k f_s,k (theta_B - theta_A) / h
//     <= beta sigma_s f_p,max I_k G,   G = min(S / d_s^2, 2 atan(S / 2 d_l) / d_l),
// because T_m, T_r, V <= 1; f_s,k <= F_k; f_p <= f_p,max (1/4pi isotropic,
// (1 + |g|) / (4 pi (1 - |g|)^2) for Henyey-Greenstein, its value at cos = +-1);
// and (theta_B - theta_A)/h = integral_0^S dt / |u(t) - y|^2 is at most S / d_s^2
// (d_s: distance from y to the segment, bounded below by the distance between B
// and the segment) and at most 2 atan(S / 2h) / h <= pi / h (h >= d_l, the distance
// from the line to B; decreasing in h). A node's estimate is
// sum-weighted by I_C / I_r, so it is at most beta sigma_s f_p,max I_C G.
// Transmittance: where every VPL of the node lies in the segment's medium on a
// shape that bounds no medium (the proxy's medium, else -1) and that medium's
// boundary is convex, u -> y stays in it, so T_m(t) T_r = exp(-sigma_t (t + r))
// with t + r >= |o - y| >= d_o, the distance from the segment's origin o to B:
// the bound takes the factor T(d_o) (floored at kTransmittanceBoundFloor against underflow).
// The cosine at y, where every VPL of the node has a Lambertian bound and their
// geometric normals n_k lie within eps of one axis a (|n_k - a| <= eps: a floor, a
// wall): for Lambertian-bounded models f_s = F_k |w.n_g| at most (the importance-mode
// factor is |w.n_g| |w_in.n_s| / |w_in.n_g|), and at the sampled point u
//   |n_k.w| = |n_k.(u - y)| / r <= (|a.(u - y)| + eps r) / r <= h / d_s + eps,
// h the largest |a.(u - y)| over the segment's ends and the box's points (a.u is
// linear along the segment, a.y over the box) and r >= d_s. So the bound takes
// the factor min(1, h / d_s + eps): it matters where the segment runs low over a
// distant patch of floor, which it sees at a grazing angle. (A bound of the
// integral of |cos| / r^2 would be smaller, but the estimate is one sample: its
// cosine is the sampled point's, times the whole integral of 1 / r^2.)
// Proven where every VPL below has a Lambertian BSDF bound (diffuse, smooth
// plastic); VPLs on glossy surfaces get F_k = 2 x the largest f_s |cos| found
// towards the mirror direction of w_in and the shading normal, a heuristic
// (the cut counts estimates above their bound: boundExceeded). A node whose box
// the segment's line meets (d_l = 0) and whose bounding box the segment's
// touches has no finite bound: it is refined without an estimate (#Inter).
//
// The cut stops when the largest bound is below errorThreshold x (luminance
// of the running total plus the pixel's other parts), as part (c)'s cut does.
//
// The same tree and estimator serve a second receiver: the camera path's surface
// point x, part (a)'s share of the VPLs (SurfaceVplEstimator's point contribution,
// the inverse square clamped at distance R). Bound (proof). For every VPL k of
// node C (box B), with d = dist(x, B) (less the rounding slack) and r = |x - y| >= d:
//   Phi_k f_s,k T_r V f_s,x |cos_x| / max(r, R)^2
//     <= I_k c_y F_x(B) T(d) / max(d, R)^2,
// where f_s,k <= F_k (I_k = Phi_k F_k, above); c_y = min(1, h / d + eps) is the
// cosine at y for nodes of Lambertian-bounded VPLs with nearly one normal a (as
// above: |n_k.w| <= |a.(x - y)| / r + eps <= h / d + eps, h the largest |a.(x - p)|
// over B's points p), else 1; F_x(B) bounds x's f_s |cos| towards B
// (SurfaceClusterBound::reflectionTowardsBox: proven for Lambertian x, the glossy
// heuristic otherwise; 0 when B lies wholly behind x); and T(d) applies where the
// node's VPLs (the proxy's medium) and x lie in one medium with a convex boundary,
// x's shape bounding no medium, so the segment x-y stays inside it, else 1. Sum
// over the representative's weighting as above: at most I_C c_y F_x T / max(d, R)^2.
// Only the VPLs part (a) takes (reflectsBroadly) contribute; the others give 0, so
// I_C there sums the I_k of those alone (0 for a node of narrow-lobe VPLs: beside a
// sibling of positive, finite bound such a node takes no slot of the stochastic cut and no
// descent takes it (stochastic_cut.h); only where every node is 0 is one drawn, and it gives 0). The clamp makes every bound finite, even for a box that holds x. Part (a) takes
// this bound as the importance of a stochastic cut (sample, below): VPLs are drawn
// in proportion to it, so a draw's estimate / probability stays near the node's
// bound where visibility and the cosines are near their bounds.
#pragma once

#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/surface_vpl_lights.h"
#include "render/lightcuts/cuts/stochastic_cut.h"
#include "render/vrl/surface_vpl_estimator.h"

#include <array>
#include <cstdint>
#include <vector>

namespace vrl {

// The intensity bound F_k of VPL k (above): proven for Lambertian-bounded BSDFs, a heuristic otherwise.
Rgb surfaceVplReflectionBound(const Scene& scene, const SurfaceVpl& vpl);

// Part (a)'s clamp radius R (surface_vpl_estimator.h): kSurfaceVplRadiusFraction of
// the diagonal of the VPLs' bounding box (the lit part of the scene), so that it
// scales with the scene; 0 without VPLs. Below R the path tracer carries the
// share the clamp leaves out: a larger R moves more of (a) back to path tracing,
// a smaller one lets the VPLs' 1/d^2 peak; part (a)'s noise is flat around this
// fraction and rises well below it (docs/measurements/2026-12-07-tuning-constants.md).
// The same VPLs give the same R on every machine.
inline constexpr float kSurfaceVplRadiusFraction = 0.02f;
// VPLs drawn per camera sample for part (a) (the stochastic cut's size): past 2 the
// rest of (a)'s noise is the path-traced remainder, so more VPLs cost time and
// remove little (docs/measurements/2026-12-07-tuning-constants.md).
inline constexpr uint32_t kSurfaceVplSamples = 2;
float surfaceVplRadius(const SurfaceVplLights& lights);

// Leaves out the VPLs whose bound is zero (they reflect nothing) and, with
// `buildTree`, builds the cut's tree over the rest; the result's vpls are the
// kept ones, in the tree's order. Plain and cut shading take the same list, so
// VPL k has the same random stream in both.
SurfaceVplLights prepareSurfaceVpls(const Scene& scene, std::vector<SurfaceVpl> vpls, bool buildTree,
                                    const LightTreeSettings& settings = {});

class SurfaceVplLightcutsEstimator {
public:
    // `lights` must hold a tree built by prepareSurfaceVpls for this scene.
    SurfaceVplLightcutsEstimator(const Scene& scene, const SurfaceVplLights& lights,
                                 const SurfaceVplEstimator& estimator, CutSettings settings);
    // What the estimator keeps per VPL besides the lights (for memory estimates).
    // (Per VPL: its bound and prepared BSDF; per node, two per VPL: the normal bound
    // and part (a)'s flux.)
    static constexpr size_t kBytesPerVpl =
        sizeof(Rgb) + sizeof(PreparedBsdf) + 2 * (sizeof(Vec3) + sizeof(float) + sizeof(Rgb));

    // The medium-then-surface light along `segment` from every VPL, by a cut.
    Rgb estimate(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                 float otherLuminance = 0.0f) const;
    // Plain shading of (b)'s surface light, every VPL against `segment`: sumOverSurfaceVpls
    // with the VPLs' BSDFs prepared once (atVpl_; without a tree, prepared on each call).
    Rgb sumAll(const CameraSegment& segment, uint64_t streamKey) const;

    // The bound above for node `node` and `segment`; infinite where the segment may meet the box.
    Rgb bound(int32_t node, const CameraSegment& segment) const;

    // Part (a)'s share at the camera path's surface point x from every VPL, the inverse
    // square clamped at `radius` > 0 (SurfaceVplEstimator: 0 unless x is
    // Lambertian-bounded): an unbiased estimate by a stochastic cut of `cutSize` nodes,
    // one VPL drawn under each (stochastic_cut.h). A node's importance is its point
    // bound above, summed over channels. With x's factor proven, it is 0 only where
    // the node's flux is 0, it holds no VPL part (a) takes (reflectsBroadly) or its
    // box lies behind x, where every VPL below gives 0:
    // every VPL that can contribute is reachable. (On glossy VPLs the bound is a
    // heuristic; as an importance it only has to be positive, which it is.)
    Rgb sample(const CameraPathSurface& x, float radius, uint32_t cutSize, Rng& rng, CutStatistics& statistics) const;
    // The importances of inner node `node`'s children at x, as sample() uses them.
    ChildImportances importances(int32_t node, const CameraPathSurface& x, float radius) const;
    // The bound above for node `node` at x; finite (the clamp).
    Rgb bound(int32_t node, const CameraPathSurface& x, float radius) const;

private:
    // Per node: the axis a of its VPLs' geometric normals and eps (above); eps < 0
    // where some VPL below has no Lambertian bound (no cosine factor then).
    struct NormalBound {
        Vec3 axis;
        float spread = -1.0f;
    };

    const Scene& scene_;
    const SurfaceVplLights& lights_;
    const SurfaceVplEstimator& estimator_;
    CutSettings settings_;
    std::vector<NormalBound> normals_;
    // Per node: I_C over the VPLs below that part (a) takes (reflectsBroadly), the
    // intensity its point bound carries in place of the cluster's.
    std::vector<Rgb> broadIntensity_;
    std::vector<Rgb> reflection_;  // F_k per VPL (surfaceVplReflectionBound), for the representatives' flux
    // Each VPL's BSDF prepared for its arrival (SurfaceVplEstimator::prepareAt): a VPL
    // is evaluated at many camera points, and its texture reads and shading frame
    // were a tenth of staircase's render time (kBytesPerVpl each).
    std::vector<PreparedBsdf> atVpl_;
    // A node's flux as its representative carries it: I_C / F_r per channel (above).
    Rgb representativeFlux(const LightTreeNode& node) const;
    // The point bound per channel, in double (bound() rounds it to float; importances sum it).
    std::array<double, 3> pointBound(int32_t node, const CameraPathSurface& x, float radius) const;
};

// Plain shading: every VPL of `vpls` against `segment`, VPL k from vrlStream(streamKey, k),
// with VPL k's BSDF from (*prepared)[k] where given (prepareAt; bit for bit the same sum,
// without preparing it on every call). Throws std::invalid_argument if the sizes differ.
Rgb sumOverSurfaceVpls(const SurfaceVplEstimator& estimator, const std::vector<SurfaceVpl>& vpls,
                       const CameraSegment& segment, uint64_t streamKey,
                       const std::vector<PreparedBsdf>* prepared = nullptr);
// Plain shading of part (a)'s share: every VPL of `vpls` at x, the inverse square clamped at `radius`.
Rgb sumOverSurfaceVpls(const SurfaceVplEstimator& estimator, const std::vector<SurfaceVpl>& vpls,
                       const CameraPathSurface& x, float radius);

}  // namespace vrl
