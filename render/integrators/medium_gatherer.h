// MediumGatherer: part (d) of transport_integrator.h, light that scatters in a
// medium, reaches the camera segment from another medium vertex, and scatters
// there towards the camera, gathered along one camera segment from the virtual
// lights. One class per estimator (MediumGathererKind, built by makeGatherers):
// plain VRLs, VRL Lightcuts, stochastic VRL Lightcuts (vrl_gatherers.h,
// stochastic_vrl_gatherers.h), plain VPLs and VPL Lightcuts (vpl_gatherers.h).
#pragma once

#include "render/core/rgb.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/vrl/camera_segment.h"

#include <cstdint>

namespace vrl {

class MediumGatherer {
public:
    virtual ~MediumGatherer() = default;
    // Part (d) along `segment` (in a scattering medium), times its throughputBefore.
    // Random streams: light k draws from vrlStream(streamKey, k) in plain and cut
    // shading alike, so the two differ by the cut's approximation alone; the
    // gatherer's own draws (distance samples, a stochastic cut's descents) come
    // from vrlStream(streamKey, ~0u). A cut adds its counters to `statistics` and
    // measures its error against its total plus `otherLuminance` (the pixel's
    // other parts; 0: its own total alone, as in the paper).
    virtual Rgb gather(const CameraSegment& segment, uint64_t streamKey, CutStatistics& statistics,
                       float otherLuminance) const = 0;
};

}  // namespace vrl
