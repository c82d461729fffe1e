#include "render/lightcuts/bounds/direction_cone.h"

#include <Imath/ImathVec.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace vrl {

namespace {

using V3d = Imath::V3d;
constexpr double kPiD = 3.14159265358979323846;

V3d toD(const Vec3& v) { return {v.x, v.y, v.z}; }
double angleD(const V3d& a, const V3d& b) { return std::atan2(a.cross(b).length(), a.dot(b)); }

DirectionCone sphere() { return {Vec3(0.0f, 0.0f, 1.0f), float(kPi)}; }

// Stores a half-angle in float, never below `angle` by more than float rounding
// (covered by the margin), and as the sphere from pi on.
float storedHalfAngle(double angle) {
    return angle >= kPiD ? float(kPi) : std::min(float(kPi), float(angle + kConeMarginRadians));
}

}  // namespace

double angleBetween(const Vec3& a, const Vec3& b) { return angleD(toD(a), toD(b)); }

DirectionCone DirectionCone::ofDirection(const Vec3& direction) {
    const V3d raw = toD(direction);
    if (!(raw.length() > 0.0) || !std::isfinite(raw.length())) return sphere();
    const V3d d = raw.normalized();
    return {Vec3(float(d.x), float(d.y), float(d.z)), storedHalfAngle(0.0)};
}

bool DirectionCone::contains(const Vec3& direction) const {
    return isSphere() || angleBetween(axis, direction) <= double(halfAngle);
}

DirectionCone DirectionCone::merge(const DirectionCone& a, const DirectionCone& b) {
    if (a.isSphere() || b.isSphere()) return sphere();
    const V3d axisA = toD(a.axis), axisB = toD(b.axis);
    const double alpha = a.halfAngle, beta = b.halfAngle;
    const double theta = angleD(axisA, axisB);
    if (theta + beta <= alpha) return a;
    if (theta + alpha <= beta) return b;
    const double spread = 0.5 * (alpha + theta + beta);
    if (spread >= kPiD) return sphere();
    // Turn axis a towards b by (spread - alpha) in their plane.
    V3d across = axisB - axisA * axisA.dot(axisB);
    const double acrossLength = across.length();
    if (!(acrossLength > 1e-12))  // (nearly) parallel axes: the wider cone, grown by theta; opposite: the sphere
        return axisA.dot(axisB) > 0.0 ? DirectionCone{a.axis, storedHalfAngle(std::max(alpha, beta) + theta)} : sphere();
    across /= acrossLength;
    const double turn = spread - alpha;
    V3d axis = axisA * std::cos(turn) + across * std::sin(turn);
    axis.normalize();
    const Vec3 stored(float(axis.x), float(axis.y), float(axis.z));
    // Re-measure against the stored (float) axis: both children inside, whatever the rounding.
    const V3d s = toD(stored);
    const double needed = std::max(angleD(s, axisA) + alpha, angleD(s, axisB) + beta);
    return {stored, storedHalfAngle(needed)};
}

bool DirectionCones::neededFor(const std::vector<HomogeneousMedium>& media) {
    return std::any_of(media.begin(), media.end(), [](const HomogeneousMedium& m) { return !m.phase().isIsotropic(); });
}

DirectionCones::DirectionCones(const LightTree& tree) {
    if (tree.empty()) return;
    const auto& nodes = tree.nodes();
    cones_.resize(nodes.size());
    // Post-order walk: children before their parent, whatever the node order.
    std::vector<std::pair<int32_t, bool>> walk{{tree.root(), false}};
    while (!walk.empty()) {
        auto [i, visited] = walk.back();
        walk.pop_back();
        const LightTreeNode& n = nodes[size_t(i)];
        if (n.isLeaf()) {
            cones_[size_t(i)] = DirectionCone::ofDirection(tree.vrls()[n.representative].direction);
        } else if (!visited) {
            walk.push_back({i, true});
            walk.push_back({n.right, false});
            walk.push_back({n.left, false});
        } else {
            cones_[size_t(i)] = DirectionCone::merge(cones_[size_t(n.left)], cones_[size_t(n.right)]);
        }
    }
}

}  // namespace vrl
