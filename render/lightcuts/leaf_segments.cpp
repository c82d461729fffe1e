#include "render/lightcuts/leaf_segments.h"

#include <utility>

namespace vrl {

LeafSegments::LeafSegments(const LightTree& tree) : tree_(tree) {
    if (tree.empty()) return;
    const auto& nodes = tree.nodes();
    first_.assign(nodes.size(), 0);
    start_.reserve(tree.vrls().size());
    end_.reserve(tree.vrls().size());
    // Post-order walk, left before right: leaves append their endpoints; an inner
    // node's first leaf is its left child's.
    std::vector<std::pair<int32_t, bool>> walk{{tree.root(), false}};
    while (!walk.empty()) {
        auto [i, visited] = walk.back();
        walk.pop_back();
        if (nodes[i].isLeaf()) {
            const Vrl& v = tree.vrls()[nodes[i].representative];
            first_[i] = uint32_t(start_.size());
            start_.push_back(v.origin);
            end_.push_back(v.end());
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
}

}  // namespace vrl
