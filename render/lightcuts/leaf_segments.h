// LeafSegments: the VRL segments of a light tree in depth-first leaf order, so
// that every node's VRLs are one contiguous range. The cluster bounds use it to
// take exact distances for small nodes (a box is loose around a few segments).
#pragma once

#include "render/core/geometry.h"
#include "render/lightcuts/light_tree.h"

#include <cstdint>
#include <span>
#include <vector>

namespace vrl {

class LeafSegments {
public:
    explicit LeafSegments(const LightTree& tree);

    // Start and end points of the VRLs below `node`.
    std::span<const Vec3> starts(int32_t node) const { return {&start_[first_[node]], count(node)}; }
    std::span<const Vec3> ends(int32_t node) const { return {&end_[first_[node]], count(node)}; }
    // The smallest distance from the line (origin, unit direction) to the VRLs below
    // `node`: distanceLineSegment's minimum, computed in SIMD lanes (segment_distances.h).
    double minDistanceToLine(int32_t node, const Vec3& origin, const Vec3& direction) const;

private:
    size_t count(int32_t node) const { return tree_.nodes()[node].vrlCount; }

    const LightTree& tree_;
    std::vector<Vec3> start_, end_;
    std::vector<float> lanes_[6];  // the same points as six float arrays (x, y, z of starts, of ends), padded
    std::vector<uint32_t> first_;  // per node: index of its first leaf
};

}  // namespace vrl
