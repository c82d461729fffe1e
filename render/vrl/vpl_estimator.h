// Plain VPLs (--method vpl, Vibert et al. 2019 Eq. 4 without a tree): VPLs sit at
// the medium collisions of the light paths (LightDeposit::Points). Along each camera
// segment, `distanceSamples` stratified distances u are drawn with density
// proportional to transmittance, normalised to the segment, and at each x(u) every
// VPL is gathered: sum_k Phi_k f(x_k) f(x_u) T_r(w_k) V / w_k^2. No clamping: the
// 1/w^2 singularity stays, as in the paper. The brute-force cost that VPL Lightcuts
// (lightcuts/cuts/vpl_lightcuts_estimator.h) is measured against; both share the
// distance sampling and the per-VPL term below.
#pragma once

#include "render/core/rgb.h"
#include "render/core/rng.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/vrl.h"

#include <functional>
#include <vector>

namespace vrl {

class Scene;

// VPL Lightcuts and plain VPLs: stratified distance samples per camera segment, each
// one cut (or gather) at a point of the segment. The one default for the renderer
// (RenderSettings), the integrator and the VPL estimators.
inline constexpr int kDefaultVplDistanceSamples = 32;

// Plain VPLs (--method vpl): the same distance samples, each gathering every
// VPL (no tree): the brute-force cost VPL Lightcuts is measured against.
class VplEstimator {
public:
    VplEstimator(const Scene& scene, const std::vector<Vrl>& vpls,
                 int distanceSamples = kDefaultVplDistanceSamples);
    Rgb estimate(const CameraSegment& segment, Rng& rng) const;

private:
    const Scene& scene_;
    const std::vector<Vrl>& vpls_;
    int distanceSamples_;
};

// The shared distance sampling: `distanceSamples` stratified u on the segment
// with density proportional to exp(-sigma u) (sigma: the smallest channel's
// extinction, so every channel's T_r(u) / p(u) stays bounded), each weighted by
// T_r(u) / (p(u) n) and multiplied by gather(x(u)); times sigma_s and throughputBefore.
Rgb integrateAlongSegment(const Scene& scene, const CameraSegment& segment, int distanceSamples, Rng& rng,
                          const std::function<Rgb(const Vec3& x)>& gather);

// One VPL's term of Eq. 4 at x (medium `medium`, light leaving towards the camera
// along `toCamera`): flux f(x_k) f(x) T_r(w) V / w^2; 0 at w = 0.
Rgb vplContribution(const Scene& scene, const Vrl& vpl, const Rgb& flux, const Vec3& x, const Vec3& toCamera,
                    int medium);

}  // namespace vrl
