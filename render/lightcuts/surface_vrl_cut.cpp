#include "render/lightcuts/surface_vrl_cut.h"

#include "render/lightcuts/cut_walk.h"
#include "render/lightcuts/vrl_cut.h"

#include <algorithm>
#include <array>
#include <limits>

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
    return estimate(InterleavedPoints::single(x), streamKey, statistics, otherLuminance);
}

const CameraPathSurface* SurfaceLightcutsEstimator::cutPoint(const InterleavedPoints& points) const {
    const CameraPathSurface* best = nullptr;
    float most = -1.0f;
    for (uint32_t q = 0; q < points.count; ++q) {
        const CameraPathSurface* p = points.points[q];
        if (!p) continue;
        if (points.count == 1 || tree_.empty()) return p;
        bool inside = false;
        const float root = luminance(bound_.bound(tree_.root(), *p, &inside));
        const float key = inside || !(root >= 0.0f) ? std::numeric_limits<float>::infinity() : root;
        if (key > most) best = p, most = key;
    }
    return best;
}

Rgb SurfaceLightcutsEstimator::estimate(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                                        float otherLuminance) const {
    if (tree_.empty()) return Rgb(0.0f);
    const CameraPathSurface* cut = cutPoint(points);
    if (!cut) return Rgb(0.0f);
    const CameraPathSurface& x = *cut;
    struct Visitor {
        const SurfaceLightcutsEstimator& self;
        const InterleavedPoints& points;
        const CameraPathSurface& x;  // the cut point: the crossing test (and, one point, every bound) is made here
        uint64_t streamKey;
        // VRL k (with `flux`) at its interleaved point, from its own stream.
        Rgb at(uint32_t k, const Rgb& flux) const {
            const CameraPathSurface* point = points.at(k);
            if (!point) return Rgb(0.0f);
            Vrl vrl = self.tree_.vrls()[k];
            vrl.flux = flux;
            Rng rng = vrlStream(streamKey, k);
            return self.estimator_.contribution(vrl, *point, rng);
        }
        Rgb leaf(int32_t i) const {
            const uint32_t k = self.tree_.nodes()[i].representative;
            return at(k, self.tree_.vrls()[k].flux);
        }
        // The distances of nodes left with a cheap bound, for their tightening (a
        // node's slot: its index modulo the size; a node found in another's slot
        // computes its distance again). Nearly every node at a glossy x is tightened.
        mutable std::array<int32_t, kDistanceSlots> distanceNode{};
        mutable std::array<double, kDistanceSlots> distance{};
        bool bound(int32_t i, const Rgb* inherited, Rgb& b, Rgb& factor, bool& tight) const {
            bool inside = false;
            if (points.count > 1) {
                // Interleaved: the node's VRLs go to any of the points, so its bound is the
                // largest of its bounds at them (each is Phi_C times the most a unit of flux
                // anywhere in the box gives that point, so the maximum bounds the node's light
                // wherever each VRL goes). The query crosses the node where the cut point lies
                // in its box; a box that holds another point is refined (infinite bound).
                b = self.bound_.bound(i, x, &inside);
                for (uint32_t q = 0; q < points.count && !inside; ++q) {
                    const CameraPathSurface* p = points.points[q];
                    if (!p || p == &x) continue;
                    bool within = false;
                    const Rgb at = self.bound_.bound(i, *p, &within);
                    if (within) {
                        b = Rgb(std::numeric_limits<float>::infinity());
                        break;
                    }
                    b = Rgb(std::max(b.x, at.x), std::max(b.y, at.y), std::max(b.z, at.z));
                }
                tight = true;
                return !inside;
            }
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
            return at(node.representative, node.clusterFlux);
        }
    };
    Visitor visitor{*this, points, x, streamKey, {}, {}};
    visitor.distanceNode.fill(-1);
    return walkCut(tree_, settings_, statistics, visitor, otherLuminance);
}

}  // namespace vrl
