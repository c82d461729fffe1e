// ClusterBound: an upper bound on the single-sample VRL estimate of a light-tree
// node for one camera segment (Vibert et al. 2019, Eq. 8-11), used to decide
// whether the cut must refine the node.
//
// Derivation (isotropic phase). With v drawn with p(v) = s/((A1-A0) h(v)) on the
// VRL (h(v): distance from v to the camera *line*, s = sin of the angle between
// the lines) and u equiangularly with p(u|v) w^2 = h(v)/(thetaB - thetaA), the
// h(v) factors cancel:  1/(w^2 p(v) p(u|v)) = (thetaB - thetaA) (A1 - A0)/s,
// and (A1 - A0)/s = integral of dv/h(v) over the VRL <= L / h_min (parallel
// lines: p(v) = 1/L gives the same). thetaB - thetaA, the angle the camera
// segment (length S) subtends from a point at distance h from its line, is at
// most 2 atan(S / (2 h)) (foot point in the middle) — the paper prints
// 2 atan(2h/S), which is inverted: it must tend to pi as S -> infinity. So
//   estimate <= Phi_C L_rep sigma_s(u) sigma_s(v) f^2 T_before T_r(h_min) theta_max / h_min,
// where Phi_C L_rep, the node's flux x length, is tighter than Eq. 11's Phi_C L_max
// (the representative carries the estimate) and also bounds the node's true
// contribution; h_min <= distance between the node's VRLs and the camera line
// (their box's, their segments' for small nodes, or optionally their bounding
// sphere's when it is far: ClusterBoundSettings::sphereDistanceBeyond; less a
// few float steps, for the rounding of sample points). Transmittance: in a
// medium whose boundary is convex, holding the node's VRLs,
// T(u) T_r(w) = exp(-sigma_t (u + w)) and u + w >= |origin - v| >= d_o, the
// distance from the segment's origin to the box (>= h_min), so it is bounded by
// T(d_o) (floored at kTransmittanceBoundFloor against underflow); elsewhere by 1, as is
// visibility. A line through the node's box (h_min = 0) gives an infinite
// bound: the node is always refined.
//
// Henyey-Greenstein media (HgBound::Cones, proven). Two things change: the
// phase product f(u) f(v) is no longer a constant, and u's angle is drawn from
// a mixture (VrlEstimator::kHgUniformWeight = w of the uniform angle, the rest
// a kHgBins-bin fit of f(u) f(v) at the bins' centres), so its pdf is
//   p(theta) = (w + (1 - w) kHgBins b_k / sum b) / span,  b_k the bin values.
// Ranges of the two scattering angles, about the camera line: with s the offset
// along omega from v's foot point to u and r v's distance to the line
// (h_min <= r <= the farthest point of the box's bounding sphere), toU's polar
// angle from omega has cos = s / sqrt(s^2 + r^2), monotone in s and (by s's sign)
// in r, so its range [theta1, theta2] follows from the box's extent along omega.
// The angle at u (between toU and c = -omega) is pi minus it. The VRL directions
// of the node lie in its DirectionCone (a, alpha) (direction_cone.h), so their
// polar angles lie in [theta_a - alpha, theta_a + alpha]; the angle between two
// directions is at least the difference of their polar angles and at most their
// sum (or 2 pi minus it): that brackets the angle at v. (A cone around the
// directions box -> segment, which keeps their azimuth, was tried: on the default
// scene it changed cut sizes by < 1% and cost 14% more time; camera segments
// cross the room, so it is mostly the whole sphere.) HG is monotone in the cosine
// (increasing for g > 0), so the largest product F and the smallest F_min come
// from the ends of these ranges.
// Every bin value is such a product, so kHgBins b_k / sum b >= b_k / F >= F_min / F.
// Also, within its bin the sample's angle is at most span / (2 kHgBins) from the
// bin centre's, and both scattering angles turn by at most that much; with
// |d ln HG / d psi| <= 3|g| / (1 - g^2) (at cos psi = 2g / (1 + g^2)),
// f(u) f(v) <= rho b_k, rho = exp((slope_u + slope_v) span / (2 kHgBins)). Then,
// for x = b_k in [F_min, F], f / p <= span min(F, rho x) / (w + (1 - w) x / F),
// largest at x = max(F_min, F / rho):
//   f(u) f(v) / p(theta) <= F span / (w + (1 - w) max(F_min / F, 1 / rho)).
// The isotropic derivation carried f^2 span: replace f^2 by this factor over span.
// Narrow ranges give about F; a short span about F (rho ~ 1); the worst case F / w. Margins: the angles widen by 2 slack / h_min + 1e-6 (rounded sample
// points), HG's denominators by 2e-6 either way (its float evaluation), rho by
// as much (1 + 6e-6 / (1 - |g|)^2 per phase) and 1e-4; a node in several media takes the extremes over their g. Isotropic scenes
// keep the isotropic path and build no cones. HgBound::Epsilon keeps the paper's
// heuristic: the isotropic bound times (1 + epsilon), exceeded by some estimates.
#pragma once

#include "render/core/distance.h"
#include "render/lightcuts/bounds/cluster_bound_settings.h"
#include "render/lightcuts/bounds/direction_cone.h"
#include "render/lightcuts/tree/leaf_segments.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/camera_segment.h"

#include <memory>
#include <vector>

namespace vrl {

class Scene;


class ClusterBound {
public:
    // `cones`: the tree's DirectionCones when the caller shares them between bounds
    // (TransportIntegrator); built here when needed and not given.
    ClusterBound(const Scene& scene, const LightTree& tree, ClusterBoundSettings settings = {},
                 const DirectionCones* cones = nullptr, const LeafSegments* leaves = nullptr);

    // RGB bound for `node` against `segment`; +infinity when the
    // camera line passes through the node (h_min = 0).
    Rgb bound(int32_t node, const CameraSegment& segment, bool* lineCrossesNode = nullptr) const;
    // The minimum distance used for the node (box, or exact for small nodes).
    double minimumDistance(int32_t node, const CameraSegment& segment) const;

private:
    // The factor replacing 1/(4 pi)^2 in the bound (see above).
    // span: the largest angle the segment subtends from the node (maxSubtendedAngle).
    double phaseFactor(int32_t node, const CameraSegment& segment, double h, double slack, double span) const;
    double hgConeFactor(int32_t node, const CameraSegment& segment, double h, double slack, double span) const;

    const Scene& scene_;
    const LightTree& tree_;
    ClusterBoundSettings settings_;
    Rgb maxSigmaS_{0.0f};  // over all media: for nodes spanning several
    bool allIsotropic_ = true;
    const LeafSegments* leaves_ = nullptr;  // shared or owned
    std::unique_ptr<LeafSegments> ownedLeaves_;
    // HgBound::Cones in a scene with an HG medium: the tree's cones (shared or owned); else null.
    const DirectionCones* cones_ = nullptr;
    std::unique_ptr<DirectionCones> ownedCones_;
};

}  // namespace vrl
