// RenderSettings: everything a render is asked to do (the method and its
// parameters, built from a job spec by service/job's resolveJob), the limits
// they are checked against, what a render reports (RenderStatistics), and what
// follows from the settings alone: the layers of the image and whether the
// surface VPLs light parts (a), (b).
#pragma once

#include "render/integrators/transport_parts.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/render_method.h"
#include "render/vrl/vpl_estimator.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vrl {

// The most independent VRL sets a render takes (RenderSettings::vrlSets).
inline constexpr int kMaxVrlSets = 1024;

// The most distance samples per camera segment the VPL methods take
// (RenderSettings::vplDistanceSamples): each is one cut (or gather) per segment.
inline constexpr int kMaxVplDistanceSamples = 4096;

// RenderSettings::surfaceVplLimit: as many surface VPLs as the VRL target (or 4 per
// light path with lightPaths), what estimateLightMemoryBytes counts.
inline constexpr uint64_t kAutoSurfaceVpls = ~uint64_t(0);

// The most shading points per pixel side (RenderSettings::shadingPointsPerSide).
inline constexpr int kMaxShadingPointsPerSide = 16;

// The longest time limit a render takes (about 116 days): a guard against typos such as 1e30.
inline constexpr double kMaxTimeLimitSeconds = 1e7;

struct RenderSettings {
    RenderMethod method = RenderMethod::Path;
    // Per pixel: the path tracer's samples, the virtual-light methods' for their parts sampled
    // per camera sample (PartEstimators::perSample); with a time limit: the cap.
    int samplesPerPixel = 1;
    // > 0: a progressive render: passes of 1, 2, 4, ... samples per pixel over the
    // whole image until this many seconds of shading (after light preparation)
    // have passed or samplesPerPixel is reached; the image holds the completed passes.
    double timeLimitSeconds = 0.0;
    uint64_t seed = 0;
    bool jitter = false;  // false: rays through pixel centres (the paper's setting)
    int maxDepth = -1;    // Mitsuba meaning (see path_tracer.h)
    int tileSize = 16;
    // the virtual-light methods (MethodReads says which reads what)
    TransportSelection transports;
    uint64_t vrlCount = 100000;  // target VRLs (whole light paths are kept)
    uint64_t lightPaths = 0;     // if > 0: trace exactly this many light paths instead
    int vrlSamples = 1;          // (u, v) samples per VRL and camera segment
    // the light-tree methods
    CutSettings cut;             // error threshold, maximum cut, bound parameters
    int vplDistanceSamples = kDefaultVplDistanceSamples;  // vpl, vpl-lightcuts: stratified distance samples per camera segment
    uint32_t partitionSize = 2048;  // light tree: VRLs per partition of the median-split phase
    // vrl-stochastic only: independent VRL sets of vrlCount VRLs each (own light-tracing
    // streams, own trees); camera sample s uses set s mod vrlSets, so the image converges
    // to the true transport rather than to one set's. Set 0 is the set of vrlSets = 1:
    // with one sample per pixel the image does not depend on vrlSets.
    int vrlSets = 1;
    // vrl, vrl-lightcuts: the most surface VPLs (part (b)'s surface light), deposited by
    // the first light paths until the limit (LightTracingSettings::surfaceVplLimit:
    // fewer paths make (b) noisier, not darker). 0: none, part (b) path-samples its
    // surface light as vrl-stochastic does. kAutoSurfaceVpls: see there.
    uint64_t surfaceVplLimit = kAutoSurfaceVpls;
    // Methods that shade (c), (d) and (b)'s surface VPLs once per pixel (vrl, vrl-lightcuts,
    // vpl, vpl-lightcuts): at K x K points of the pixel (K this), each in its stratum
    // (jittered, or its centre without jitter) from its own stream, averaged. One point
    // leaves those parts' noise between seeds mostly the pixel's footprint (edges,
    // textures); K x K points cost K^2 times those parts.
    int shadingPointsPerSide = 1;
};

struct RenderStatistics {
    double seconds = 0.0;  // shading (after light tracing)
    uint64_t cameraSamples = 0;
    int samplesPerPixel = 0;  // of the image (a progressive render: of its completed passes)
    int passes = 0;           // sample passes in the image (sample_passes.h)
    // the virtual-light methods
    uint64_t vrlCount = 0;    // over all VRL sets
    uint64_t lightPaths = 0;  // over all VRL sets
    int vrlSets = 0;          // traced sets (RenderSettings::vrlSets; 0 when none)
    size_t vrlBytes = 0;
    double tracingSeconds = 0.0;
    // the light-tree methods
    double treeSeconds = 0.0;
    size_t treeBytes = 0;
    double meanEvaluated = 0.0, meanIntersected = 0.0, meanCutSize = 0.0;  // per pixel, part (d)
    double surfaceMeanEvaluated = 0.0, surfaceMeanIntersected = 0.0, surfaceMeanCutSize = 0.0;  // part (c)
    double meanImportance = 0.0, surfaceMeanImportance = 0.0;  // vrl-stochastic: importances per pixel and sample
    uint64_t surfaceVplCount = 0;  // surface VPLs (part (b)), over the kept ones
    uint64_t surfaceVplPaths = 0;  // the light paths that deposited them (all unless the limit was reached)
    double surfaceVplMeanEvaluated = 0.0, surfaceVplMeanIntersected = 0.0, surfaceVplMeanCutSize = 0.0;  // their cut
    float surfaceVplRadius = 0.0f;  // part (a)'s clamp radius R (0: (a) takes no light from them)
    uint64_t boundExceeded = 0, boundedEstimates = 0;  // inner-node estimates above their bound, (c) and (d)
};

// Called from worker threads with the fraction done of a phase ("light tracing",
// "rendering"); must be thread-safe.
using ProgressCallback = std::function<void(const char* phase, double fraction)>;

// Checks the settings; throws std::invalid_argument for a non-positive sample
// count, a negative error threshold, a negative or non-finite time limit,
// vplDistanceSamples outside [1, kMaxVplDistanceSamples], or vrlSets outside
// [1, kMaxVrlSets] or above 1 for another method than vrl-stochastic.
void validateRenderSettings(const RenderSettings& settings);

// Whether `settings` take light from surface VPLs: a method with a surface-VPL kind
// (vrl, vrl-lightcuts) with part (a) or (b) selected and a surface VPL limit above 0.
bool usesSurfaceVpls(const RenderSettings& settings);
// They light part (b)'s medium-then-surface light / part (a)'s surface-to-surface
// light (sampled per camera sample down their tree, transport_integrator.h).
bool surfaceVplsLightSingle(const RenderSettings& settings);
bool surfaceVplsLightSurfaces(const RenderSettings& settings);
// settings.surfaceVplLimit with kAutoSurfaceVpls resolved.
uint64_t surfaceVplLimit(const RenderSettings& settings);

// Names of the layers after the image that `settings` produce: the selected parts
// ("surface", ...), "single-vpl" where the surface VPLs light part (b), then the
// cuts' counters (render_method.h); throws like validateRenderSettings.
std::vector<std::string> renderLayerNames(const RenderSettings& settings);

}  // namespace vrl
