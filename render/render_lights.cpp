#include "render/render_lights.h"

#include "render/core/timing.h"
#include "render/integrators/gatherers.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"
#include "render/vrl/light_tracer.h"

#include <algorithm>
#include <chrono>
#include <string>

#include <spdlog/spdlog.h>

namespace vrl {

namespace {

// The VRLs (or VPLs) are needed: part (d), or part (c) by VRLs, is selected.
bool needsVrls(const RenderSettings& settings) {
    const MethodTraits& method = methodTraits(settings.method);
    return method.lights != VirtualLights::None &&
           (settings.transports.has(TransportPart::Multiple) ||
            (method.estimators.vrlLitSurfaces() && settings.transports.has(TransportPart::MediumSurface)));
}

// Light paths are traced: for VRLs or surface VPLs.
bool needsLights(const RenderSettings& settings) { return needsVrls(settings) || usesSurfaceVpls(settings); }

// The surface VPLs get a tree: for their cut, and for part (a)'s sampling of them
// (plain VRLs too: the methods then differ by their cuts alone).
bool surfaceVplTree(const RenderSettings& settings) {
    return methodTraits(settings.method).estimators.surfaceVpls == SurfaceVplLightKind::Cut ||
           surfaceVplsLightSurfaces(settings);
}

}  // namespace

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
            // Plain and cut shading take the same list (prepareSurfaceVpls); the cut also its tree.
            const bool cut = surfaceVplTree(settings);
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
    // What the shading adds per light: the deterministic VRL cut's direction cones and
    // leaf segments, the stochastic importance's record per inner node, plain VRLs'
    // structure-of-arrays copy (gathererBytesPerLight).
    perLight += double(gathererBytesPerLight(methodTraits(settings.method).estimators));
    // Surface VPLs (part (b)): their limit (by default one per VRL: a light path meets
    // about as many surfaces as it leaves segments in a medium that fills the scene),
    // twice while traced, and for the cut its proxies, nodes, build scratch and the
    // estimator's per-VPL record (its BSDF prepared, its bound).
    double perSurfaceVpl = 0.0;
    if (usesSurfaceVpls(settings)) {
        perSurfaceVpl = 2.0 * sizeof(SurfaceVpl);
        if (surfaceVplTree(settings))
            perSurfaceVpl += sizeof(Vrl) + 2.0 * sizeof(LightTreeNode) + double(LightTree::buildScratchBytesPerVrl()) +
                             double(SurfaceVplLightcutsEstimator::kBytesPerVpl);
    }
    const double bytes = perLight * double(settings.vrlCount) * double(std::max(1, settings.vrlSets)) +
                         perSurfaceVpl * double(surfaceVplLimit(settings));
    return bytes >= 1.8e19 ? ~uint64_t(0) : uint64_t(bytes);
}

}  // namespace vrl
