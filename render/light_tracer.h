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

#include "render/scene.h"
#include "render/vrl.h"

#include <cstdint>
#include <functional>

namespace vrl {

struct LightTracingSettings {
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
