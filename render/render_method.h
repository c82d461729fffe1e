// The render methods and the one table of what each one is: its names, which
// lights it traces, which estimator takes each transport part
// (integrators/transport_integrator.h's (a)-(d)), which settings it reads, and so
// which layers and metadata it writes. The renderer, the integrator's settings,
// the metadata writer, the command line's warnings and the report's titles all
// read this table; past the command line and the job spec, code compares
// RenderMethod values, never strings.
//
//   method          lights  tree  (d) multiple      (c) medium-surface  (b)/(a) surface VPLs
//   path            -       -     path tracer       path tracer         path tracer
//   vrl             VRLs    -     plain VRLs        plain VRLs          plain (b); (a) sampled
//   vrl-lightcuts   VRLs    yes   VRL cut           VRL cut             cut (b); (a) sampled
//   vrl-stochastic  VRLs    yes   stochastic cut    stochastic cut      path-sampled
//   vpl             VPLs    -     plain VPLs        path-sampled        path-sampled
//   vpl-lightcuts   VPLs    yes   VPL cut           path-sampled        path-sampled
//
// (a) and (b) are path-sampled per camera sample in every virtual-light method,
// less the surface VPLs' share where a method takes one. (c) and (d) are
// evaluated once per pixel, except by the stochastic cuts (per camera sample, so
// --spp applies to them too). The cuts write per-pixel counter layers: "eval",
// "inter", "cut" (the paper's Table 1) for part (d), "medium-surface-..." for
// (c), "single-vpl-..." for the surface VPLs' cut; a stochastic cut writes
// "importance" (node importances computed) in place of "inter".
#pragma once

#include "render/integrators/part_estimators.h"

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace vrl {

enum class RenderMethod { Path, Vrl, VrlLightcuts, VrlStochastic, Vpl, VplLightcuts };
inline constexpr std::array<RenderMethod, 6> kRenderMethods = {RenderMethod::Path,          RenderMethod::Vrl,
                                                               RenderMethod::VrlLightcuts,  RenderMethod::VrlStochastic,
                                                               RenderMethod::Vpl,           RenderMethod::VplLightcuts};
// The method a job renders when neither it nor its scene's <integrator> names
// one: the README's recommended method (the paper's, VRL Lightcuts).
inline constexpr RenderMethod kHeadlineMethod = RenderMethod::VrlLightcuts;

// The virtual lights a method traces.
enum class VirtualLights : uint8_t {
    None,  // the path tracer renders the whole image
    Vrls,  // virtual ray lights, the light paths' medium segments
    Vpls,  // virtual point lights at the light paths' medium collisions (RenderSettings::vrlCount counts them)
};

// The RenderSettings a method reads beyond those every method reads (samples,
// seed, jitter, depth, resolution, time limit); a flag setting one of the others
// has no effect (the command line warns).
struct MethodReads {
    bool lightCount = false;          // vrlCount, lightPaths
    bool transports = false;          // transports: the parts rendered, one layer each
    bool vrlSamples = false;          // (u, v) samples per VRL
    bool cutError = false;            // cut.errorThreshold, maxCutSize, bound.anisotropyEpsilon (a deterministic cut)
    bool vrlClusterBounds = false;    // cut.bound.exactDistanceBelow, hgBound, glossyBound (the VRL cuts' bounds)
    bool partitionSize = false;       // a light tree's build
    bool stochasticCutSize = false;   // cut.stochasticCutSize
    bool vrlSets = false;             // several VRL sets, one per camera sample
    bool vplDistanceSamples = false;  // distance samples per camera segment
    bool shadingPoints = false;       // K x K points per pixel for the parts shaded once per pixel
    bool surfaceVplLimit = false;     // surface VPLs for parts (a), (b)
};

struct MethodTraits {
    RenderMethod method;
    std::string_view name;   // --method's value, the job spec's and the EXR's vrl.method
    std::string_view title;  // in words, for reports ("VRL Lightcuts")
    VirtualLights lights;
    bool lightTree;             // prepareLights builds a light tree; the lights blob ships it, not a VRL set
    PartEstimators estimators;  // what takes (c), (d) and the surface VPLs' light
    MethodReads reads;
};

inline constexpr std::array<MethodTraits, 6> kMethodTraits = {{
    {RenderMethod::Path, "path", "path tracing", VirtualLights::None, false,
     {MediumGathererKind::None, SurfaceGathererKind::PathSampled, SurfaceVplLightKind::None},
     {}},
    {RenderMethod::Vrl, "vrl", "plain VRLs", VirtualLights::Vrls, false,
     {MediumGathererKind::PlainVrls, SurfaceGathererKind::PlainVrls, SurfaceVplLightKind::Plain},
     {.lightCount = true, .transports = true, .vrlSamples = true, .shadingPoints = true, .surfaceVplLimit = true}},
    {RenderMethod::VrlLightcuts, "vrl-lightcuts", "VRL Lightcuts", VirtualLights::Vrls, true,
     {MediumGathererKind::VrlCut, SurfaceGathererKind::VrlCut, SurfaceVplLightKind::Cut},
     {.lightCount = true, .transports = true, .vrlSamples = true, .cutError = true, .vrlClusterBounds = true,
      .partitionSize = true, .shadingPoints = true, .surfaceVplLimit = true}},
    {RenderMethod::VrlStochastic, "vrl-stochastic", "stochastic VRL Lightcuts", VirtualLights::Vrls, true,
     {MediumGathererKind::StochasticVrlCut, SurfaceGathererKind::StochasticVrlCut, SurfaceVplLightKind::None},
     {.lightCount = true, .transports = true, .vrlSamples = true, .partitionSize = true, .stochasticCutSize = true,
      .vrlSets = true}},
    {RenderMethod::Vpl, "vpl", "plain VPLs", VirtualLights::Vpls, false,
     {MediumGathererKind::PlainVpls, SurfaceGathererKind::PathSampled, SurfaceVplLightKind::None},
     {.lightCount = true, .transports = true, .vplDistanceSamples = true, .shadingPoints = true}},
    {RenderMethod::VplLightcuts, "vpl-lightcuts", "VPL Lightcuts", VirtualLights::Vpls, true,
     {MediumGathererKind::VplCut, SurfaceGathererKind::PathSampled, SurfaceVplLightKind::None},
     {.lightCount = true, .transports = true, .cutError = true, .partitionSize = true, .vplDistanceSamples = true,
      .shadingPoints = true}},
}};

// The row of `method`; throws std::invalid_argument for a value outside the enum.
constexpr const MethodTraits& methodTraits(RenderMethod method) {
    if (size_t(method) >= kMethodTraits.size())
        throw std::invalid_argument("unknown RenderMethod " + std::to_string(int(method)));
    return kMethodTraits[size_t(method)];
}

// The table's rows agree with themselves: indexed by method, a tree exactly where
// (d) is a cut, VRL estimators only for VRLs, a per-pixel part's counters never
// mixed with per-sample ones.
constexpr bool methodTableConsistent() {
    for (size_t i = 0; i < kMethodTraits.size(); ++i) {
        const MethodTraits& m = kMethodTraits[i];
        const PartEstimators& e = m.estimators;
        if (m.method != kRenderMethods[i] || size_t(m.method) != i) return false;
        if (m.lightTree != isCut(e.multiple)) return false;
        if ((m.lights == VirtualLights::None) != (e.multiple == MediumGathererKind::None)) return false;
        if (m.lights != VirtualLights::Vrls &&
            (e.vrlLitSurfaces() || e.surfaceVpls != SurfaceVplLightKind::None))
            return false;
        if (isStochastic(e.multiple) != e.perSample()) return false;
    }
    return true;
}
static_assert(methodTableConsistent());

// "path", "vrl", "vrl-lightcuts", "vrl-stochastic", "vpl", "vpl-lightcuts".
constexpr std::string_view methodName(RenderMethod method) { return methodTraits(method).name; }
// Every method's name, in kRenderMethods order (for the command line's choices).
std::vector<std::string> renderMethodNames();
// The method named `name`; throws std::invalid_argument naming it and the valid names.
RenderMethod parseRenderMethod(std::string_view name);
// The methods whose row reads the setting `member` of MethodReads, in words:
// "vrl-lightcuts and vpl-lightcuts", "the virtual-light methods" when every one does.
std::string methodsReading(bool MethodReads::*member);

// The method deposits VPLs (points) rather than VRLs.
constexpr bool usesVpls(RenderMethod m) { return methodTraits(m).lights == VirtualLights::Vpls; }
// The method builds a light tree (VRL, stochastic VRL or VPL Lightcuts): it ships a tree, not a VRL set.
constexpr bool usesLightTree(RenderMethod m) { return methodTraits(m).lightTree; }
// The method renders the four transport parts with virtual lights (every method but path).
constexpr bool usesVirtualLights(RenderMethod m) { return methodTraits(m).lights != VirtualLights::None; }

// The counter layers of a cut (single channel, one value per pixel, or per camera
// sample summed for the stochastic cuts): part (d)'s (the paper's Table 1), part
// (c)'s, and the surface VPLs' cut (part (b)).
using CounterLayerNames = std::array<std::string_view, 3>;
inline constexpr CounterLayerNames kCutLayerNames = {"eval", "inter", "cut"};
inline constexpr CounterLayerNames kSurfaceCutLayerNames = {"medium-surface-eval", "medium-surface-inter",
                                                            "medium-surface-cut"};
// Stochastic cuts: VRL estimates, node importances computed and cut size.
inline constexpr CounterLayerNames kStochasticLayerNames = {"eval", "importance", "cut"};
inline constexpr CounterLayerNames kSurfaceStochasticLayerNames = {"medium-surface-eval", "medium-surface-importance",
                                                                   "medium-surface-cut"};
inline constexpr CounterLayerNames kSurfaceVplCutLayerNames = {"single-vpl-eval", "single-vpl-inter",
                                                               "single-vpl-cut"};
inline constexpr std::array<const CounterLayerNames*, 5> kAllCounterLayerNames = {
    &kCutLayerNames, &kSurfaceCutLayerNames, &kStochasticLayerNames, &kSurfaceStochasticLayerNames,
    &kSurfaceVplCutLayerNames};

// The counter layers of an estimator kind; null for one without a cut.
constexpr const CounterLayerNames* counterLayers(MediumGathererKind k) {
    return !isCut(k) ? nullptr : isStochastic(k) ? &kStochasticLayerNames : &kCutLayerNames;
}
constexpr const CounterLayerNames* counterLayers(SurfaceGathererKind k) {
    return !isCut(k) ? nullptr : isStochastic(k) ? &kSurfaceStochasticLayerNames : &kSurfaceCutLayerNames;
}
constexpr const CounterLayerNames* counterLayers(SurfaceVplLightKind k) {
    return k == SurfaceVplLightKind::Cut ? &kSurfaceVplCutLayerNames : nullptr;
}

}  // namespace vrl
