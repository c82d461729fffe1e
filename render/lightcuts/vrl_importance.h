// VrlImportance: the importance of a light-tree node for a camera segment (part
// (d)) or a surface point (part (c)), which stochastic cuts (stochastic_cut.h)
// use to choose the cut and to draw one VRL under each cut node.
//
// It is a heuristic estimate of the node's contribution, not a bound; its only
// hard requirement is unbiasedness: it is 0 only where every VRL of the node
// contributes exactly 0, and finite everywhere (no forced refinement where the
// camera line crosses a box).
//
// Segment (d). A VRL's estimate (vrl_estimator.h) integrates
// Phi sigma_s f f T_r T_r V / w^2 over the VRL and the segment; for a point at
// distance h from the segment's line the integral over the segment of 1/w^2 is
// (theta_b - theta_a) / h, the angle the segment subtends over h (Conty
// Estevez & Kulla 2018 use it for ray segments). For the node:
//   I = lum(Phi L sigma_s) T_r(h_box) (theta_b - theta_a)(h, t) / h,
// h = max(distance from the line to the box, f x box diagonal, tiny): the
// clamp (f = minimumDistanceFraction) keeps crossed boxes finite; t is the
// foot point on the line, taken in the box's projection onto the line as close
// to the segment's middle as it gets (the angle is largest there). T_r(h_box)
// only in one convex medium (as ClusterBound). Henyey-Greenstein media multiply
// by (4 pi)^2 f_V f_U towards the line's point u in the middle of the subtended
// angle, from the box's centre (f_U: the camera side, for boxes smaller than
// half their distance to u, else 1; f_V: the VRL's own, for single VRLs only,
// else 1 — an inner node does not know its VRLs' directions); HG is positive
// everywhere, so the factor never makes an importance 0.
// Zero only if Phi L sigma_s is 0 (then every VRL's estimate is 0).
//
// Surface (c) (vrl_surface_estimator.h integrates Phi sigma_s f_p f_s |cos| T_r V / r^2
// over the VRL):
//   I = lum(Phi L sigma_s) max(cos_max, 1e-3) T_r(d_box) / max(d_box, f diag, tiny)^2,
// cos_max = max over the box of |n.(q - x)| / d (n: shading normal), as
// SurfaceClusterBound bounds it; a single VRL in an HG medium also gets 4 pi
// f_V towards x from its midpoint. Zero also when the box lies wholly behind a
// surface that only reflects (SurfaceClusterBound proves those VRLs give 0).
#pragma once

#include "render/core/rgb.h"
#include "render/lightcuts/light_tree.h"
#include "render/vrl/camera_segment.h"

namespace vrl {

class Scene;

class VrlImportance {
public:
    static constexpr float kDefaultMinimumDistanceFraction = 0.05f;

    VrlImportance(const Scene& scene, const LightTree& tree,
                  float minimumDistanceFraction = kDefaultMinimumDistanceFraction);

    double segment(int32_t node, const CameraSegment& segment) const;
    double surface(int32_t node, const CameraPathSurface& x) const;

private:
    double weight(const LightTreeNode& node) const;  // lum(Phi L sigma_s)
    // Anisotropic media: (4 pi)^2 f_V f_U towards the camera line's point at parameter u.
    double phaseFactor(int32_t node, const CameraSegment& segment, const Vec3& centre, double u) const;

    const Scene& scene_;
    const LightTree& tree_;
    float fraction_;
    Rgb maxSigmaS_{0.0f};
};

}  // namespace vrl
