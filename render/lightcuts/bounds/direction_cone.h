// DirectionCone: a set of unit directions {d : angle(d, axis) <= halfAngle}, and
// DirectionCones: one per light-tree node, bounding the directions of its VRLs.
// The HG cluster bound (cluster_bound.h) uses them: Henyey-Greenstein phase
// functions are monotone in the cosine of the scattering angle, so their
// extremes over a cone of directions sit at its nearest and farthest angles.
//
// Contract: every VRL direction below a node lies in the node's cone; the cones
// are conservative through rounding (angles in double, a margin of
// kConeMarginRadians added at each merge and to each leaf; a margin grows with
// depth only, so about 1e-4 rad at depth 60). A half-angle of pi is the whole
// sphere. Built in O(N) from the tree, bottom-up, on the side that needs it (the
// cluster bound of a scene with an anisotropic medium): it is derived data, so
// the tree's serialised form does not carry it and isotropic scenes never
// allocate it.
//
// Merge (the smallest cone around two cones, as in Estevez-Conty 2018): with
// theta the angle between the axes, a cone containing the other is kept; else
// the new half-angle is (alpha + theta + beta) / 2 and the axis turns from a
// towards b by (new half-angle - alpha) in their plane; a half-angle >= pi, or
// opposite axes, give the whole sphere. The merged half-angle is then
// re-measured against both inputs (angle(axis, a) + alpha, angle(axis, b) +
// beta, the larger), so the rotation's rounding cannot leave a child outside.
#pragma once

#include "render/core/geometry.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/media/homogeneous_medium.h"

#include <memory>
#include <vector>

namespace vrl {

inline constexpr double kConeMarginRadians = 2e-6;

// Angle between two nonzero vectors in [0, pi], in double (atan2 of |a x b| and
// a.b: accurate near 0 and pi, where acos is not).
double angleBetween(const Vec3& a, const Vec3& b);

struct DirectionCone {
    Vec3 axis{0.0f, 0.0f, 1.0f};  // unit
    float halfAngle = 0.0f;       // radians, [0, pi]; pi: every direction

    static DirectionCone ofDirection(const Vec3& direction);
    static DirectionCone merge(const DirectionCone& a, const DirectionCone& b);
    bool isSphere() const { return halfAngle >= float(kPi); }
    // Whether `direction` (nonzero) lies in the cone (exact test in double, no margin).
    bool contains(const Vec3& direction) const;
};

class DirectionCones {
public:
    DirectionCones() = default;
    explicit DirectionCones(const LightTree& tree);

    const DirectionCone& operator[](int32_t node) const { return cones_[size_t(node)]; }
    static constexpr size_t kBytesPerVrl = 2 * sizeof(DirectionCone);  // a cone per node, two nodes per VRL
    // `shared` if given, else cones built into `owned`: what a bound keeps a pointer to.
    static const DirectionCones* shareOrBuild(const DirectionCones* shared, const LightTree& tree,
                                              std::unique_ptr<DirectionCones>& owned) {
        if (shared) return shared;
        owned = std::make_unique<DirectionCones>(tree);
        return owned.get();
    }
    // Whether a scene's bounds need cones: some medium is anisotropic.
    static bool neededFor(const std::vector<HomogeneousMedium>& media);

private:
    std::vector<DirectionCone> cones_;
};

}  // namespace vrl
