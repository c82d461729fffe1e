// Test helper: the nodes of a light tree with every node after its children
// (post-order from the root), without assuming the storage order. Checks that
// fold values up the tree (a node's largest per-light ratio from its children's)
// visit nodes in this order.
#pragma once

#include "render/lightcuts/tree/light_tree.h"

#include <utility>
#include <vector>

namespace vrl::test {

inline std::vector<int32_t> childrenBeforeParents(const LightTree& tree) {
    const auto& nodes = tree.nodes();
    std::vector<int32_t> order;
    std::vector<std::pair<int32_t, bool>> stack{{tree.root(), false}};
    while (!stack.empty()) {
        const auto [i, expanded] = stack.back();
        stack.pop_back();
        if (expanded || nodes[i].isLeaf()) {
            order.push_back(i);
            continue;
        }
        stack.push_back({i, true});
        stack.push_back({nodes[i].left, false});
        stack.push_back({nodes[i].right, false});
    }
    return order;
}

}  // namespace vrl::test
