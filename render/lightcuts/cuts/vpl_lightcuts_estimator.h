// VPL Lightcuts: the baseline the paper compares against (Vibert et al. 2019
// §6, after Walter et al. 2005). VPLs sit at the medium collisions of the light
// paths (LightDeposit::Points); a light tree with point clusters is built over
// them. Along each camera segment, `distanceSamples` stratified distances u are
// drawn with density proportional to transmittance, normalised to the segment
// (so a sample always lands on it); at each x(u) a Lightcut over the VPL tree
// gathers  sum_k Phi_k f(x_k) f(x_u) T_r(w_k) V / w_k^2  (Eq. 4), refining the
// node with the largest bound Phi_C f T_r(d_min) / d_min^2 (d_min: distance
// from x(u) to the node's box) while it exceeds errorThreshold x (luminance of
// the current gather). No clamping: the 1/w^2 singularity stays, as in the paper.
// The phase factor of the bound is 1/(4 pi)^2, times (1 + epsilon) in
// Henyey-Greenstein media: the same treatment as the VRL ClusterBound, so that
// the two Lightcuts differ only in their primitives.
#pragma once

#include "render/core/rng.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/vrl/vpl_estimator.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/vrl.h"

#include <vector>

namespace vrl {

class Scene;

class VplLightcutsEstimator {
public:
    // `tree` must be built with LightTreeSettings::points over VPLs (Vrls of length 0).
    VplLightcutsEstimator(const Scene& scene, const LightTree& tree, CutSettings settings,
                          int distanceSamples = kDefaultVplDistanceSamples);

    // Multiple scattering along `segment` (already multiplied by its throughputBefore).
    Rgb estimate(const CameraSegment& segment, Rng& rng, CutStatistics& statistics) const;

    // The gather at one point x of the segment's medium towards the camera
    // (propagation direction `toCamera`): the Lightcut estimate of the in-scattered
    // radiance before sigma_s(x). Public for tests.
    Rgb gather(const Vec3& x, const Vec3& toCamera, int medium, CutStatistics& statistics) const;
    // One VPL's exact term of the same sum (flux given separately for clusters).
    Rgb vplContribution(const Vrl& vpl, const Rgb& flux, const Vec3& x, const Vec3& toCamera, int medium) const;
    // Upper bound on any VPL of `node` (infinite when x lies in its box, less rounding).
    Rgb bound(int32_t node, const Vec3& x, int medium) const;

private:
    const Scene& scene_;
    const LightTree& tree_;
    CutSettings settings_;
    int distanceSamples_;
};

}  // namespace vrl
