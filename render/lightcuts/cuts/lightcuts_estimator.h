// Lightcuts over VRLs (Vibert et al. 2019 §4-5): for one camera segment, walk a
// cut through the light tree. Each node in the cut is estimated by its
// representative VRL carrying the cluster flux Phi_C; the node with the largest
// ClusterBound is refined (replaced by its children) while that bound exceeds
// errorThreshold x (luminance of the current total). A node whose box the camera
// line passes through has an infinite bound and is always refined, without
// being estimated. Leaves are single VRLs, estimated directly. maxCutSize is a
// safety valve on the number of nodes in the cut.
#pragma once

#include "render/lightcuts/bounds/cluster_bound.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/vrl_estimator.h"

#include <cstdint>

namespace vrl {

class LightcutsEstimator {
public:
    // `cones`, `leaves`: the tree's DirectionCones and LeafSegments, shared with the surface cut (optional).
    LightcutsEstimator(const Scene& scene, const LightTree& tree, const VrlEstimator& estimator, CutSettings settings,
                       const DirectionCones* cones = nullptr,
                       const LeafSegments* leaves = nullptr);

    // Multiple scattering from every VRL of the tree along `segment`. The sample of
    // VRL k comes from the stream (streamKey, k) (see vrlStream), as in plain VRL
    // shading, so a cluster's estimate is its representative's plain sample rescaled.
    // `otherLuminance`: what the pixel receives besides this segment's (d) (walkCut);
    // 0, the cut's own total alone is the error's reference, as in the paper.
    Rgb estimate(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                 float otherLuminance = 0.0f) const;

private:
    const LightTree& tree_;
    const VrlEstimator& estimator_;
    CutSettings settings_;
    ClusterBound bound_;
};

}  // namespace vrl
