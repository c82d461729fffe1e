// The smallest distance from a line, or from a point, to many segments, in double
// SIMD lanes (Google Highway, run-time dispatch): the exact h_min of small
// light-tree nodes (ClusterBound::minimumDistance), the edges of distanceLineBox,
// and the exact distance from a surface point to a small node's VRLs
// (SurfaceClusterBound::minimumDistance). Per segment it is the arithmetic of
// distanceLineSegment, or distancePointSegment (render/core/distance.h), in the
// same order, without fused multiply-adds, so the result equals the scalar loop's
// bit for bit and the cluster bounds' margins are unchanged.
#pragma once

#include "render/core/geometry.h"

#include <cstddef>

namespace vrl {

// Segments k < count run from (ax, ay, az)[k] to (bx, by, bz)[k]; each array must be
// readable for kSegmentLanesPadding entries past count (lanes past count are ignored).
inline constexpr size_t kSegmentLanesPadding = 8;
struct SegmentLanes {
    const float *ax, *ay, *az, *bx, *by, *bz;
};
double minDistanceLineSegments(const Vec3& origin, const Vec3& direction, const SegmentLanes& segments, size_t count);
// min over k < count of distancePointSegment(point, a_k, b_k); infinity when count is 0.
double minDistancePointSegments(const Vec3& point, const SegmentLanes& segments, size_t count);

}  // namespace vrl
