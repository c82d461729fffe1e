// SurfaceVplLight: the light of the surface VPLs (surface_vpl.h, deposited where
// light paths meet non-Dirac surfaces) in two transport parts of
// transport_integrator.h:
//   (b) the light that a surface x2 reflects by a non-Dirac lobe into a camera
//       segment (x1 in the medium), once per pixel against each camera segment:
//       every VPL (PlainSurfaceVplLight) or a Lightcut over their tree
//       (SurfaceVplCutLight, surface_vpl_lightcuts_estimator.h);
//   (a) the light x2 reflects by a non-Dirac lobe towards the camera path's
//       surface point x1, per camera sample: a stochastic cut of kSurfaceVplSamples
//       VPLs drawn down their tree (both classes; it needs the tree), the inverse
//       square clamped at a radius R (the path tracer keeps the rest).
// VPL k draws from vrlStream(streamKey, k) in plain and cut shading alike.
#pragma once

#include "render/core/rgb.h"
#include "render/core/rng.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"
#include "render/lightcuts/tree/surface_vpl_lights.h"
#include "render/vrl/camera_segment.h"
#include "render/vrl/surface_vpl_estimator.h"

#include <cstdint>
#include <memory>

namespace vrl {

class SurfaceVplLight {
public:
    // `lights` must outlive this; with a tree (prepareSurfaceVpls) part (a) can sample them.
    SurfaceVplLight(const Scene& scene, const SurfaceVplLights& lights, const CutSettings& cut);
    virtual ~SurfaceVplLight();
    SurfaceVplLight(const SurfaceVplLight&) = delete;
    SurfaceVplLight& operator=(const SurfaceVplLight&) = delete;

    // Part (b)'s share along `segment` (times its throughputBefore). A cut adds its
    // counters to `statistics` and measures its error against its total plus `otherLuminance`.
    virtual Rgb alongSegment(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                             float otherLuminance) const = 0;
    // Part (a)'s share at x, the inverse square clamped at `radius` > 0; needs the tree (hasTree).
    Rgb atSurface(const CameraPathSurface& x, float radius, Rng& rng) const;
    bool hasTree() const { return cut_ != nullptr; }

protected:
    const SurfaceVplLights& lights_;
    SurfaceVplEstimator estimator_;
    std::unique_ptr<SurfaceVplLightcutsEstimator> cut_;  // over their tree, where they have one
};

// (b) from every VPL (with their BSDFs prepared once where they have a tree: the same sum bit for bit).
class PlainSurfaceVplLight final : public SurfaceVplLight {
public:
    using SurfaceVplLight::SurfaceVplLight;
    Rgb alongSegment(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                     float otherLuminance) const override;
};

// (b) by a Lightcut over the VPLs' tree; `lights` must hold one.
class SurfaceVplCutLight final : public SurfaceVplLight {
public:
    SurfaceVplCutLight(const Scene& scene, const SurfaceVplLights& lights, const CutSettings& cut);
    Rgb alongSegment(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                     float otherLuminance) const override;
};

}  // namespace vrl
