// SurfaceGatherer: part (c) of transport_integrator.h, a surface point x1 the
// camera path reaches lit by the VRLs (light that scattered in a medium last),
// at one point or interleaved over several points of a pixel
// (interleaved_points.h). One class per estimator (SurfaceGathererKind, built
// by makeGatherers): plain VRLs, a VRL Lightcut (vrl_gatherers.h) and a
// stochastic cut (stochastic_vrl_gatherers.h).
#pragma once

#include "render/core/rgb.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/vrl/interleaved_points.h"

#include <cstdint>

namespace vrl {

class SurfaceGatherer {
public:
    virtual ~SurfaceGatherer() = default;
    // Part (c) at `points`: VRL k lights points.at(k) and draws from
    // vrlStream(streamKey, k); the gatherer's own draws come from vrlStream(streamKey, ~0u).
    // A cut adds its counters to `statistics` and measures its error against its
    // total plus `otherLuminance`, the luminance of the pixel's other parts.
    virtual Rgb gather(const InterleavedPoints& points, uint64_t streamKey, CutStatistics& statistics,
                       float otherLuminance) const = 0;
    // Whether it takes several interleaved points at once (once per pixel); false:
    // one point per call, the camera sample's own (a per-sample estimate).
    virtual bool interleaves() const = 0;
};

}  // namespace vrl
