#include "render/lightcuts/tree/leaf_segments.h"

#include "render/core/segment_distances.h"

#include <utility>

namespace vrl {

LeafSegments::LeafSegments(const LightTree& tree) : tree_(tree) {
    if (tree.empty()) return;
    const auto& nodes = tree.nodes();
    first_.assign(nodes.size(), 0);
    for (auto& lane : lanes_) {
        lane.reserve(tree.vrls().size() + kSegmentLanesPadding);
        lane.clear();
    }
    // Post-order walk, left before right: leaves append their endpoints; an inner
    // node's first leaf is its left child's.
    std::vector<std::pair<int32_t, bool>> walk{{tree.root(), false}};
    while (!walk.empty()) {
        auto [i, visited] = walk.back();
        walk.pop_back();
        if (nodes[i].isLeaf()) {
            const Vrl& v = tree.vrls()[nodes[i].representative];
            first_[i] = uint32_t(lanes_[0].size());
            const Vec3 end = v.end();
            for (int axis = 0; axis < 3; ++axis) {
                lanes_[axis].push_back(v.origin[axis]);
                lanes_[3 + axis].push_back(end[axis]);
            }
            continue;
        }
        if (!visited) {
            walk.push_back({i, true});
            walk.push_back({nodes[i].right, false});
            walk.push_back({nodes[i].left, false});
        } else {
            first_[i] = first_[nodes[i].left];
        }
    }
    for (auto& lane : lanes_) lane.resize(lane.size() + kSegmentLanesPadding, 0.0f);
}

size_t LeafSegments::memoryBytes() const {
    size_t bytes = first_.capacity() * sizeof(uint32_t);
    for (const auto& lane : lanes_) bytes += lane.capacity() * sizeof(float);
    return bytes;
}

SegmentLanes LeafSegments::lanesOf(int32_t node) const {
    const size_t first = first_[node];
    return {lanes_[0].data() + first, lanes_[1].data() + first, lanes_[2].data() + first,
            lanes_[3].data() + first, lanes_[4].data() + first, lanes_[5].data() + first};
}

double LeafSegments::minDistanceToLine(int32_t node, const Vec3& origin, const Vec3& direction) const {
    return minDistanceLineSegments(origin, direction, lanesOf(node), count(node));
}

double LeafSegments::minDistanceToPoint(int32_t node, const Vec3& point) const {
    return minDistancePointSegments(point, lanesOf(node), count(node));
}

}  // namespace vrl
