#include "render/lightcuts/cuts/surface_lightcuts_estimator.h"

#include "render/lightcuts/cuts/cut_walk.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"

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
    std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints> distinct{};
    const uint32_t n = points.distinct(distinct);
    return n == 0 ? nullptr : distinct[cutPointAmong(distinct, n)];
}

uint32_t SurfaceLightcutsEstimator::cutPointAmong(
    const std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints>& distinct, uint32_t n) const {
    if (n == 1 || tree_.empty()) return 0;
    uint32_t best = 0;
    float most = -1.0f;
    for (uint32_t j = 0; j < n; ++j) {
        bool inside = false;
        const float root = luminance(bound_.bound(tree_.root(), *distinct[j], &inside));
        const float key = inside || !(root >= 0.0f) ? std::numeric_limits<float>::infinity() : root;
        if (key > most) best = j, most = key;
    }
    return best;
}

Rgb SurfaceLightcutsEstimator::estimate(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                                        float otherLuminance) const {
    if (tree_.empty()) return Rgb(0.0f);
    // The points the VRLs go to, the cut point first (one: every VRL goes to it or
    // nowhere, and its own bound holds for any subset of the node's VRLs).
    std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints> targets{};
    const uint32_t count = points.distinct(targets);
    if (count == 0) return Rgb(0.0f);
    std::swap(targets[0], targets[cutPointAmong(targets, count)]);
    // The distances of nodes left with a cheap bound, at each target, for their
    // tightening (a node's slot: its index modulo the size; a node found in another's
    // slot computes its distances again; read only where distanceNode names the node,
    // so left uninitialised). Nearly every node at a glossy x is tightened.
    std::array<int32_t, kDistanceSlots> distanceNode;
    distanceNode.fill(-1);
    std::array<std::array<double, InterleavedPoints::kMaxPoints>, kDistanceSlots> distance;
    struct Visitor {
        const SurfaceLightcutsEstimator& self;
        const InterleavedPoints& points;
        const std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints>& targets;
        uint32_t count;  // targets; targets[0] is the cut point x, where the crossing test is made
        uint64_t streamKey;
        std::array<int32_t, kDistanceSlots>& distanceNode;
        std::array<std::array<double, InterleavedPoints::kMaxPoints>, kDistanceSlots>& distance;
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
        // The node's bound: over interleaved points the node's VRLs go to any of the
        // targets, so it is the largest of its bounds at them (each is Phi_C times the
        // most a unit of flux anywhere in the box gives that point, so the maximum bounds
        // the node's light wherever each VRL goes). The query crosses the node where the
        // cut point x lies in its box; a box that holds another target has an infinite
        // bound (refined). Deferred: at a glossy point the cheap bound takes the factor
        // the node's parent passed down, the largest of the parent's factors at the
        // targets: at least the parent's own factor at this point, which bounds this
        // node's there (its directions lie among the parent's), so a proven factor stays
        // proven. The factor passed on is likewise the largest over the targets.
        bool bound(int32_t i, const Rgb* inherited, Rgb& b, Rgb& factor, bool& tight) const {
            std::array<double, InterleavedPoints::kMaxPoints> distances{};
            tight = true;
            for (uint32_t j = 0; j < count; ++j) {
                bool inside = false, pointTight = true;
                Rgb f(0.0f);
                const Rgb at = self.bound_.cheapBound(i, *targets[j], &inside, inherited, &f, &pointTight, &distances[j]);
                if (inside) {
                    if (j == 0) return false;  // crossed at x
                    // Another target in the box: refine. Its children inherit an infinite
                    // factor: at a glossy point their cheap bound is infinite, and made
                    // tight before they are refined.
                    b = factor = Rgb(std::numeric_limits<float>::infinity());
                    tight = true;
                    return true;
                }
                b = j == 0 ? at : componentMax(b, at);
                factor = j == 0 ? f : componentMax(factor, f);
                tight = tight && pointTight;
            }
            if (!tight) {
                const size_t slot = size_t(i) % kDistanceSlots;
                distanceNode[slot] = i, distance[slot] = distances;
            }
            return true;
        }
        void tighten(int32_t i, Rgb& b, Rgb& factor) const {
            const size_t slot = size_t(i) % kDistanceSlots;
            const bool cached = distanceNode[slot] == i;
            for (uint32_t j = 0; j < count; ++j) {
                Rgb f(0.0f);
                const Rgb at = self.bound_.bound(i, *targets[j], nullptr, &f, cached ? &distance[slot][j] : nullptr);
                b = j == 0 ? at : componentMax(b, at);
                factor = j == 0 ? f : componentMax(factor, f);
            }
        }
        Rgb estimate(int32_t i) const {
            const LightTreeNode& node = self.tree_.nodes()[i];
            return at(node.representative, node.clusterFlux);
        }
    };
    Visitor visitor{*this, points, targets, count, streamKey, distanceNode, distance};
    return walkCut(tree_, settings_, statistics, visitor, otherLuminance);
}

}  // namespace vrl
