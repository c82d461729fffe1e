// LeafSegments: the VRL segments of a light tree in depth-first leaf order, so
// that every node's VRLs are one contiguous range. The cluster bounds use it to
// take exact distances for small nodes (a box is loose around a few segments).
// Six float arrays (24 bytes per VRL), built once per integrator and shared by
// the (c) and (d) bounds.
#pragma once

#include "render/core/geometry.h"
#include "render/core/segment_distances.h"
#include "render/lightcuts/tree/light_tree.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace vrl {

class LeafSegments {
public:
    explicit LeafSegments(const LightTree& tree);

    // The VRLs below `node` are k in [first(node), first(node) + count(node)).
    size_t first(int32_t node) const { return first_[node]; }
    size_t count(int32_t node) const { return tree_.nodes()[node].vrlCount; }
    // The smallest distance from the line (origin, unit direction) to the VRLs below
    // `node`: distanceLineSegment's minimum, computed in SIMD lanes (segment_distances.h).
    double minDistanceToLine(int32_t node, const Vec3& origin, const Vec3& direction) const;
    // The smallest distance from `point` to the VRLs below `node`: distancePointSegment's
    // minimum, in SIMD lanes.
    double minDistanceToPoint(int32_t node, const Vec3& point) const;
    size_t memoryBytes() const;
    // Per VRL: six float coordinates and a first-leaf index for each of its two nodes.
    static constexpr size_t kBytesPerVrl = 6 * sizeof(float) + 2 * sizeof(uint32_t);
    // `shared` when given, else a new one kept in `owned`.
    static const LeafSegments* shareOrBuild(const LeafSegments* shared, const LightTree& tree,
                                            std::unique_ptr<LeafSegments>& owned) {
        if (shared) return shared;
        owned = std::make_unique<LeafSegments>(tree);
        return owned.get();
    }

private:
    SegmentLanes lanesOf(int32_t node) const;  // the node's VRLs, from its first

    const LightTree& tree_;
    std::vector<float> lanes_[6];  // x, y, z of the starts, of the ends; padded for the SIMD lanes
    std::vector<uint32_t> first_;  // per node: index of its first leaf
};

}  // namespace vrl
