#include "render/render_metadata.h"

#include "render/scene/camera.h"

#include <cstdint>

namespace vrl {

void writeRenderMetadata(const RenderRecord& record, const PerspectiveCamera& camera, Metadata& metadata) {
    const RenderSettings& s = record.settings;
    const RenderStatistics& stats = record.statistics;
    metadata["vrl.version"] = std::string(VRL_VERSION);
    metadata["vrl.scene"] = record.scene;
    metadata["vrl.method"] = std::string(methodName(s.method));
    // A progressive render holds the samples of its completed passes; its cap and limit are recorded apart.
    const bool progressive = s.timeLimitSeconds > 0.0;
    metadata["vrl.spp"] = int32_t(progressive ? stats.samplesPerPixel : s.samplesPerPixel);
    if (progressive) {
        metadata["vrl.progressive.passes"] = int32_t(stats.passes);
        metadata["vrl.progressive.timeLimit"] = s.timeLimitSeconds;
        metadata["vrl.progressive.sppCap"] = int32_t(s.samplesPerPixel);
    }
    metadata["vrl.seed"] = std::to_string(s.seed);
    metadata["vrl.maxDepth"] = int32_t(s.maxDepth);
    metadata["vrl.jitter"] = int32_t(s.jitter ? 1 : 0);
    metadata["vrl.width"] = int32_t(camera.width());
    metadata["vrl.height"] = int32_t(camera.height());
    if (camera.crop()) {
        metadata["vrl.crop"] = camera.crop()->toString();
        metadata["vrl.film"] = std::to_string(camera.filmWidth()) + "x" + std::to_string(camera.filmHeight());
    }
    std::string defines;
    for (const auto& [name, value] : record.defines) defines += (defines.empty() ? "" : " ") + name + "=" + value;
    metadata["vrl.defines"] = defines;
    if (!record.medium.empty()) metadata["vrl.medium"] = record.medium;
    for (const auto& [key, value] : record.sceneNotes) metadata[key] = value;

    const MethodTraits& method = methodTraits(s.method);
    const PartEstimators& estimators = method.estimators;
    const bool points = method.lights == VirtualLights::Vpls;
    if (method.lights != VirtualLights::None) {
        metadata["vrl.transport"] = s.transports.toString();
        if (method.reads.vrlSamples) metadata["vrl.vrlSamples"] = int32_t(s.vrlSamples);
        metadata[points ? "vrl.vpls" : "vrl.vrls"] = double(stats.vrlCount);
        metadata["vrl.lightPaths"] = double(stats.lightPaths);
        metadata["vrl.time.lightTracing"] = stats.tracingSeconds;
        if (method.reads.shadingPoints && s.shadingPointsPerSide > 1)
            metadata["vrl.shadingPoints"] = int32_t(s.shadingPointsPerSide);  // per side: K x K points
        if (usesSurfaceVpls(s)) {
            metadata["vrl.surfaceVpls"] = double(stats.surfaceVplCount);
            metadata["vrl.surfaceVplLimit"] = double(surfaceVplLimit(s));
            metadata["vrl.surfaceVplPaths"] = double(stats.surfaceVplPaths);  // the light paths that deposited them
            // Part (a)'s share: the inverse square clamped at this distance (scene units).
            if (surfaceVplsLightSurfaces(s)) metadata["vrl.surfaceVplRadius"] = stats.surfaceVplRadius;
        } else if (method.reads.surfaceVplLimit && s.transports.has(TransportPart::Single)) {
            metadata["vrl.surfaceVplLimit"] = 0.0;  // none: (b) path-samples its surface light
        }
    }
    if (method.reads.vplDistanceSamples) metadata["vrl.vplDistanceSamples"] = int32_t(s.vplDistanceSamples);
    if (method.lightTree) {
        if (method.reads.stochasticCutSize) metadata["vrl.cutSize"] = int32_t(s.cut.stochasticCutSize);
        if (method.reads.vrlSets) metadata["vrl.vrlSets"] = int32_t(s.vrlSets);  // vrl.vrls and vrl.lightPaths count all sets
        if (method.reads.cutError) {
            metadata["vrl.error"] = s.cut.errorThreshold;
            metadata["vrl.maxCut"] = int32_t(s.cut.maxCutSize);
            metadata["vrl.exactDistanceBelow"] = int32_t(s.cut.bound.exactDistanceBelow);
            metadata["vrl.hgEpsilon"] = s.cut.bound.anisotropyEpsilon;
        }
        if (method.reads.vrlClusterBounds) {
            metadata["vrl.hgBound"] = std::string(s.cut.bound.hgBound == HgBound::Cones ? "cones" : "epsilon");
            metadata["vrl.glossyBound"] = std::string(s.cut.bound.glossyBound == GlossyBound::Cones ? "cones" : "corners");
        }
        metadata["vrl.partitionSize"] = int32_t(s.partitionSize);
        // The cuts' counters (render_method.h): per pixel, or per pixel and camera sample for
        // a stochastic cut, which counts importances instead of #Inter and has no bounds.
        const bool stochastic = isStochastic(estimators.multiple);
        metadata["vrl.meanEval"] = stats.meanEvaluated;
        if (stochastic)
            metadata["vrl.meanImportance"] = stats.meanImportance;
        else
            metadata["vrl.meanInter"] = stats.meanIntersected;
        metadata["vrl.meanCut"] = stats.meanCutSize;
        if (s.transports.has(TransportPart::MediumSurface) && counterLayers(estimators.mediumSurface)) {
            metadata["vrl.surface.meanEval"] = stats.surfaceMeanEvaluated;
            if (isStochastic(estimators.mediumSurface))
                metadata["vrl.surface.meanImportance"] = stats.surfaceMeanImportance;
            else
                metadata["vrl.surface.meanInter"] = stats.surfaceMeanIntersected;
            metadata["vrl.surface.meanCut"] = stats.surfaceMeanCutSize;
        }
        if (surfaceVplsLightSingle(s) && counterLayers(estimators.surfaceVpls)) {
            metadata["vrl.surfaceVpl.meanEval"] = stats.surfaceVplMeanEvaluated;
            metadata["vrl.surfaceVpl.meanInter"] = stats.surfaceVplMeanIntersected;
            metadata["vrl.surfaceVpl.meanCut"] = stats.surfaceVplMeanCutSize;
        }
        if (!stochastic) {
            metadata["vrl.boundExceeded"] = double(stats.boundExceeded);
            metadata["vrl.boundedEstimates"] = double(stats.boundedEstimates);
        }
        metadata["vrl.time.treeBuild"] = stats.treeSeconds;
    }
    metadata["vrl.time.render"] = stats.seconds;
    for (const auto& [phase, seconds] : record.phases) metadata["vrl.time." + phase] = seconds;
    for (const auto& [key, value] : record.run) metadata["vrl.run." + key] = value;
    metadata["worldToCamera"] = camera.worldToCamera();
    metadata["worldToNDC"] = camera.worldToNDC();
}

}  // namespace vrl
