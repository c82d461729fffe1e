// makeGatherers: the one factory of a TransportIntegrator's virtual-light
// estimators, built once from its PartEstimators (part_estimators.h): part (d)'s
// MediumGatherer, part (c)'s SurfaceGatherer and the SurfaceVplLight of (a), (b).
// A new estimator is a kind and a class, wired here alone.
#pragma once

#include "render/integrators/medium_gatherer.h"
#include "render/integrators/part_estimators.h"
#include "render/integrators/surface_gatherer.h"
#include "render/integrators/surface_vpl_light.h"
#include "render/integrators/transport_parts.h"
#include "render/lightcuts/cuts/cut_settings.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/surface_vpl_lights.h"
#include "render/vrl/vrl.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace vrl {

struct Gatherers {
    std::unique_ptr<MediumGatherer> multiple;        // (d); null when (d) is not selected
    std::unique_ptr<SurfaceGatherer> mediumSurface;  // (c); null when path-sampled or not selected
    std::unique_ptr<SurfaceVplLight> surfaceVpls;    // (a), (b)'s surface VPLs; null when they take none
};

// What the gatherers are built over and with.
struct GathererInputs {
    const std::vector<Vrl>* lights = nullptr;            // every VRL (or VPL) of a method without a tree
    const LightTree* tree = nullptr;                     // the VRL (or VPL) tree of a cut
    const SurfaceVplLights* surfaceVpls = nullptr;       // part (a), (b)'s surface VPLs, if any
    int vrlSamples = 1;                                  // (u, v) samples per VRL and camera segment or point
    CutSettings cut;
    int vplDistanceSamples = 1;                          // distance samples per camera segment (VPLs)
};

// The gatherers of `kinds` for the selected parts. A cut kind without a tree (a
// light set in which light tracing found nothing) takes its plain kind over
// `lights`; a plain kind given a tree takes the tree's lights. The surface VPLs
// light (b) when it is selected, and (a) when it is and they are not empty.
// Throws std::invalid_argument for part (d) without virtual lights (MediumGathererKind::None).
Gatherers makeGatherers(const Scene& scene, const TransportSelection& transports, const PartEstimators& kinds,
                        const GathererInputs& inputs);

// What the gatherers of `kinds` keep per light beside the lights themselves (for
// memory estimates): SIMD lanes, cut bound data or node importances.
size_t gathererBytesPerLight(const PartEstimators& kinds);

}  // namespace vrl
