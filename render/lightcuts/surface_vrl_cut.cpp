#include "render/lightcuts/surface_vrl_cut.h"

#include "render/lightcuts/cut_walk.h"
#include "render/lightcuts/vrl_cut.h"

#include <array>

namespace vrl {

namespace {
constexpr size_t kDistanceSlots = 512;  // the visitor's cache of distances (below)
}  // namespace

SurfaceLightcutsEstimator::SurfaceLightcutsEstimator(const Scene& scene, const LightTree& tree,
                                                     const VrlSurfaceEstimator& estimator, CutSettings settings,
                                                     const DirectionCones* cones, const LeafSegments* leaves)
    : tree_(tree), estimator_(estimator), settings_(settings), bound_(scene, tree, settings.bound, cones, leaves) {}

Rgb SurfaceLightcutsEstimator::estimate(const CameraPathSurface& x, uint64_t streamKey, CutStatistics& statistics,
                                        float otherLuminance) const {
    if (tree_.empty()) return Rgb(0.0f);
    struct Visitor {
        const SurfaceLightcutsEstimator& self;
        const CameraPathSurface& x;
        uint64_t streamKey;
        Rgb leaf(int32_t i) const {
            const uint32_t k = self.tree_.nodes()[i].representative;
            Rng rng = vrlStream(streamKey, k);
            return self.estimator_.contribution(self.tree_.vrls()[k], x, rng);
        }
        // The distances of nodes left with a cheap bound, for their tightening (a
        // node's slot: its index modulo the size; a node found in another's slot
        // computes its distance again). Nearly every node at a glossy x is tightened.
        mutable std::array<int32_t, kDistanceSlots> distanceNode{};
        mutable std::array<double, kDistanceSlots> distance{};
        bool bound(int32_t i, const Rgb* inherited, Rgb& b, Rgb& factor, bool& tight) const {
            bool inside = false;
            double d = 0.0;
            b = self.bound_.cheapBound(i, x, &inside, inherited, &factor, &tight, &d);
            if (!tight) distanceNode[size_t(i) % kDistanceSlots] = i, distance[size_t(i) % kDistanceSlots] = d;
            return !inside;
        }
        void tighten(int32_t i, Rgb& b, Rgb& factor) const {
            const size_t slot = size_t(i) % kDistanceSlots;
            b = self.bound_.bound(i, x, nullptr, &factor, distanceNode[slot] == i ? &distance[slot] : nullptr);
        }
        Rgb estimate(int32_t i) const {
            const LightTreeNode& node = self.tree_.nodes()[i];
            Vrl representative = self.tree_.vrls()[node.representative];
            representative.flux = node.clusterFlux;
            Rng rng = vrlStream(streamKey, node.representative);
            return self.estimator_.contribution(representative, x, rng);
        }
    };
    Visitor visitor{*this, x, streamKey, {}, {}};
    visitor.distanceNode.fill(-1);
    return walkCut(tree_, settings_, statistics, visitor, otherLuminance);
}

}  // namespace vrl
