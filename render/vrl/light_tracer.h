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
    // Also deposit a SurfaceVpl (surface_vpl.h) wherever a path meets a surface
    // that is not purely specular (Segments only). The paths, their random
    // numbers and their VRLs are the same either way. A VPL at the path's k-th
    // scattering vertex makes camera paths of k + 2 segments (to a medium point
    // x1, then to the camera); like the VRLs, it is kept only where the path
    // may still continue, which gives k + 2 <= maxDepth.
    bool surfaceVpls = false;
    // The most surface VPLs kept. Paths deposit them in order, 64 paths (a chunk) at
    // a time, until the next chunk's would pass the limit; from there on no path
    // deposits any, and the kept ones' flux is divided by the count of the paths
    // that deposited them (VrlSet::surfaceVplPaths): an unbiased estimate from fewer
    // paths, the same on any thread count. The first chunk is always kept (so that
    // a small limit gives a noisy part (b), never a black one). Bounds their memory
    // where paths meet many surfaces per VRL (a thin or small medium).
    uint64_t surfaceVplLimit = ~uint64_t(0);
};

// Throws std::invalid_argument if both lightPaths and targetVrls are 0.
VrlSet traceVrls(const Scene& scene, const LightTracingSettings& settings,
                 const std::function<void(double fraction)>& progress = {});

// A scattering vertex of a light path, for estimators that connect light paths
// to the camera (light_tracing_reference.h). Its weight: in a medium, the
// throughput arriving times sigma_s over the density the collision was sampled
// with (what the VPL of a real collision carries), so that the mean over paths
// of the sum of weight x g(v, direction) over their medium vertices is the
// integral over the volume and directions of sigma_s x incident radiance x g;
// on a surface, the throughput arriving (the BSDF is not applied yet).
struct LightPathVertex {
    Vec3 position;
    Vec3 direction;  // the direction the path travels in as it arrives
    Rgb weight{0.0f};
    int medium = -1;                      // the medium the path arrives through
    // Null for a medium vertex; else the walker's own hit record, valid only
    // during the visit call (copy it to keep it).
    const SurfaceHit* surface = nullptr;
    // Scattering vertices on the path up to this one, itself included: connected
    // to the camera, it makes a camera path of depth + 1 segments.
    int depth = 0;
};

// Walks the light paths of `settings` one at a time: path `index` uses the same
// random stream and the same emitter, collision, phase and BSDF sampling as
// traceVrls' path `index`, with weights not divided by the path count.
// Thread-safe (const); build one per render, not per path.
class LightPathWalker {
public:
    LightPathWalker(const Scene& scene, const LightTracingSettings& settings);

    // Calls `visit` at each vertex of path `index` where it scatters in a medium or
    // meets a surface that is not purely specular, up to the vertices whose camera
    // connection stays within settings.maxDepth (depth + 1 <= maxDepth). Deposits nothing.
    void walk(uint64_t index, const std::function<void(const LightPathVertex&)>& visit) const {
        trace(index, nullptr, &visit);
    }
    // Appends the VRLs (or VPLs) of path `index` to `out`, and its surface VPLs to
    // `surfaceOut` when settings.surfaceVpls, flux not yet divided by the path count.
    void deposit(uint64_t index, std::vector<Vrl>& out, std::vector<SurfaceVpl>* surfaceOut = nullptr) const {
        trace(index, &out, nullptr, surfaceOut);
    }

private:
    void trace(uint64_t index, std::vector<Vrl>* out, const std::function<void(const LightPathVertex&)>* visit,
               std::vector<SurfaceVpl>* surfaceOut = nullptr) const;

    const Scene& scene_;
    LightTracingSettings settings_;
    std::vector<char> areaEmitter_;  // by emitter index: emits from a surface
};

}  // namespace vrl
