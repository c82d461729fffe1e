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
// (less a few float steps, for the rounding of sample points), T_r(h_min)
// only for media whose boundary is convex (else 1), visibility and T_r(u)
// bounded by 1. A line through the node's box (h_min = 0) gives an infinite
// bound: the node is always refined. Henyey-Greenstein media have no such
// bound; theirs is the isotropic one times (1 + epsilon) (a heuristic).
#pragma once

#include "render/core/distance.h"
#include "render/lightcuts/cut_settings.h"
#include "render/lightcuts/leaf_segments.h"
#include "render/lightcuts/light_tree.h"
#include "render/vrl/camera_segment.h"

#include <vector>

namespace vrl {

class Scene;


class ClusterBound {
public:
    ClusterBound(const Scene& scene, const LightTree& tree, ClusterBoundSettings settings = {});

    // RGB bound for `node` against `segment`; +infinity when the
    // camera line passes through the node (h_min = 0).
    Rgb bound(int32_t node, const CameraSegment& segment, bool* lineCrossesNode = nullptr) const;
    // The minimum distance used for the node (box, or exact for small nodes).
    double minimumDistance(int32_t node, const CameraSegment& segment) const;

private:
    const Scene& scene_;
    const LightTree& tree_;
    ClusterBoundSettings settings_;
    Rgb maxSigmaS_{0.0f};  // over all media: for nodes spanning several
    LeafSegments leaves_;
};

}  // namespace vrl
