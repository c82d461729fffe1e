// The smallest distance from a line to many segments, in double SIMD lanes
// (Google Highway, run-time dispatch): the exact h_min of small light-tree
// nodes (ClusterBound::minimumDistance) and the edges of distanceLineBox. Per segment it is the arithmetic of
// distanceLineSegment (render/core/distance.h) in the same order, without fused
// multiply-adds, so the result equals the scalar loop's bit for bit and the
// cluster bounds' margins are unchanged.
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

}  // namespace vrl
