#include "render/integrators/surface_vpl_light.h"

#include <stdexcept>

namespace vrl {

SurfaceVplLight::SurfaceVplLight(const Scene& scene, const SurfaceVplLights& lights, const CutSettings& cut)
    : lights_(lights), estimator_(scene) {
    if (!lights.tree.empty()) cut_ = std::make_unique<SurfaceVplLightcutsEstimator>(scene, lights, estimator_, cut);
}

SurfaceVplLight::~SurfaceVplLight() = default;

Rgb SurfaceVplLight::atSurface(const CameraPathSurface& x, float radius, Rng& rng) const {
    if (!cut_) throw std::logic_error("SurfaceVplLight::atSurface: the surface VPLs have no tree");
    CutStatistics unused;
    return cut_->sample(x, radius, kSurfaceVplSamples, rng, unused);
}

Rgb PlainSurfaceVplLight::alongSegment(const CameraSegment& segment, uint64_t streamKey, CutStatistics&,
                                       float) const {
    if (cut_) return cut_->sumAll(segment, streamKey);
    return sumOverSurfaceVpls(estimator_, lights_.vpls, segment, streamKey);
}

SurfaceVplCutLight::SurfaceVplCutLight(const Scene& scene, const SurfaceVplLights& lights, const CutSettings& cut)
    : SurfaceVplLight(scene, lights, cut) {
    if (!cut_) throw std::invalid_argument("SurfaceVplCutLight: the surface VPLs have no tree");
}

Rgb SurfaceVplCutLight::alongSegment(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                                     float otherLuminance) const {
    return cut_->estimate(segment, streamKey, statistics, otherLuminance);
}

}  // namespace vrl
