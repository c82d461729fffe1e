// render/lightcuts/: the paper's algorithm: the light tree over VRLs (or VPLs) and
// its serialisation, the cluster bound, the Lightcuts walk, and the VRL and VPL cuts.
//
// LightTree: a binary hierarchy over short VRLs (Vibert et al. 2019 §4,
// "Building the light tree"), stored in flat arrays. Leaves are single VRLs;
// an inner node clusters its children: bounding box of their segments, the
// summed flux x length (conserved), a representative VRL drawn from the
// children's representatives in proportion to (luminance of) flux x length,
// the cluster flux Phi_C = sum(Phi_k L_k) / L_rep (Eq. 7: the representative's
// estimator with flux Phi_C carries the cluster's flux x length), and the
// longest VRL length L_max.
//
// Hybrid build (parallel, deterministic: the same tree for the same input and
// seed whatever the thread count): recursive median splits along the x, y and
// z axes, keeping at each step the split whose child boxes overlap least, until
// a partition holds at most `partitionSize` VRLs; agglomerative clustering in
// each partition (Walter et al. 2008) merging the pair that minimises
// I_c E_c^2 (I_c: luminance of the merged flux x length, E_c: diagonal of the
// merged box), found exactly by the nearest-neighbour chain (the cost is
// reducible); then the partition roots are merged by the same rule. A global
// agglomerative build (partitionSize >= N) is the quality baseline.
// Cost: O(N log N) for the splits (each level a few streaming passes and one
// selection), O(N partitionSize) for the clustering, O(P^2) for the
// P <= 2N / partitionSize roots. Memory: the tree (VRLs and 2N - 1 nodes,
// allocated once) plus buildScratchBytesPerVrl() per VRL while it is built.
// `lightcuts_bench --build-only --vrls 10000000` times it at scale.
#pragma once

#include "render/core/rgb.h"
#include "render/vrl/vrl.h"

#include <Imath/ImathBox.h>

#include <cstdint>
#include <vector>

namespace vrl {

struct LightTreeNode {
    Imath::Box3f box;        // bounds every VRL segment below
    Rgb fluxLength{0.0f};    // sum of Phi_k L_k below (W m)
    Rgb clusterFlux{0.0f};   // Phi_C = fluxLength / length of the representative
    float maxLength = 0.0f;  // L_max
    uint32_t representative = 0;  // VRL index
    uint32_t vrlCount = 0;
    int32_t left = -1;   // child node indices; -1 for a leaf
    int32_t right = -1;
    int32_t medium = -1;  // the VRLs' medium, or -1 if they are in several

    bool isLeaf() const { return left < 0; }
};

struct LightTreeSettings {
    uint32_t partitionSize = 2048;  // VRLs per partition of the median-split phase
    uint64_t seed = 0;              // representative choice
    // Point clusters (VPL Lightcuts): the VRLs are VPLs of length 0 and every
    // weight is the flux itself (fluxLength holds the summed flux, clusterFlux
    // equals it), as in Walter et al. 2005.
    bool points = false;
};

class LightTree {
public:
    LightTree() = default;
    // Builds over `vrls` (copied in). Empty input gives an empty tree.
    static LightTree build(std::vector<Vrl> vrls, const LightTreeSettings& settings = {});
    // Memory build() needs per VRL beyond the tree it returns (bytes).
    static size_t buildScratchBytesPerVrl();
    // Reassembles a tree from its parts (deserialisation); throws std::invalid_argument
    // if the structure is inconsistent (bad indices, counts, a cycle).
    static LightTree fromParts(std::vector<Vrl> vrls, std::vector<LightTreeNode> nodes, int32_t root);

    const std::vector<Vrl>& vrls() const { return vrls_; }
    const std::vector<LightTreeNode>& nodes() const { return nodes_; }
    int32_t root() const { return root_; }  // -1 when empty
    bool empty() const { return root_ < 0; }
    size_t memoryBytes() const { return vrls_.capacity() * sizeof(Vrl) + nodes_.capacity() * sizeof(LightTreeNode); }

private:
    std::vector<Vrl> vrls_;
    std::vector<LightTreeNode> nodes_;  // leaves first (node i is VRL i), then inner nodes
    int32_t root_ = -1;
};

}  // namespace vrl
