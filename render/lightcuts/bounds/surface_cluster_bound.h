// SurfaceClusterBound: an upper bound on the single-sample part-(c) estimate
// (VrlSurfaceEstimator, vrl/vrl_surface_estimator.h) of a light-tree node at a
// surface point x, so that a cut can stop refining a node whose contribution is
// below the error threshold. The paper bounds medium-to-medium nodes only
// (cluster_bound.h); this is its counterpart for VRL-lit surfaces.
//
// Derivation. A node is estimated by its representative VRL (length L_rep)
// carrying the cluster flux Phi_C. One sample of that VRL is
//   Phi_C sigma_s f_p(d, -wi) [f_s(wo, wi) |cos(wi, n_s)|] T_r(v, x) V (theta_B - theta_A) / h
// and (theta_B - theta_A) / h = integral_0^L dt / |x - v(t)|^2 <= L_rep / d^2,
// d the distance from x to the representative's segment (the estimator floors
// h from above, which only lowers the ratio). It is also <= pi / d, whatever the
// length: the segment lies on its line (distance h <= d from x) where |x - v| >= d,
// outside the stretch |t| < t0 = sqrt(d^2 - h^2) about the foot of x, so the integral is
// at most 2 integral_t0^inf dt / (h^2 + t^2) = 2 atan(h / t0) / h = 2 phi / (d sin phi)
// with h = d sin phi, phi in (0, pi/2], which is largest, pi / d, at phi = pi/2.
// So the node's factor is Phi_C min(L_rep / d^2, pi / d) = min(fluxLength / d^2,
// pi Phi_C / d) per channel: the second is the smaller for nodes nearer than
// L_rep / pi (staircase: part (c)'s evaluations -6%). Each remaining factor is bounded
// over every point p of the node's box B (the sampled v lies in B):
//   - d >= dist(x, B), or the exact distance to the node's segments for small
//     nodes (LeafSegments). x inside B (d = 0): no bound, the cut refines.
//   - |cos(wi, n_s)| = |n_s.(v - x)| / |v - x| <= max_B |n_s.(p - x)| / d (<= 1);
//     max_B of a linear function is at the box's support point.
//   - f_s for a diffuse surface is rho(x)/pi whatever the directions (exact);
//     a reflecting model is 0 for wi on the other geometric side than wo: if
//     all of B lies there, the bound is 0.
//   - f_p <= 1/(4 pi) (isotropic). Henyey-Greenstein: f_p is monotone in the
//     cosine between the VRL direction d and v -> x. The node's VRL directions lie
//     in its DirectionCone (a, alpha) (direction_cone.h); the directions from its
//     box (half diagonal R, centre c) to x lie within beta = asin(R / |x - c|) of
//     x - c (every direction when x is within R of c). So that angle lies in
//     [theta(a, x - c) -+ (alpha + beta)], and f_p is bounded by its value at the
//     nearer end (PhaseFunction::valueRange, with its float margins), over every
//     medium of a node spanning several; the angles widen by 2 slack / d + 1e-6
//     for rounded sample points. Without cones (a cone of pi) this is HG's peak
//     (1 + |g|) / (4 pi (1 - |g|)^2).
//   - T_r(v, x) V <= T_r(d) when the node's VRLs lie in x's own medium and its
//     boundary is convex (the segment x-v stays inside it), else 1.
//   - sigma_s: the node's medium's, or the largest of all media.
// With Phi_C L_rep = the node's flux x length:
//   bound = min(fluxLength / d^2, pi Phi_C / d) sigma_s f_p,max (rho/pi) cos_max T_r(d) throughput.
// Glossy models: rough plastic and rough conductor with a Beckmann or GGX lobe
// (GlossyBound::Cones, the default) take PreparedBsdf::coneBound over the cone of
// directions from x to the box (a cap around the directions to its corners, which
// holds them all when x lies outside the box: they are its spherically convex
// hull; proven, derivation in materials/bsdf.h). The other glossy models (Phong,
// Ward, rough dielectric), and all with GlossyBound::Corners, take glossyMargin
// times the largest f_s|cos| towards the box's corners, its centre and its point
// nearest the mirror direction of wo (where a lobe peaks): a heuristic;
// CutStatistics::boundExceeded counts the estimates above it. (Refining every
// node wider than its distance instead made staircase's cuts reach 19,000 of
// 10^5 VRLs per pixel, 6x the time.) Float rounding of sample points: d is taken a few float
// steps closer and the bound carries a 1.001 margin, as in cluster_bound.h.
#pragma once

#include "render/lightcuts/bounds/cluster_bound_settings.h"
#include "render/lightcuts/bounds/direction_cone.h"
#include "render/lightcuts/tree/leaf_segments.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/camera_segment.h"

#include <memory>

namespace vrl {

class Scene;

class SurfaceClusterBound {
public:
    // `cones`: shared DirectionCones of the tree (built here when the scene has an HG medium and none are given).
    SurfaceClusterBound(const Scene& scene, const LightTree& tree, ClusterBoundSettings settings = {},
                        const DirectionCones* cones = nullptr, const LeafSegments* leaves = nullptr);

    // RGB bound for `node` lighting `x`; +infinity (and *xInsideNode = true) when
    // x lies in the node's box (or on one of a small node's segments).
    // *factor (optional): the receiver's factor f_s|cos| it used (below).
    // `distance` (optional): the distance cheapBound gave for this node and x, which
    // the bound then takes instead of computing it again.
    Rgb bound(int32_t node, const CameraPathSurface& x, bool* xInsideNode = nullptr, Rgb* factor = nullptr,
              const double* distance = nullptr) const;
    // A cheaper bound for the cut's deferred bounds (cut_walk.h); *tight says whether it
    // is the full one. For a glossy x, given `inheritedGlossy` (the factor of a box that
    // holds this node's box: its parent's), it takes that factor instead of its own: the
    // directions to the node are among those to the parent's box, so a proven (cone)
    // factor stays proven, a heuristic one stays a heuristic. Elsewhere it is the full bound. (Deferring a small node's exact
    // distance as well, with the box's distance as the cheap one, made renders slower:
    // nearly every such node reached the heap's top and paid for both.)
    // *distance (optional): the distance it used (after the rounding slack), for bound().
    Rgb cheapBound(int32_t node, const CameraPathSurface& x, bool* xInsideNode, const Rgb* inheritedGlossy,
                   Rgb* factor, bool* tight, double* distance = nullptr) const;
    // The distance from x to the node used by the bound (box, or exact for small nodes).
    double minimumDistance(int32_t node, const Vec3& x) const;
    // Whether the bound is proven for the BSDF at x (Lambertian-bounded models; with
    // GlossyBound::Cones also rough plastic and rough conductor, Beckmann and GGX) or a
    // heuristic (the other glossy models).
    static bool provenFor(const Bsdf& bsdf, const ClusterBoundSettings& settings = {});
    // The receiver's factor above, also the surface-VPL cut's at a surface point
    // (surface_vpl_lightcuts_estimator.h): a bound on f_s(x; wo, wi) |cos(wi, n_s)| over the
    // directions wi from x to the points of `box`, at distance >= d > 0 from x
    // (`slack`: the rounding margin of the caller's distances). 0 where the whole
    // box lies behind a reflecting x; Lambertian: proven; glossy: the cone bound above
    // where settings.glossyBound and the model allow it (proven), else the heuristic
    // with `glossyMargin`.
    // `inheritedGlossy`: for a glossy x, the factor to use instead of evaluating the BSDF.
    static Rgb reflectionTowardsBox(const CameraPathSurface& x, const Bsdf& bsdf, const Imath::Box3f& box, double d,
                                    double slack, const ClusterBoundSettings& settings,
                                    const Rgb* inheritedGlossy = nullptr);

private:
    // x's PreparedBsdf::coneBound over the cone of directions from x to `box`; empty
    // where the model has none there (the glossy heuristic applies).
    static std::optional<Rgb> coneBoundTowardsBox(const CameraPathSurface& x, const Imath::Box3f& box, double d,
                                                  double slack);
    // The bound at distance >= d (after the rounding slack; d <= 0: x may lie in the node).
    Rgb boundAt(int32_t node, const CameraPathSurface& x, double d, double slack, const Rgb* inheritedGlossy,
                Rgb* factor) const;
    // The rounding slack of distances between x and the node's box.
    static double slackOf(const Imath::Box3f& box, const Vec3& x);
    // The bound on f_p (see above) for the node's VRLs lighting x at distance >= d.
    double phaseBound(int32_t node, const Vec3& x, double slack, double d) const;

    const Scene& scene_;
    const LightTree& tree_;
    ClusterBoundSettings settings_;
    Rgb maxSigmaS_{0.0f};   // over all media: for nodes spanning several
    float maxPhase_ = 0.0f;  // largest phase-function value of any medium
    const LeafSegments* leaves_ = nullptr;  // shared or owned
    std::unique_ptr<LeafSegments> ownedLeaves_;
    const DirectionCones* cones_ = nullptr;  // with an HG medium: the tree's cones (shared or owned)
    std::unique_ptr<DirectionCones> ownedCones_;
};

}  // namespace vrl
