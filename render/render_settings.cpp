#include "render/render_settings.h"

#include <stdexcept>

namespace vrl {

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
    if (settings.vrlSets > 1 && !methodTraits(settings.method).reads.vrlSets)
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

namespace {

bool surfaceVplsFor(const RenderSettings& settings, TransportPart part) {
    return methodTraits(settings.method).estimators.surfaceVpls != SurfaceVplLightKind::None &&
           settings.transports.has(part) && settings.surfaceVplLimit > 0;
}

}  // namespace

bool usesSurfaceVpls(const RenderSettings& settings) {
    return surfaceVplsLightSingle(settings) || surfaceVplsLightSurfaces(settings);
}

bool surfaceVplsLightSingle(const RenderSettings& settings) { return surfaceVplsFor(settings, TransportPart::Single); }

bool surfaceVplsLightSurfaces(const RenderSettings& settings) {
    return surfaceVplsFor(settings, TransportPart::Surface);
}

uint64_t surfaceVplLimit(const RenderSettings& settings) {
    if (settings.surfaceVplLimit != kAutoSurfaceVpls) return settings.surfaceVplLimit;
    if (settings.lightPaths > 0) return settings.lightPaths > kAutoSurfaceVpls / 4 ? kAutoSurfaceVpls : 4 * settings.lightPaths;
    return settings.vrlCount;
}

std::vector<std::string> renderLayerNames(const RenderSettings& settings) {
    validateRenderSettings(settings);
    std::vector<std::string> names;
    const MethodTraits& method = methodTraits(settings.method);
    if (method.lights == VirtualLights::None) return names;
    for (size_t p = 0; p < kTransportPartNames.size(); ++p)
        if (settings.transports.enabled[p]) names.emplace_back(kTransportPartNames[p]);
    const bool surfaceVplsSingle = surfaceVplsLightSingle(settings);
    if (surfaceVplsSingle) names.emplace_back(kSurfaceVplLayerName);
    // The cuts' counters: (d)'s whether or not (d) is selected, (c)'s and the surface VPLs' with their parts.
    const auto add = [&](const CounterLayerNames* counters) {
        if (counters)
            for (std::string_view name : *counters) names.emplace_back(name);
    };
    add(counterLayers(method.estimators.multiple));
    if (settings.transports.has(TransportPart::MediumSurface)) add(counterLayers(method.estimators.mediumSurface));
    if (surfaceVplsSingle) add(counterLayers(method.estimators.surfaceVpls));
    return names;
}

}  // namespace vrl
