// Renderer: turns a Scene into an image with a chosen method, in parallel tiles
// (TBB). Camera sample s of pixel (x, y) draws from its own random stream,
// keyed by (seed, film pixel index, s), and the virtual-light parts evaluated
// once per pixel from (seed, film pixel index, ~0); the samples are taken and
// summed in passes (sample_passes.h). So the image is bit-identical whatever
// the thread count, tile size or order, or process that shades a tile, a crop
// window (camera.h) equals that window of the full film, and a progressive
// render (RenderSettings::timeLimitSeconds) that completed P passes equals the
// fixed render of 2^P - 1 samples. The phases are public so that the service can split them: the
// coordinator runs prepareLights once, workers run TileShader on leased tiles (and passes).
#pragma once

#include "render/image/image.h"
#include "render/integrators/transport_parts.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"
#include "render/sample_passes.h"
#include "render/sample_sums.h"
#include "render/scene/scene.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace vrl {

// Methods the renderer knows; `vrl render --method` takes their names (the one
// name table is methodName / parseRenderMethod; past the command line and the
// job spec, code compares RenderMethod values, never strings).
//   path: the volumetric path tracer (reference), one image
//   vrl:  the four transport parts, multiple scattering by plain VRLs; one layer per part
//   vrl-lightcuts: the same, parts (c) and (d) by cuts through a VRL light tree,
//         plus single-channel per-pixel layers "eval", "inter" and "cut" (statistics
//         of (d)'s cuts) and, with part (c) selected, "medium-surface-eval",
//         "medium-surface-inter", "medium-surface-cut" (those of (c)'s cuts)
//   vpl:  the four parts, multiple scattering by plain VPLs (every VPL at each of
//         the distance samples; the brute force VPL Lightcuts is measured against)
//   vrl-stochastic: stochastic VRL Lightcuts: parts (c) and (d) by stochastic cuts
//         of cut.stochasticCutSize nodes through the VRL light tree, one VRL drawn
//         under each node (lightcuts/cuts/stochastic_lightcuts_estimator.h): unbiased against plain
//         VRLs; estimated per camera sample, so --spp applies to (c) and (d) too.
//         Its counter layers are "eval", "importance", "cut" (and "medium-surface-eval",
//         "-importance", "-cut"): VRL estimates, node importances computed and cut
//         size, per pixel and camera sample.
//   vpl-lightcuts: the same layers as vrl-lightcuts, multiple scattering by VPL
//         Lightcuts (the paper's baseline, lightcuts/cuts/vpl_lightcuts_estimator.h)
// For vpl and vpl-lightcuts, vrlCount counts VPLs.
enum class RenderMethod { Path, Vrl, VrlLightcuts, VrlStochastic, Vpl, VplLightcuts };
inline constexpr std::array<RenderMethod, 6> kRenderMethods = {RenderMethod::Path,          RenderMethod::Vrl,
                                                               RenderMethod::VrlLightcuts,  RenderMethod::VrlStochastic,
                                                               RenderMethod::Vpl,           RenderMethod::VplLightcuts};
// The method a job renders when neither it nor its scene's <integrator> names
// one: the README's recommended method (the paper's, VRL Lightcuts).
inline constexpr RenderMethod kHeadlineMethod = RenderMethod::VrlLightcuts;

// "path", "vrl", "vrl-lightcuts", "vrl-stochastic", "vpl", "vpl-lightcuts".
std::string_view methodName(RenderMethod method);
// Every method's name, in kRenderMethods order (for the command line's choices).
std::vector<std::string> renderMethodNames();
// The method named `name`; throws std::invalid_argument naming it and the valid names.
RenderMethod parseRenderMethod(std::string_view name);

// The method deposits VPLs (points) rather than VRLs.
constexpr bool usesVpls(RenderMethod m) { return m == RenderMethod::Vpl || m == RenderMethod::VplLightcuts; }
// The method builds a light tree (VRL, stochastic VRL or VPL Lightcuts): it ships a tree, not a VRL set.
constexpr bool usesLightTree(RenderMethod m) {
    return m == RenderMethod::VrlLightcuts || m == RenderMethod::VrlStochastic || m == RenderMethod::VplLightcuts;
}
// The method renders the four transport parts with virtual lights (every method but path).
constexpr bool usesVirtualLights(RenderMethod m) { return m != RenderMethod::Path; }

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
    int samplesPerPixel = 1;  // path: per pixel; vrl: for parts (a)-(c); with a time limit: the cap
    // > 0: a progressive render: passes of 1, 2, 4, ... samples per pixel over the
    // whole image until this many seconds of shading (after light preparation)
    // have passed or samplesPerPixel is reached; the image holds the completed passes.
    double timeLimitSeconds = 0.0;
    uint64_t seed = 0;
    bool jitter = false;  // false: rays through pixel centres (the paper's setting)
    int maxDepth = -1;    // Mitsuba meaning (see path_tracer.h)
    int tileSize = 16;
    // vrl method
    TransportSelection transports;
    uint64_t vrlCount = 100000;  // target VRLs (whole light paths are kept)
    uint64_t lightPaths = 0;     // if > 0: trace exactly this many light paths instead
    int vrlSamples = 1;          // (u, v) samples per VRL and camera segment
    // vrl-lightcuts method
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
    // vrl method
    uint64_t vrlCount = 0;    // over all VRL sets
    uint64_t lightPaths = 0;  // over all VRL sets
    int vrlSets = 0;          // traced sets (RenderSettings::vrlSets; 0 when none)
    size_t vrlBytes = 0;
    double tracingSeconds = 0.0;
    // vrl-lightcuts method
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

// The per-image light work of a render (the coordinator's part in the service):
// the VRLs of the `vrl` method, or the light tree of `vrl-lightcuts` (which owns
// its VRLs). Empty for the path tracer and when neither part (c) nor (d) is selected.
// vrl-stochastic with vrlSets P > 1: `tree` is set 0's and moreTrees sets 1 ... P-1.
// Surface VPLs (part (b)'s surface light, vrl and vrl-lightcuts): `surfaceVpls`,
// with its own tree for vrl-lightcuts (surface_vpl_lightcuts_estimator.h).
struct RenderLights {
    VrlSet vrls;
    LightTree tree;
    std::vector<LightTree> moreTrees;
    SurfaceVplLights surfaceVpls;
};

// Whether `settings` take part (b)'s surface light from surface VPLs: vrl and
// vrl-lightcuts with part (b) selected and a surface VPL limit above 0.
bool usesSurfaceVpls(const RenderSettings& settings);
// They light part (b)'s medium-then-surface light / part (a)'s surface-to-surface
// light (sampled per camera sample down their tree, transport_integrator.h).
bool surfaceVplsLightSingle(const RenderSettings& settings);
bool surfaceVplsLightSurfaces(const RenderSettings& settings);
// settings.surfaceVplLimit with kAutoSurfaceVpls resolved.
uint64_t surfaceVplLimit(const RenderSettings& settings);
RenderLights prepareLights(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
                           RenderStatistics* statistics = nullptr);

// Peak memory of prepareLights for `settings` (0 when it prepares nothing): the
// target VRL (or VPL) count times the bytes of a light, with the light tracer's
// batch growth, plus the tree's nodes and build scratch for the tree methods,
// times the VRL sets.
// With --light-paths the count is not known in advance and this returns 0.
uint64_t estimateLightMemoryBytes(const RenderSettings& settings);

// Pixels [x0, x1) x [y0, y1) of the image.
struct TileRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    bool operator==(const TileRect&) const = default;
};
// The image cut into tileSize x tileSize tiles, row by row from the top left.
std::vector<TileRect> imageTiles(int width, int height, int tileSize);
// The embedded render's tile side for `threads` threads: tileSize, halved (to no less
// than kMinBalancedTileSize) while the image holds fewer than kTilesPerThread tiles per
// thread. Tiles differ in cost (a floor whose cuts reach the cap against a dark wall),
// and with a few tiles per thread the last heavy ones leave the other threads idle:
// staircase at 45x80 has 6 tiles of 32 pixels (the CLI's side), and two threads shaded
// it in 16.6-21.5 s against 24.9 s on one; in 60 tiles of 8, in 14.2-16.1 s (once 19.9). The image
// does not depend on it (renderer_test).
inline constexpr int kTilesPerThread = 16;
inline constexpr int kMinBalancedTileSize = 4;
int balancedTileSize(int width, int height, int tileSize, int threads);

// Stopping a render early (an interrupt): `requested` is polled from the
// light-tracing progress, before each tile and before each row of a tile. A
// tile stopped midway keeps its finished rows (the rest stay zero); when it
// fires during light preparation, render throws RenderInterrupted. A
// progressive render keeps its completed passes and drops the one stopped,
// unless it is the first (then its finished rows are kept, as above).
struct RenderStop {
    std::function<bool()> requested;
    bool operator()() const { return requested && requested(); }
};

// Layers of a tile or image, in order: the image itself, then the method's layers.
struct TileImages {
    std::vector<Image> layers;  // each tile-sized; layers[0] is the image
    uint64_t boundExceeded = 0, boundedEstimates = 0;
    bool interrupted = false;  // `stop` fired before the last row: only the first `rowsDone` rows are shaded
    int rowsDone = 0;
};

// Names of the layers after the image that `settings` produce ("surface", ...,
// "eval", "inter", "cut"); throws like validateRenderSettings.
std::vector<std::string> renderLayerNames(const RenderSettings& settings);

// Sample s of pixel (x, y) of a tile draws from the stream
// (seed, Rng::combine(camera.filmPixelIndex(x, y), s)) only.
// The once-per-pixel parts' stream: sample index kPixelLightsSample - m for shading point m.
inline constexpr uint64_t kPixelLightsSample = ~uint64_t(0);

// A tile's sample sums (sample_sums.h) and how far it got.
struct TileSums {
    SampleSums sums;
    bool interrupted = false;  // `stop` fired before the last row: only the first `rowsDone` rows are shaded
    int rowsDone = 0;
};

// Shades tiles (the worker's part), in image pixels (the crop window's, if
// any). Pixel (x, y) uses the streams of its film pixel only (above), so a
// tile's pixels equal those of a whole-image (and whole-film) render bit for bit.
// renderTile and shadeTile are const and thread-safe; `lights` must outlive the TileShader.
class TileShader {
public:
    TileShader(const Scene& scene, const RenderSettings& settings, const RenderLights& lights);
    ~TileShader();
    // Names of the layers after the image ("surface", ..., "eval", "inter", "cut").
    const std::vector<std::string>& layerNames() const { return layerNames_; }
    // Per layer (image first): 1 where it holds one value per pixel rather than a sum over samples.
    const std::vector<uint8_t>& layerPerPixel() const { return layerPerPixel_; }
    // The fixed render's tile: passes [0, passesFor(samplesPerPixel)) resolved.
    TileImages renderTile(const TileRect& tile, const RenderStop& stop = {}) const;
    // The sums of passes [firstPass, firstPass + passCount) folded in pass order
    // (sample_passes.h), the samples capped at samplesPerPixel; a range must
    // start at pass 0 or hold one pass (throws std::invalid_argument otherwise),
    // so that addPass of its result onto passes [0, firstPass) is the canonical fold.
    TileSums shadeTile(const TileRect& tile, int firstPass, int passCount, const RenderStop& stop = {}) const;

private:
    const Scene& scene_;
    RenderSettings settings_;
    std::vector<std::string> layerNames_;
    std::vector<uint8_t> layerPerPixel_;
    bool lightsPerSample_ = false;
    std::unique_ptr<class TransportIntegrator> integrator_;  // set 0's (and the path-sampled parts)
    std::vector<std::unique_ptr<class TransportIntegrator>> moreIntegrators_;  // sets 1 ... vrlSets - 1
    std::unique_ptr<class VolumetricPathTracer> tracer_;
};

// Whole-image layers (one per TileShader layer, image first) into an ImageSet,
// filling the cut statistics of `statistics` from the "eval", "inter", "cut" layers
// (which it marks single-channel).
ImageSet assembleImageSet(std::vector<Image> layers, const std::vector<std::string>& layerNames,
                          RenderStatistics* statistics = nullptr);

struct RenderInterrupted : std::runtime_error {
    RenderInterrupted() : std::runtime_error("interrupted before any tile was shaded") {}
};
// What a render finished: `covered` has one entry per pixel (row-major, 1 where
// the pixel was shaded: finished tiles and the finished rows of tiles stopped
// midway), for partial_image.h's markPartial; tilesDone counts whole tiles.
struct RenderCoverage {
    std::vector<uint8_t> covered;
    int tilesDone = 0, tilesTotal = 0;
    int rowsDone = 0;  // pixel rows shaded, over all tiles (0: nothing to keep)
    bool complete() const { return tilesDone == tilesTotal; }
};

// prepareLights, then every tile in parallel (TBB), then assembleImageSet.
// The vrl method returns the sum in .image and each selected part as a layer.
// With `stop`, tiles not started when it fires are skipped (zero) and
// `coverage`, if given, says which were finished. With a time limit, the
// passes run one after the other over the whole image (each in parallel
// tiles) until the limit, `stop` or the sample cap; statistics->passes and
// ->samplesPerPixel say what the image holds (a first pass cut short leaves a
// partial image of 1 sample per pixel and passes 0, as an interrupt does).
ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
                RenderStatistics* statistics = nullptr, const RenderStop& stop = {},
                RenderCoverage* coverage = nullptr);

}  // namespace vrl
