// Light tracing into short VRLs (Vibert et al. 2019 §4, "null collision
// transmittance"). Paths leave emitters chosen in proportion to power; inside a
// medium each segment between consecutive collisions becomes one Vrl with the
// path's throughput before it. Collisions are sampled against the majorant
// max(sigma_t) and split into real scattering and null events (spectral
// tracking), so chromatic media stay unbiased with constant-flux VRLs; in grey
// media there are no null events. Paths scatter in media (phase sampling) and
// on diffuse surfaces, up to maxDepth, with unbiased Russian roulette.
// Path i always uses the random stream (seed, i): results do not depend on
// the thread count.
#pragma once

#include "render/scene/scene.h"
#include "render/vrl/vrl.h"

#include <cstdint>
#include <functional>

namespace vrl {

// What light tracing deposits: short VRLs (every collision-free stretch of a
// path in a scattering medium), or VPLs for the VPL Lightcuts baseline.
enum class LightDeposit {
    Segments,
    // One VPL at every collision sampled in a scattering medium (real or null),
    // stored as a Vrl of length 0 at the collision, `direction` the path's
    // direction before it, flux = (flux of the segment ending there) x
    // sigma_s / majorant: the collision estimator of the same segment's VRL
    // integral, so VPLs and VRLs of one path estimate the same light.
    Points,
};

struct LightTracingSettings {
    LightDeposit deposit = LightDeposit::Segments;
    uint64_t lightPaths = 0;  // trace exactly this many paths, or (if 0) ...
    uint64_t targetVrls = 100000;  // ... whole batches of paths until this many VRLs
    // Mitsuba's maxDepth for the full camera path. A VRL that is the j-th
    // segment of its light path is kept if j + 2 <= maxDepth (two more segments
    // reach the camera); -1 = unlimited.
    int maxDepth = -1;
    uint64_t seed = 0;
    int rouletteDepth = 5;
};

// Throws std::invalid_argument if both lightPaths and targetVrls are 0.
VrlSet traceVrls(const Scene& scene, const LightTracingSettings& settings,
                 const std::function<void(double fraction)>& progress = {});

}  // namespace vrl
