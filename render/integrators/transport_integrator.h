// render/integrators/: whole-image estimators: the reference volumetric path tracer
// and the four-part transport integrator that the virtual-light methods share.
//
// TransportIntegrator: the image as the sum of four transport parts (transport_parts.h).
// (a) path-traces from the first surface the camera ray reaches, with the
// camera segment's exact transmittance; (b) samples a point on the camera
// segment equiangularly towards a light and does next-event estimation there;
// (c) samples a point on the segment in proportion to transmittance, a
// direction by the phase function, and path-traces from the surface that
// direction reaches (exact transmittance in between, no emission there: (b)
// has it); (d) sums the VRL estimator over every VRL (plain VRLs, --method vrl),
// walks Lightcuts over a VRL tree (vrl-lightcuts), or gathers VPLs at distance
// samples, every one (vpl) or by Lightcuts over a VPL tree (vpl-lightcuts).
// Each part is estimated for paths its siblings leave out, so the parts add up
// to the reference path tracer's image. Camera paths continue through purely
// specular surfaces (camera_segment.h): parts (b)-(d) shade every medium
// segment of that path, and (a) takes the first other surface it reaches.
// With a finite maxDepth, the specular bounces count towards it in (a)-(c); part
// (d) does not know each VRL's depth and ignores them (a warning says so).
#pragma once

#include "render/integrators/path_tracer.h"
#include "render/integrators/transport_parts.h"
#include "render/lightcuts/light_tree.h"
#include "render/lightcuts/vpl_cut.h"
#include "render/lightcuts/vrl_cut.h"
#include "render/vrl/vrl.h"
#include "render/vrl/vrl_estimator.h"

#include <array>
#include <memory>

namespace vrl {

struct TransportIntegratorSettings {
    TransportSelection transports;
    int maxDepth = -1;
    int vrlSamples = 1;  // (u, v) samples per VRL and camera segment
    CutSettings cut;     // used when a light tree is given
    // The lights are VPLs: (d) is VPL Lightcuts over the tree, or plain VPLs without one.
    bool vpls = false;
    int vplDistanceSamples = 32;  // distance samples per camera segment (VPLs)
};

class TransportIntegrator {
public:
    // Part (d) sums every VRL of `vrls`, or, when `tree` is given, walks Lightcuts over it.
    TransportIntegrator(const Scene& scene, const VrlSet& vrls, const TransportIntegratorSettings& settings,
                  const LightTree* tree = nullptr);

    // Parts (a), (b), (c) for one camera ray: one sample each.
    std::array<Rgb, 4> samplePathParts(const Ray& cameraRay, Rng& rng) const;
    // Part (d) for one camera ray: every VRL (or a cut) against every camera segment.
    Rgb multipleScattering(const Ray& cameraRay, Rng& rng, CutStatistics* statistics = nullptr) const;

private:
    Rgb singleScattering(const CameraSegment& segment, Rng& rng) const;
    Rgb mediumToSurface(const CameraSegment& segment, Rng& rng) const;

    const Scene& scene_;
    const VrlSet& vrls_;
    TransportIntegratorSettings settings_;
    VolumetricPathTracer tracer_;
    VrlEstimator estimator_;
    const LightTree* tree_;
    std::unique_ptr<LightcutsEstimator> lightcuts_;
    std::unique_ptr<VplLightcutsEstimator> vplLightcuts_;
    std::unique_ptr<VplEstimator> plainVpls_;
};

}  // namespace vrl
