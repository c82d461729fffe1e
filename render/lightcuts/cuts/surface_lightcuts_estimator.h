// Lightcuts over VRLs for VRL-lit surfaces (part (c), transport_parts.h): for a
// surface point x the camera sees, walk a cut through the same light tree as
// part (d). Each node in the cut is estimated by its representative VRL with
// the cluster flux Phi_C (VrlSurfaceEstimator); the node with the largest
// SurfaceClusterBound is refined while that bound exceeds errorThreshold x
// (luminance of the running total plus the pixel's other parts: (c) is often a
// small share of a surface pixel, and the paper's error is relative to the
// pixel). A node whose box holds x has no bound and is
// refined without being estimated (#Inter); leaves are single VRLs.
// Over interleaved points (interleaved_points.h) each node is estimated at its
// representative's point and bounded by the largest of its bounds at the points.
#pragma once

#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/bounds/surface_cluster_bound.h"
#include "render/vrl/interleaved_points.h"
#include "render/vrl/vrl_surface_estimator.h"

#include <array>
#include <cstdint>

namespace vrl {

class SurfaceLightcutsEstimator {
public:
    // `cones`, `leaves`: the tree's DirectionCones and LeafSegments, shared with the medium cut (optional).
    SurfaceLightcutsEstimator(const Scene& scene, const LightTree& tree, const VrlSurfaceEstimator& estimator,
                              CutSettings settings, const DirectionCones* cones = nullptr,
                       const LeafSegments* leaves = nullptr);

    // Part (c) at x from every VRL of the tree. VRL k draws from vrlStream(streamKey, k)
    // as in plain VRL shading, so a cluster's estimate is its representative's plain sample rescaled.
    // The threshold applies to the cut's total plus `otherLuminance`, the luminance of
    // the pixel's other parts (cut_walk.h).
    Rgb estimate(const CameraPathSurface& x, uint64_t streamKey, CutStatistics& statistics,
                 float otherLuminance = 0.0f) const;
    // The same over interleaved points: node n estimated at points.at(its representative)
    // and bounded by the largest of its bounds at the points present, so every estimate is
    // held against a bound that holds where it is made. The query crosses a node where
    // cutPoint(points) lies in its box.
    Rgb estimate(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                 float otherLuminance = 0.0f) const;
    // The point the crossing test is made at: the present point with the largest bound of
    // the root; null when none is present. Depends on the points, not on o.
    const CameraPathSurface* cutPoint(const InterleavedPoints& points) const;

private:
    // cutPoint among the n different points of `distinct` (InterleavedPoints::distinct): its index.
    uint32_t cutPointAmong(const std::array<const CameraPathSurface*, InterleavedPoints::kMaxPoints>& distinct,
                           uint32_t n) const;

    const LightTree& tree_;
    const VrlSurfaceEstimator& estimator_;
    CutSettings settings_;
    SurfaceClusterBound bound_;
};

}  // namespace vrl
