// Distances between points, lines, segments and boxes, in double precision:
// the geometric terms of the cluster bounds (lightcuts/) and of the VRL and
// VPL estimators. `direction` arguments are unit vectors; a line is infinite
// in both directions. An empty box is infinitely far from everything.
#pragma once

#include "render/core/geometry.h"

#include <Imath/ImathBox.h>

#include <utility>

namespace vrl {

// The largest angle a segment of length `segmentLength` subtends from a point at
// distance h from its line (foot point in the middle): 2 atan(S / (2 h)); pi at h = 0.
double maxSubtendedAngle(double segmentLength, double h);
// Distance between the infinite line (origin, unit direction) and a box / a segment [a, b].
double distanceLineBox(const Vec3& origin, const Vec3& direction, const Imath::Box3f& box);
double distanceLineSegment(const Vec3& origin, const Vec3& direction, const Vec3& a, const Vec3& b);
// Distances from a box to the segment [origin, origin + length direction] and to
// its whole line, exactly: the squared distance to the box is a convex piecewise
// quadratic in the line's parameter (one piece between consecutive slab
// crossings); the piece where its slope turns non-negative holds the line's
// minimiser t*, and the segment's is t* clamped to [0, length]. Infinite for an empty box.
struct SegmentBoxDistances {
    double segment = 0.0, line = 0.0;
};
SegmentBoxDistances distancesSegmentBox(const Vec3& origin, const Vec3& direction, double length,
                                        const Imath::Box3f& box);
// Distance from a point to a box (0 inside it).
double distancePointBox(const Vec3& point, const Imath::Box3f& box);
// Smallest and largest of n.(q - x) over the points q of the box (n need not be
// unit): the range of signed distances from the plane through x with normal n.
std::pair<double, double> signedDistanceRange(const Imath::Box3f& box, const Vec3& n, const Vec3& x);
// Distance from a point to the segment [a, b].
double distancePointSegment(const Vec3& point, const Vec3& a, const Vec3& b);

}  // namespace vrl
