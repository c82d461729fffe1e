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
// Zero only if Phi L sigma_s is 0 (then every VRL's estimate is 0): T_r is
// floored at kTransmittanceBoundFloor (1e-30) so that distance never makes an importance 0.
//
// Surface (c) (vrl_surface_estimator.h integrates Phi sigma_s f_p f_s |cos| T_r V / r^2
// over the VRL):
//   I = lum(Phi L sigma_s) max(cos_max, 1e-3) T_r(d_box) / max(d_box, f diag, tiny)^2,
// cos_max = max over the box of |n.(q - x)| / d (n: shading normal), as
// SurfaceClusterBound bounds it; a single VRL in an HG medium also gets 4 pi
// f_V towards x from its midpoint. Zero also when the box lies wholly behind a
// surface that only reflects (SurfaceClusterBound proves those VRLs give 0).
//
// Cost. A descent computes two importances per level, so they are computed in
// pairs from a compact copy of the tree made for this purpose: one 64-byte,
// cache-line-aligned record per inner node with both children's boxes (float),
// weights lum(Phi L sigma_s), node indices and media (one memory line per level
// instead of two 72-byte tree nodes; (N - 1) x 64 bytes, built only for
// vrl-stochastic). Per-query terms (the segment's, the surface point's) are
// computed once per query (prepare()). Being a heuristic, the importance may be
// approximate where that is cheaper, as long as it stays positive and finite:
// h_box is the distance from the line to the box after three alternating
// projections between them (an upper bound of the exact distance, equal to it
// when the line crosses the box; the slab test detects that exactly), and the
// angles use a polynomial arctangent (error < 1e-5 rad, positive for positive
// arguments).
#pragma once

#include "render/core/rgb.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/cuts/stochastic_cut.h"
#include "render/vrl/camera_segment.h"

#include <vector>

namespace vrl {

class Scene;

class VrlImportance {
public:
    static constexpr float kDefaultMinimumDistanceFraction = 0.05f;
    static constexpr size_t kBytesPerInnerNode = 64;  // sizeof(Pair): the memory it adds per VRL

    VrlImportance(const Scene& scene, const LightTree& tree,
                  float minimumDistanceFraction = kDefaultMinimumDistanceFraction);

    // The terms of one camera segment (part (d)) or surface point (part (c)).
    struct SegmentQuery {
        Vec3 origin, direction, absDirection;
        double length = 0.0, tinyBase = 0.0;
        int medium = -1;
        float sigmaTMin = 0.0f;  // > 0 only in a convex medium (T_r applies)
        bool anisotropic = false;  // the camera's medium is HG
    };
    struct SurfaceQuery {
        Vec3 position, facingNormal, shadingNormal;
        double tinyBase = 0.0;
        int medium = -1;
        bool reflectsOnly = true, changesMedium = false;
    };
    SegmentQuery prepare(const CameraSegment& segment) const;
    SurfaceQuery prepare(const CameraPathSurface& x) const;

    // The two children of the inner node `parent` and their importances for the query.
    ChildImportances children(int32_t parent, const SegmentQuery& query) const;
    ChildImportances children(int32_t parent, const SurfaceQuery& query) const;

    size_t memoryBytes() const { return pairs_.capacity() * sizeof(Pair); }

private:
    struct Child {
        float lo[3], hi[3];
        float weight;    // lum(Phi L sigma_s)
        int32_t packed;  // node index | (medium + 1) << indexBits_ (medium code 0: several or unknown)
    };
    struct alignas(64) Pair {
        Child child[2];
    };
    static_assert(sizeof(Pair) == kBytesPerInnerNode);

    int32_t nodeOf(const Child& c) const { return c.packed & indexMask_; }
    int mediumOf(const Child& c) const { return int(uint32_t(c.packed) >> indexBits_) - 1; }
    const Pair& pair(int32_t parent) const;
    double segmentImportance(const Child& c, const SegmentQuery& q) const;
    double surfaceImportance(const Child& c, const SurfaceQuery& q) const;

    const Scene& scene_;
    const LightTree& tree_;
    float fraction_;
    int32_t leafCount_ = 0;
    int indexBits_ = 31;
    int32_t indexMask_ = 0x7fffffff;
    std::vector<Pair> pairs_;        // pairs_[parent - leafCount_]
    std::vector<float> sigmaTMin_;   // per medium: smallest channel of sigma_t
    std::vector<char> convex_, isotropic_;
};

}  // namespace vrl
