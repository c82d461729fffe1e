#include "render/renderer.h"

#include "render/core/timing.h"
#include "render/integrators/path_tracer.h"
#include "render/integrators/transport_integrator.h"
#include "render/lightcuts/bounds/direction_cone.h"
#include "render/lightcuts/tree/leaf_segments.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"
#include "render/lightcuts/cuts/vrl_importance.h"
#include "render/vrl/light_tracer.h"
#include "render/vrl/vrl_lanes.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

namespace vrl {

namespace {

// Per-pixel cut counters: part (d)'s (the paper's Table 1), then part (c)'s.
constexpr const char* kCutLayerNames[3] = {"eval", "inter", "cut"};
constexpr const char* kSurfaceCutLayerNames[3] = {"medium-surface-eval", "medium-surface-inter", "medium-surface-cut"};
// vrl-stochastic: VRL estimates, node importances computed and cut size, per pixel and camera sample.
constexpr const char* kStochasticLayerNames[3] = {"eval", "importance", "cut"};
constexpr const char* kSurfaceStochasticLayerNames[3] = {"medium-surface-eval", "medium-surface-importance",
                                                         "medium-surface-cut"};
// vrl-lightcuts: the cut over surface VPLs (part (b)'s surface light), per pixel, over its camera segments.
constexpr const char* kSurfaceVplCutLayerNames[3] = {"single-vpl-eval", "single-vpl-inter", "single-vpl-cut"};

// Point (sx, sy) of a side x side grid over image pixel (x, y): jittered within its stratum,
// or its centre; through the film pixel, so a crop shades what the full film would.
Ray stratifiedCameraRay(const PerspectiveCamera& camera, const RenderSettings& settings, int x, int y, int sx, int sy,
                        int side, Rng& rng) {
    const float jx = settings.jitter ? rng.next() : 0.5f;
    const float jy = settings.jitter ? rng.next() : 0.5f;
    const float inverse = 1.0f / float(side);
    return camera.generateRay(float(x + camera.cropX0()) + (float(sx) + jx) * inverse,
                              float(y + camera.cropY0()) + (float(sy) + jy) * inverse);
}

// The ray of image pixel (x, y): the grid of side 1 ((0 + j) x 1 = j, the same bits as j).
Ray cameraRay(const PerspectiveCamera& camera, const RenderSettings& settings, int x, int y, Rng& rng) {
    return stratifiedCameraRay(camera, settings, x, y, 0, 0, 1, rng);
}

bool isVrlMethod(const RenderSettings& settings) { return usesVirtualLights(settings.method); }

// Part (c) comes from the VRLs (the VPL methods path-trace it).
bool vrlLitSurfaces(const RenderSettings& settings) {
    return isVrlMethod(settings) && !usesVpls(settings.method) && settings.transports.has(TransportPart::MediumSurface);
}

// The VRLs are needed: part (d), or part (c) by VRLs, is selected.
bool needsVrls(const RenderSettings& settings) {
    return isVrlMethod(settings) && (settings.transports.has(TransportPart::Multiple) || vrlLitSurfaces(settings));
}

// Light paths are traced: for VRLs or surface VPLs.
bool needsLights(const RenderSettings& settings) { return needsVrls(settings) || usesSurfaceVpls(settings); }

}  // namespace

bool usesSurfaceVpls(const RenderSettings& settings) {
    return surfaceVplsLightSingle(settings) || surfaceVplsLightSurfaces(settings);
}

bool surfaceVplsLightSingle(const RenderSettings& settings) {
    return (settings.method == RenderMethod::Vrl || settings.method == RenderMethod::VrlLightcuts) &&
           settings.transports.has(TransportPart::Single) && settings.surfaceVplLimit > 0;
}

bool surfaceVplsLightSurfaces(const RenderSettings& settings) {
    return (settings.method == RenderMethod::Vrl || settings.method == RenderMethod::VrlLightcuts) &&
           settings.transports.has(TransportPart::Surface) && settings.surfaceVplLimit > 0;
}

uint64_t surfaceVplLimit(const RenderSettings& settings) {
    if (settings.surfaceVplLimit != kAutoSurfaceVpls) return settings.surfaceVplLimit;
    if (settings.lightPaths > 0) return settings.lightPaths > kAutoSurfaceVpls / 4 ? kAutoSurfaceVpls : 4 * settings.lightPaths;
    return settings.vrlCount;
}

std::string_view methodName(RenderMethod method) {
    switch (method) {
        case RenderMethod::Path: return "path";
        case RenderMethod::Vrl: return "vrl";
        case RenderMethod::VrlLightcuts: return "vrl-lightcuts";
        case RenderMethod::VrlStochastic: return "vrl-stochastic";
        case RenderMethod::Vpl: return "vpl";
        case RenderMethod::VplLightcuts: return "vpl-lightcuts";
    }
    throw std::invalid_argument("unknown RenderMethod " + std::to_string(int(method)));
}

std::vector<std::string> renderMethodNames() {
    std::vector<std::string> names;
    for (RenderMethod m : kRenderMethods) names.emplace_back(methodName(m));
    return names;
}

RenderMethod parseRenderMethod(std::string_view name) {
    for (RenderMethod m : kRenderMethods)
        if (methodName(m) == name) return m;
    std::string valid;
    for (RenderMethod m : kRenderMethods) valid += (valid.empty() ? "" : ", ") + std::string(methodName(m));
    throw std::invalid_argument("unknown method '" + std::string(name.substr(0, 64)) + "' (valid: " + valid + ")");
}

void validateRenderSettings(const RenderSettings& settings) {
    if (settings.samplesPerPixel < 1) throw std::invalid_argument("samples per pixel must be at least 1");
    if (settings.vrlSamples < 1) throw std::invalid_argument("samples per VRL must be at least 1");
    if (!(settings.cut.errorThreshold >= 0.0f)) throw std::invalid_argument("the error threshold must be >= 0");
    if (settings.vplDistanceSamples < 1 || settings.vplDistanceSamples > kMaxVplDistanceSamples)
        throw std::invalid_argument("the VPL distance samples per camera segment must be in [1, " +
                                    std::to_string(kMaxVplDistanceSamples) + "], not " +
                                    std::to_string(settings.vplDistanceSamples));
    if (settings.cut.stochasticCutSize < 1 || settings.cut.stochasticCutSize > (1u << 20))
        throw std::invalid_argument("the stochastic cut size must be in [1, 1048576], not " +
                                    std::to_string(settings.cut.stochasticCutSize));
    if (settings.vrlSets < 1 || settings.vrlSets > kMaxVrlSets)
        throw std::invalid_argument("the VRL sets must be in [1, " + std::to_string(kMaxVrlSets) + "], not " +
                                    std::to_string(settings.vrlSets));
    if (settings.vrlSets > 1 && settings.method != RenderMethod::VrlStochastic)
        throw std::invalid_argument("several VRL sets (" + std::to_string(settings.vrlSets) +
                                    ") need the vrl-stochastic method, which draws its VRLs per camera sample; " +
                                    std::string(methodName(settings.method)) +
                                    " shades a whole set per pixel (ask for more --vrls instead)");
    if (settings.shadingPointsPerSide < 1 || settings.shadingPointsPerSide > kMaxShadingPointsPerSide)
        throw std::invalid_argument("the shading points per pixel side must be in [1, " +
                                    std::to_string(kMaxShadingPointsPerSide) + "], not " +
                                    std::to_string(settings.shadingPointsPerSide));
    if (!(settings.timeLimitSeconds >= 0.0 && settings.timeLimitSeconds <= kMaxTimeLimitSeconds))
        throw std::invalid_argument("the time limit must be 0 (none) or a number of seconds up to " +
                                    std::to_string(int64_t(kMaxTimeLimitSeconds)) + ", got " +
                                    std::to_string(settings.timeLimitSeconds));
}

RenderLights prepareLights(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                           RenderStatistics* statistics) {
    validateRenderSettings(settings);
    RenderLights lights;
    if (!needsLights(settings)) return lights;
    RenderStatistics local;
    RenderStatistics& stats = statistics ? *statistics : local;
    const bool points = usesVpls(settings.method);
    const int sets = settings.vrlSets;
    const uint64_t firstSeed = settings.seed ^ 0x5bd1e995ULL;  // a stream family apart from the camera's
    stats.vrlCount = stats.lightPaths = 0;
    stats.vrlBytes = 0;
    stats.tracingSeconds = stats.treeSeconds = 0.0;
    stats.treeBytes = 0;
    stats.vrlSets = sets;
    for (int k = 0; k < sets; ++k) {
        LightTracingSettings tracing;
        tracing.lightPaths = settings.lightPaths;
        tracing.targetVrls = settings.vrlCount;
        tracing.maxDepth = settings.maxDepth;
        tracing.seed = k == 0 ? firstSeed : Rng::combine(firstSeed, uint64_t(k));  // set 0: as with one set
        if (points) tracing.deposit = LightDeposit::Points;
        tracing.surfaceVpls = k == 0 && usesSurfaceVpls(settings);
        tracing.surfaceVplLimit = surfaceVplLimit(settings);
        const std::string tracingPhase = sets == 1 ? std::string("light tracing")
                                                   : "light tracing (set " + std::to_string(k + 1) + " of " +
                                                         std::to_string(sets) + ")";
        VrlSet set = traceVrls(scene, tracing, [&](double f) {
            if (progress) progress(tracingPhase.c_str(), f);
        });
        stats.vrlCount += set.vrls.size();
        stats.lightPaths += set.lightPaths;
        stats.vrlBytes += set.memoryBytes();
        stats.tracingSeconds += set.tracingSeconds;
        if (tracing.surfaceVpls) {
            // Plain and cut shading take the same list (prepareSurfaceVpls); the cut also its tree,
            // and so does part (a)'s sampling of them (plain VRLs too: the methods then differ by
            // their cuts alone).
            const bool cut = usesLightTree(settings.method) || surfaceVplsLightSurfaces(settings);
            const auto treeStart = std::chrono::steady_clock::now();
            lights.surfaceVpls = prepareSurfaceVpls(scene, std::move(set.surfaceVpls), cut,
                                                    LightTreeSettings{settings.partitionSize, settings.seed});
            if (cut) stats.treeSeconds += secondsSince(treeStart);
            stats.surfaceVplCount = lights.surfaceVpls.vpls.size();
            if (surfaceVplsLightSurfaces(settings)) stats.surfaceVplRadius = surfaceVplRadius(lights.surfaceVpls);
            stats.surfaceVplPaths = set.surfaceVplPaths;
            if (set.surfaceVplPaths < set.lightPaths)
                spdlog::info("surface VPLs: the limit of {} was reached after {} of {} light paths; (b)'s surface "
                             "light comes from those paths (raise --surface-vpls for less noise)",
                             surfaceVplLimit(settings), set.surfaceVplPaths, set.lightPaths);
            stats.treeBytes += lights.surfaceVpls.tree.memoryBytes();
            set.surfaceVpls = {};
        }
        if (!needsVrls(settings)) {  // only part (b)'s surface VPLs: no VRLs kept, no VRL tree
            lights.vrls.lightPaths = set.lightPaths;
            lights.vrls.tracingSeconds = set.tracingSeconds;
            continue;
        }
        if (!usesLightTree(settings.method) || set.vrls.empty()) {
            // Without a tree there is one set (validateRenderSettings); an empty set keeps its place.
            if (k == 0)
                lights.vrls = std::move(set);
            else
                lights.moreTrees.emplace_back();
            continue;
        }
        if (progress) progress("building the light tree", 0.0);
        const auto treeStart = std::chrono::steady_clock::now();
        // The tree takes the VRLs over: shading reads them from it.
        LightTree tree = LightTree::build(std::move(set.vrls), LightTreeSettings{settings.partitionSize, settings.seed, points});
        stats.treeSeconds += secondsSince(treeStart);
        stats.treeBytes += tree.memoryBytes();
        if (k == 0) {
            lights.vrls.lightPaths = set.lightPaths;
            lights.vrls.tracingSeconds = set.tracingSeconds;
            lights.tree = std::move(tree);
        } else {
            lights.moreTrees.push_back(std::move(tree));
        }
        if (progress) progress("building the light tree", 1.0);
    }
    return lights;
}

uint64_t estimateLightMemoryBytes(const RenderSettings& settings) {
    if (!needsLights(settings) || settings.lightPaths > 0) return 0;
    // The light tracer's vector may double while it is filled (2 lights per
    // light); a tree takes the lights over and adds 2 nodes per light plus its
    // build scratch (packed boxes, freed once it is built).
    double perLight = 2.0 * sizeof(Vrl);
    if (usesLightTree(settings.method)) perLight += 2.0 * sizeof(LightTreeNode) + double(LightTree::buildScratchBytesPerVrl());
    // What the shading adds per light: the deterministic cut's direction cones (an
    // HG medium only; counted always, the scene is not read here) and leaf
    // segments, the stochastic importance's record per inner node, plain VRLs'
    // structure-of-arrays copy.
    if (settings.method == RenderMethod::VrlLightcuts)
        perLight += double(DirectionCones::kBytesPerVrl + LeafSegments::kBytesPerVrl);
    if (settings.method == RenderMethod::VrlStochastic)
        perLight += double(VrlImportance::kBytesPerInnerNode);
    if (settings.method == RenderMethod::Vrl) perLight += double(VrlLanes::kBytesPerVrl);
    // Surface VPLs (part (b)): their limit (by default one per VRL: a light path meets
    // about as many surfaces as it leaves segments in a medium that fills the scene),
    // twice while traced, and for the cut its proxies, nodes, build scratch and the
    // estimator's per-VPL record (its BSDF prepared, its bound).
    double perSurfaceVpl = 0.0;
    if (usesSurfaceVpls(settings)) {
        perSurfaceVpl = 2.0 * sizeof(SurfaceVpl);
        if (usesLightTree(settings.method) || surfaceVplsLightSurfaces(settings))
            perSurfaceVpl += sizeof(Vrl) + 2.0 * sizeof(LightTreeNode) + double(LightTree::buildScratchBytesPerVrl()) +
                             double(SurfaceVplLightcutsEstimator::kBytesPerVpl);
    }
    const double bytes = perLight * double(settings.vrlCount) * double(std::max(1, settings.vrlSets)) +
                         perSurfaceVpl * double(surfaceVplLimit(settings));
    return bytes >= 1.8e19 ? ~uint64_t(0) : uint64_t(bytes);
}

std::vector<TileRect> imageTiles(int width, int height, int tileSize) {
    const int tile = std::max(1, tileSize);
    std::vector<TileRect> tiles;
    for (int y0 = 0; y0 < height; y0 += tile)
        for (int x0 = 0; x0 < width; x0 += tile)
            tiles.push_back({x0, y0, std::min(width, x0 + tile), std::min(height, y0 + tile)});
    return tiles;
}

int balancedTileSize(int width, int height, int tileSize, int threads) {
    int tile = std::max(1, tileSize);
    const auto count = [&](int side) { return int64_t((width + side - 1) / side) * ((height + side - 1) / side); };
    const int64_t wanted = int64_t(kTilesPerThread) * std::max(1, threads);
    while (tile / 2 >= kMinBalancedTileSize && count(tile) < wanted) tile /= 2;
    return tile;
}

std::vector<std::string> renderLayerNames(const RenderSettings& settings) {
    validateRenderSettings(settings);
    std::vector<std::string> names;
    if (!isVrlMethod(settings)) return names;
    for (size_t p = 0; p < kTransportPartNames.size(); ++p)
        if (settings.transports.enabled[p]) names.emplace_back(kTransportPartNames[p]);
    if (surfaceVplsLightSingle(settings)) names.emplace_back(kSurfaceVplLayerName);
    if (usesLightTree(settings.method)) {
        const bool stochastic = settings.method == RenderMethod::VrlStochastic;
        for (const char* name : stochastic ? kStochasticLayerNames : kCutLayerNames) names.emplace_back(name);
        if (vrlLitSurfaces(settings))
            for (const char* name : stochastic ? kSurfaceStochasticLayerNames : kSurfaceCutLayerNames)
                names.emplace_back(name);
        if (surfaceVplsLightSingle(settings))
            for (const char* name : kSurfaceVplCutLayerNames) names.emplace_back(name);
    }
    return names;
}

namespace {

// Lights that arrive from elsewhere (a deserialised blob) must belong to this
// scene: every medium index in range, or shading would index out of bounds.
void checkLightsMatchScene(const Scene& scene, const RenderLights& lights) {
    const size_t media = scene.media().size();
    const auto check = [&](const std::vector<Vrl>& vrls) {
        for (size_t k = 0; k < vrls.size(); ++k)
            if (vrls[k].medium < 0 || size_t(vrls[k].medium) >= media)
                throw std::invalid_argument("light " + std::to_string(k) + " lies in medium " +
                                            std::to_string(vrls[k].medium) + " but the scene has " +
                                            std::to_string(media) + " media: the lights do not belong to this scene");
    };
    check(lights.vrls.vrls);
    const auto checkTree = [&](const LightTree& tree) {
        check(tree.vrls());
        for (const LightTreeNode& node : tree.nodes())
            if (node.medium < -1 || node.medium >= int32_t(media))
                throw std::invalid_argument("a light-tree node names medium " + std::to_string(node.medium) +
                                            " but the scene has " + std::to_string(media) + " media");
    };
    checkTree(lights.tree);
    for (const LightTree& tree : lights.moreTrees) checkTree(tree);
    const SurfaceVplLights& surface = lights.surfaceVpls;
    for (size_t k = 0; k < surface.vpls.size(); ++k) {
        const SurfaceVpl& vpl = surface.vpls[k];
        if (vpl.shape >= scene.shapes().size() || vpl.medium < -1 || vpl.medium >= int32_t(media))
            throw std::invalid_argument("surface VPL " + std::to_string(k) + " lies on shape " +
                                        std::to_string(vpl.shape) + " in medium " + std::to_string(vpl.medium) +
                                        " but the scene has " + std::to_string(scene.shapes().size()) + " shapes and " +
                                        std::to_string(media) + " media: the lights do not belong to this scene");
    }
    if (!surface.tree.empty() && surface.tree.vrls().size() != surface.vpls.size())
        throw std::invalid_argument("the surface VPL tree holds " + std::to_string(surface.tree.vrls().size()) +
                                    " lights but the list beside it " + std::to_string(surface.vpls.size()) +
                                    ": the lights are corrupt");
}

}  // namespace

TileShader::TileShader(const Scene& scene, const RenderSettings& settings, const RenderLights& lights)
    : scene_(scene), settings_(settings), layerNames_(renderLayerNames(settings)) {
    checkLightsMatchScene(scene, lights);
    if (isVrlMethod(settings)) {
        const bool lightcuts = usesLightTree(settings.method);
        TransportIntegratorSettings integratorSettings{settings.transports, settings.maxDepth, settings.vrlSamples,
                                                 settings.cut};
        integratorSettings.vpls = usesVpls(settings.method);
        integratorSettings.vplDistanceSamples = settings.vplDistanceSamples;
        integratorSettings.stochastic = settings.method == RenderMethod::VrlStochastic;
        integratorSettings.surfaceVplCut = lightcuts;
        // (c) once per pixel over interleaved points of the pixel; at pixel centres, the centre's alone.
        integratorSettings.surfacePointsSide = settings.jitter ? kInterleavedPointsSide : 1;
        integrator_ = std::make_unique<TransportIntegrator>(scene, lights.vrls, integratorSettings,
                                                      lightcuts && lights.tree.root() >= 0 ? &lights.tree : nullptr,
                                                      usesSurfaceVpls(settings) ? &lights.surfaceVpls : nullptr);
        lightsPerSample_ = integrator_->virtualLightsPerSample();
        // Sets 1 ... P-1 (vrl-stochastic): each set's tree, or none when its light tracing found no VRL.
        if (lights.moreTrees.size() + 1 != size_t(settings.vrlSets) && (lights.tree.root() >= 0 || !lights.moreTrees.empty()))
            throw std::invalid_argument("the lights hold " + std::to_string(1 + lights.moreTrees.size()) +
                                        " VRL sets but the render asks for " + std::to_string(settings.vrlSets));
        for (const LightTree& tree : lights.moreTrees)
            moreIntegrators_.push_back(std::make_unique<TransportIntegrator>(
                scene, lights.vrls, integratorSettings, tree.root() >= 0 ? &tree : nullptr));
    } else {
        tracer_ = std::make_unique<VolumetricPathTracer>(scene, PathTracerSettings{settings.maxDepth});
    }
    // Once per pixel: the virtual-light parts (c) (when by VRLs) and (d), and the cut counters.
    layerPerPixel_.assign(1 + layerNames_.size(), 0);
    if (integrator_ && !lightsPerSample_)
        for (size_t l = 0; l < layerNames_.size(); ++l) {
            const std::string& name = layerNames_[l];
            const bool part = std::find(kTransportPartNames.begin(), kTransportPartNames.end(), name) !=
                              kTransportPartNames.end();
            const bool virtualLightPart = name == kTransportPartNames[size_t(TransportPart::Multiple)] ||
                                          (name == kTransportPartNames[size_t(TransportPart::MediumSurface)] &&
                                           integrator_->vrlLitSurfaces());
            layerPerPixel_[l + 1] = !part || virtualLightPart;
        }
}

TileShader::~TileShader() = default;

TileImages TileShader::renderTile(const TileRect& tile, const RenderStop& stop) const {
    TileSums shaded = shadeTile(tile, 0, passesFor(settings_.samplesPerPixel), stop);
    TileImages out;
    out.layers = resolveSamples(shaded.sums, layerNames_, settings_.samplesPerPixel);
    out.boundExceeded = shaded.sums.boundExceeded;
    out.boundedEstimates = shaded.sums.boundedEstimates;
    out.interrupted = shaded.interrupted;
    out.rowsDone = shaded.rowsDone;
    return out;
}

namespace {

// One pixel's values, one per layer (image first), summed or set by shadeTile.
using PixelValues = std::vector<Rgb>;

// The cut counters of one evaluation, as layer values.
// `add`: per camera sample (stochastic cuts), whose middle counter is the
// importances computed (kStochasticLayerNames) rather than #Inter.
// `surface`: part (c)'s counters follow; `surfaceVpl`: then the surface-VPL cut's (never with `add`).
void writeCounters(PixelValues& values, size_t& layer, const CutStatistics& cut, const CutStatistics& surfaceCut,
                   bool add, bool surface, const CutStatistics* surfaceVplCut = nullptr) {
    const auto put = [&](uint64_t count) {
        Rgb& v = values[layer++];
        v = add ? v + Rgb(float(count)) : Rgb(float(count));
    };
    put(cut.evaluated), put(add ? cut.importanceEvaluations : cut.intersected), put(cut.cutSize);
    if (surface)
        put(surfaceCut.evaluated), put(add ? surfaceCut.importanceEvaluations : surfaceCut.intersected),
            put(surfaceCut.cutSize);
    if (surfaceVplCut) put(surfaceVplCut->evaluated), put(surfaceVplCut->intersected), put(surfaceVplCut->cutSize);
}

}  // namespace

TileSums TileShader::shadeTile(const TileRect& tile, int firstPass, int passCount, const RenderStop& stop) const {
    const PerspectiveCamera& camera = scene_.camera();
    if (tile.x0 < 0 || tile.y0 < 0 || tile.x1 > camera.width() || tile.y1 > camera.height() || tile.x0 >= tile.x1 ||
        tile.y0 >= tile.y1)
        throw std::invalid_argument("tile outside the image");
    if (firstPass < 0 || passCount < 1 || firstPass > kMaxPasses || (firstPass > 0 && passCount != 1))
        throw std::invalid_argument("shadeTile: passes [" + std::to_string(firstPass) + ", +" +
                                    std::to_string(passCount) + ") must start at pass 0 or be a single pass");
    const int w = tile.width();
    const size_t layerCount = 1 + layerNames_.size();
    const bool lightcuts = usesLightTree(settings_.method);
    TileSums out;
    out.sums = SampleSums::zeros(w, tile.height(), layerPerPixel_);
    PixelValues total(layerCount), pass(layerCount);
    for (int y = tile.y0; y < tile.y1; ++y) {
        if (stop()) {
            out.interrupted = true;
            out.rowsDone = y - tile.y0;
            return out;
        }
        for (int x = tile.x0; x < tile.x1; ++x) {
            const uint64_t pixel = camera.filmPixelIndex(x, y);
            std::fill(total.begin(), total.end(), Rgb(0.0f));
            float firstSampleLuminance = 0.0f;  // of sample 0's path-sampled parts, for (c)'s cut
            for (int p = firstPass; p < firstPass + passCount; ++p) {
                const SamplePass samples = samplePass(p, settings_.samplesPerPixel);
                if (samples.count == 0) break;
                std::fill(pass.begin(), pass.end(), Rgb(0.0f));
                for (int s = samples.first; s < samples.first + samples.count; ++s) {
                    Rng rng(settings_.seed, Rng::combine(pixel, uint64_t(s)));
                    const Ray ray = cameraRay(camera, settings_, x, y, rng);
                    if (tracer_) {
                        pass[0] += tracer_->radiance(ray, scene_.cameraMedium(), rng);
                        continue;
                    }
                    std::array<Rgb, 4> parts = integrator_->samplePathParts(ray, rng);
                    const float pathLuminance = std::max(0.0f, luminance(parts[0] + parts[1] + parts[2]));
                    if (s == 0) firstSampleLuminance = pathLuminance;
                    CutStatistics cut, surfaceCut;
                    if (lightsPerSample_) {
                        // Sample s draws from VRL set s mod P (set 0: integrator_).
                        const size_t set = size_t(s) % (moreIntegrators_.size() + 1);
                        const TransportIntegrator& lighting = set == 0 ? *integrator_ : *moreIntegrators_[set - 1];
                        const auto lit = lighting.virtualLightParts(ray, rng, &cut, &surfaceCut, pathLuminance);
                        if (integrator_->vrlLitSurfaces()) parts[size_t(TransportPart::MediumSurface)] = lit.mediumSurface;
                        parts[size_t(TransportPart::Multiple)] = lit.multiple;
                        out.sums.boundExceeded += cut.boundExceeded + surfaceCut.boundExceeded;
                        out.sums.boundedEstimates += cut.boundedEstimates + surfaceCut.boundedEstimates;
                    }
                    size_t layer = 1;
                    for (size_t part = 0; part < parts.size(); ++part)
                        if (settings_.transports.enabled[part]) pass[layer++] += parts[part];
                    if (lightcuts && lightsPerSample_)
                        writeCounters(pass, layer, cut, surfaceCut, true, integrator_->vrlLitSurfaces() &&
                                                                             settings_.transports.has(TransportPart::MediumSurface));
                }
                // The canonical fold: the first pass's sums as they are, later ones added (per-sample layers only).
                for (size_t l = 0; l < layerCount; ++l)
                    if (!layerPerPixel_[l]) total[l] = p == firstPass ? pass[l] : total[l] + pass[l];
                if (p != 0 || !integrator_ || lightsPerSample_) continue;
                // (c) and (d) once per pixel, in pass 0, from the pixel's own stream: their cost is per
                // VRL, not per camera sample. (c)'s cut measures its error against sample 0's other parts.
                // With K x K shading points, point m has its own stream and stratum; their mean is the
                // pixel's value and the counters their sum.
                const int side = settings_.shadingPointsPerSide, points = side * side;
                CutStatistics cut, surfaceCut, surfaceVplCut;
                TransportIntegrator::VirtualLightParts lit;
                for (int m = 0; m < points; ++m) {
                    Rng rng(settings_.seed, Rng::combine(pixel, kPixelLightsSample - uint64_t(m)));
                    const Ray ray = stratifiedCameraRay(camera, settings_, x, y, m % side, m / side, side, rng);
                    // The point's stratum: (c) interleaves its VRLs over 2 x 2 points of it when
                    // jittered, one representative per class of coherent points, with its
                    // textures averaged over its class's quarters, else takes the ray's own point
                    // with its textures averaged over the stratum (pixel_footprint.h).
                    const float stratum = 1.0f / float(side);
                    const FilmSquare square{float(x + camera.cropX0()) + float(m % side) * stratum,
                                            float(y + camera.cropY0()) + float(m / side) * stratum, stratum};
                    const auto one = integrator_->virtualLightParts(ray, rng, &cut, &surfaceCut, firstSampleLuminance,
                                                                    &surfaceVplCut, &square);
                    if (m == 0) {
                        lit = one;
                        continue;
                    }
                    lit.mediumSurface += one.mediumSurface, lit.multiple += one.multiple, lit.singleSurface += one.singleSurface;
                }
                if (points > 1) {
                    const float inverse = 1.0f / float(points);
                    lit.mediumSurface *= inverse, lit.multiple *= inverse, lit.singleSurface *= inverse;
                }
                size_t layer = 1;
                for (size_t part = 0; part < 4; ++part) {
                    if (!settings_.transports.enabled[part]) continue;
                    if (part == size_t(TransportPart::Multiple)) total[layer] = lit.multiple;
                    if (part == size_t(TransportPart::MediumSurface) && integrator_->vrlLitSurfaces())
                        total[layer] = lit.mediumSurface;
                    ++layer;
                }
                const bool surfaceVpls = integrator_->surfaceVplsLight();
                if (surfaceVpls) total[layer++] = lit.singleSurface;
                if (lightcuts) {
                    writeCounters(total, layer, cut, surfaceCut, false,
                                  integrator_->vrlLitSurfaces() && settings_.transports.has(TransportPart::MediumSurface),
                                  surfaceVpls ? &surfaceVplCut : nullptr);
                    out.sums.boundExceeded += cut.boundExceeded + surfaceCut.boundExceeded + surfaceVplCut.boundExceeded;
                    out.sums.boundedEstimates +=
                        cut.boundedEstimates + surfaceCut.boundedEstimates + surfaceVplCut.boundedEstimates;
                }
            }
            for (size_t l = 0; l < layerCount; ++l) out.sums.layers[l].at(x - tile.x0, y - tile.y0) = total[l];
        }
    }
    return out;
}

ImageSet assembleImageSet(std::vector<Image> layers, const std::vector<std::string>& layerNames,
                          RenderStatistics* statistics) {
    if (layers.size() != layerNames.size() + 1) throw std::invalid_argument("assembleImageSet: layer count mismatch");
    ImageSet result;
    result.image = std::move(layers[0]);
    for (size_t l = 0; l < layerNames.size(); ++l) {
        const std::string& name = layerNames[l];
        if (statistics) {
            double sum = 0.0;
            for (const auto& p : layers[l + 1].pixels()) sum += p.x;
            const double mean = layers[l + 1].pixelCount() ? sum / double(layers[l + 1].pixelCount()) : 0.0;
            if (name == kCutLayerNames[0]) statistics->meanEvaluated = mean;
            if (name == kCutLayerNames[1]) statistics->meanIntersected = mean;
            if (name == kCutLayerNames[2]) statistics->meanCutSize = mean;
            if (name == kSurfaceCutLayerNames[0]) statistics->surfaceMeanEvaluated = mean;
            if (name == kSurfaceCutLayerNames[1]) statistics->surfaceMeanIntersected = mean;
            if (name == kSurfaceCutLayerNames[2]) statistics->surfaceMeanCutSize = mean;
            if (name == kStochasticLayerNames[1]) statistics->meanImportance = mean;
            if (name == kSurfaceStochasticLayerNames[1]) statistics->surfaceMeanImportance = mean;
            if (name == kSurfaceVplCutLayerNames[0]) statistics->surfaceVplMeanEvaluated = mean;
            if (name == kSurfaceVplCutLayerNames[1]) statistics->surfaceVplMeanIntersected = mean;
            if (name == kSurfaceVplCutLayerNames[2]) statistics->surfaceVplMeanCutSize = mean;
        }
        result.layers.emplace_back(name, std::move(layers[l + 1]));
        for (const char* counter : kCutLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kSurfaceCutLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kStochasticLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kSurfaceStochasticLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
        for (const char* counter : kSurfaceVplCutLayerNames)
            if (name == counter) result.singleChannelLayers.insert(name);
    }
    return result;
}

namespace {

// Passes [firstPass, firstPass + passCount) of every tile, in parallel (TBB),
// into whole-image sums; a tile stopped midway keeps its finished rows.
struct TilesShaded {
    SampleSums sums;
    std::vector<int> tileRows;  // rows shaded per tile
    int tilesDone = 0;
};
TilesShaded shadeTiles(const TileShader& shader, const std::vector<TileRect>& tiles, int width, int height,
                       int firstPass, int passCount, const RenderStop& stop, const ProgressCallback& progress,
                       const std::string& phase) {
    TilesShaded out;
    out.sums = SampleSums::zeros(width, height, shader.layerPerPixel());
    out.tileRows.assign(tiles.size(), 0);
    std::atomic<uint64_t> boundExceeded{0}, boundedEstimates{0};
    std::atomic<long long> pixelsDone{0};
    std::atomic<int> tilesDone{0};
    const double totalPixels = double(width) * height;
    if (progress) progress(phase.c_str(), 0.0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t t = range.begin(); t < range.end(); ++t) {
            if (stop()) return;
            const TileRect& tile = tiles[t];
            const TileSums shaded = shader.shadeTile(tile, firstPass, passCount, stop);
            const int rows = shaded.interrupted ? shaded.rowsDone : tile.height();
            out.tileRows[t] = rows;
            copyRows(out.sums, shaded.sums, tile.x0, tile.y0, rows);
            if (shaded.interrupted) return;
            ++tilesDone;
            boundExceeded += shaded.sums.boundExceeded;
            boundedEstimates += shaded.sums.boundedEstimates;
            const long long count = static_cast<long long>(tile.width()) * tile.height();
            const long long done = pixelsDone.fetch_add(count) + count;
            if (progress) progress(phase.c_str(), double(done) / totalPixels);
        }
    });
    out.tilesDone = tilesDone.load();
    out.sums.boundExceeded = boundExceeded.load();
    out.sums.boundedEstimates = boundedEstimates.load();
    return out;
}

void fillCoverage(RenderCoverage& coverage, const std::vector<TileRect>& tiles, const std::vector<int>& tileRows,
                  int tilesDone, int width, int height) {
    coverage.tilesTotal = int(tiles.size());
    coverage.tilesDone = tilesDone;
    coverage.rowsDone = 0;
    coverage.covered.assign(size_t(width) * height, 0);
    for (size_t t = 0; t < tiles.size(); ++t) {
        coverage.rowsDone += tileRows[t];
        for (int y = tiles[t].y0; y < tiles[t].y0 + tileRows[t]; ++y)
            std::fill_n(&coverage.covered[size_t(y) * width + tiles[t].x0], tiles[t].width(), uint8_t(1));
    }
}

}  // namespace

ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                RenderStatistics* statistics, const RenderStop& stop, RenderCoverage* coverage) {
    validateRenderSettings(settings);
    RenderStatistics stats;
    const auto stopRequested = [&] { return stop(); };
    // Light tracing runs in TBB tasks; an exception from its progress callback
    // cancels them and reaches the caller.
    const ProgressCallback preparing = [&](const char* phase, double fraction) {
        if (stopRequested()) throw RenderInterrupted();
        if (progress) progress(phase, fraction);
    };
    const RenderLights lights = prepareLights(scene, settings, preparing, &stats);
    if (stopRequested()) throw RenderInterrupted();
    const auto start = std::chrono::steady_clock::now();
    const TileShader shader(scene, settings, lights);
    const int width = scene.camera().width(), height = scene.camera().height();
    const std::vector<TileRect> tiles = imageTiles(
        width, height, balancedTileSize(width, height, settings.tileSize, tbb::this_task_arena::max_concurrency()));
    const int cap = settings.samplesPerPixel;
    SampleSums sums;
    std::vector<int> tileRows(tiles.size(), 0);
    int tilesDone = 0, passes = 0, samples = cap;
    if (settings.timeLimitSeconds <= 0.0) {
        // A fixed render: every pass of a tile at once, tile after tile.
        TilesShaded shaded = shadeTiles(shader, tiles, width, height, 0, passesFor(cap), stop, progress, "rendering");
        sums = std::move(shaded.sums);
        tileRows = std::move(shaded.tileRows);
        tilesDone = shaded.tilesDone;
        passes = passesFor(cap);
    } else {
        // Progressive: pass after pass over the whole image until the time limit.
        const auto deadline =
            start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(settings.timeLimitSeconds));
        const RenderStop passStop{[&] { return stop() || std::chrono::steady_clock::now() >= deadline; }};
        sums = SampleSums::zeros(width, height, shader.layerPerPixel());
        while (samplesAfter(passes, cap) < cap && !passStop()) {
            const SamplePass pass = samplePass(passes, cap);
            const std::string phase = "rendering pass " + std::to_string(passes + 1) + " (" +
                                      std::to_string(pass.count) + " spp, " +
                                      std::to_string(pass.first + pass.count) + " in all)";
            TilesShaded shaded = shadeTiles(shader, tiles, width, height, passes, 1, passStop, progress, phase);
            const bool complete = shaded.tilesDone == int(tiles.size());
            if (passes == 0) {  // a first pass cut short is kept, as an interrupt keeps its rows
                sums = std::move(shaded.sums);
                tileRows = std::move(shaded.tileRows);
                tilesDone = shaded.tilesDone;
            } else if (complete) {
                addPass(sums, shaded.sums);
            }
            if (!complete) break;
            ++passes;
        }
        if (passes > 0) {
            tilesDone = int(tiles.size());
            for (size_t t = 0; t < tiles.size(); ++t) tileRows[t] = tiles[t].height();
        }
        samples = std::max(1, samplesAfter(passes, cap));
    }
    if (coverage) fillCoverage(*coverage, tiles, tileRows, tilesDone, width, height);
    ImageSet result = assembleImageSet(resolveSamples(sums, shader.layerNames(), samples), shader.layerNames(), &stats);
    stats.boundExceeded = sums.boundExceeded;
    stats.boundedEstimates = sums.boundedEstimates;
    stats.seconds = secondsSince(start);
    stats.cameraSamples = uint64_t(width) * height * uint64_t(samples);
    stats.samplesPerPixel = samples;
    stats.passes = passes;
    if (statistics) *statistics = stats;
    return result;
}

}  // namespace vrl
