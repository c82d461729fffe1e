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
    std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints> distinct{};
    const uint32_t n = points.distinct(distinct);
    if (n == 0) return nullptr;
    if (n == 1 || tree_.empty()) return distinct[0];
    const CameraPathSurface* best = nullptr;
    float most = -1.0f;
    for (uint32_t j = 0; j < n; ++j) {
        bool inside = false;
        const float root = luminance(bound_.bound(tree_.root(), *distinct[j], &inside));
        const float key = inside || !(root >= 0.0f) ? std::numeric_limits<float>::infinity() : root;
        if (key > most) best = distinct[j], most = key;
    }
    return best;
}

Rgb SurfaceLightcutsEstimator::estimate(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                                        float otherLuminance) const {
    if (tree_.empty()) return Rgb(0.0f);
    const CameraPathSurface* cut = cutPoint(points);
    if (!cut) return Rgb(0.0f);
    const CameraPathSurface& x = *cut;
    // The other points the VRLs go to (none: every VRL goes to x or nowhere, and x's
    // own bound holds for any subset of the node's VRLs).
    std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints> others{};
    uint32_t otherCount = 0;
    {
        std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints> distinct{};
        const uint32_t n = points.distinct(distinct);
        for (uint32_t j = 0; j < n; ++j)
            if (distinct[j] != cut) others[otherCount++] = distinct[j];
    }
    struct Visitor {
        const SurfaceLightcutsEstimator& self;
        const InterleavedPoints& points;
        const CameraPathSurface& x;  // the cut point: the crossing test (and, one point, every bound) is made here
        const std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints>& others;
        uint32_t otherCount;
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
        // The distances of nodes left with a cheap bound, at x and the other points, for
        // their tightening (a node's slot: its index modulo the size; a node found in
        // another's slot computes its distances again). Nearly every node at a glossy x is
        // tightened.
        mutable std::array<int32_t, kDistanceSlots> distanceNode{};
        mutable std::array<std::array<double, InterleavedPoints::kMaxPoints>, kDistanceSlots> distance{};
        const CameraPathSurface& point(uint32_t j) const { return j == 0 ? x : *others[j - 1]; }
        // The node's bound: over interleaved points the node's VRLs go to any of the
        // points, so it is the largest of its bounds at them (each is Phi_C times the
        // most a unit of flux anywhere in the box gives that point, so the maximum bounds
        // the node's light wherever each VRL goes). The query crosses the node where the
        // cut point x lies in its box; a box that holds another point has an infinite
        // bound (refined). Deferred: at a glossy point the cheap bound takes the factor
        // the node's parent passed down, the largest of the parent's factors at the
        // points: at least the parent's own factor at this point, which bounds this
        // node's there (its directions lie among the parent's), so a proven factor stays
        // proven. The factor passed on is likewise the largest over the points.
        bool bound(int32_t i, const Rgb* inherited, Rgb& b, Rgb& factor, bool& tight) const {
            std::array<double, InterleavedPoints::kMaxPoints> distances{};
            tight = true;
            for (uint32_t j = 0; j <= otherCount; ++j) {
                bool inside = false, pointTight = true;
                double d = 0.0;
                Rgb f(0.0f);
                const Rgb at = self.bound_.cheapBound(i, point(j), &inside, inherited, &f, &pointTight, &d);
                if (inside) {
                    if (j == 0) return false;  // crossed at x
                    // Another point in the box: refine. Its children inherit an infinite
                    // factor: at a glossy point their cheap bound is infinite, and made
                    // tight before they are refined.
                    b = factor = Rgb(std::numeric_limits<float>::infinity());
                    tight = true;
                    return true;
                }
                distances[j] = d;
                b = j == 0 ? at : Rgb(std::max(b.x, at.x), std::max(b.y, at.y), std::max(b.z, at.z));
                factor = j == 0 ? f : Rgb(std::max(factor.x, f.x), std::max(factor.y, f.y), std::max(factor.z, f.z));
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
            for (uint32_t j = 0; j <= otherCount; ++j) {
                Rgb f(0.0f);
                const Rgb at = self.bound_.bound(i, point(j), nullptr, &f, cached ? &distance[slot][j] : nullptr);
                b = j == 0 ? at : Rgb(std::max(b.x, at.x), std::max(b.y, at.y), std::max(b.z, at.z));
                factor = j == 0 ? f : Rgb(std::max(factor.x, f.x), std::max(factor.y, f.y), std::max(factor.z, f.z));
            }
        }
        Rgb estimate(int32_t i) const {
            const LightTreeNode& node = self.tree_.nodes()[i];
            return at(node.representative, node.clusterFlux);
        }
    };
    Visitor visitor{*this, points, x, others, otherCount, streamKey, {}, {}};
    visitor.distanceNode.fill(-1);
    return walkCut(tree_, settings_, statistics, visitor, otherLuminance);
}

}  // namespace vrl
