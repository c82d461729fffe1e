// Light preparation, the per-image light work of a render (the coordinator's
// part in the service): light tracing into VRLs (or VPLs), the light tree of the
// tree methods, and the surface VPLs of parts (a), (b); and the memory it takes.
#pragma once

#include "render/lightcuts/tree/light_tree.h"
#include "render/lightcuts/tree/surface_vpl_lights.h"
#include "render/render_settings.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl.h"

#include <cstdint>
#include <vector>

namespace vrl {

// The lights of a render: the VRLs of the `vrl` method, or the light tree of a
// tree method (which owns its VRLs). Empty for the path tracer and when neither
// part (c) nor (d) is selected. vrl-stochastic with vrlSets P > 1: `tree` is set
// 0's and moreTrees sets 1 ... P-1. Surface VPLs (usesSurfaceVpls): `surfaceVpls`,
// with its own tree for their cut and for part (a)'s sampling
// (surface_vpl_lightcuts_estimator.h).
struct RenderLights {
    VrlSet vrls;
    LightTree tree;
    std::vector<LightTree> moreTrees;
    SurfaceVplLights surfaceVpls;
};

// Traces and builds the lights `settings` need; fills the light-tracing and tree
// entries of `statistics`. Validates the settings first (validateRenderSettings).
RenderLights prepareLights(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
                           RenderStatistics* statistics = nullptr);

// Peak memory of prepareLights for `settings` (0 when it prepares nothing): the
// target VRL (or VPL) count times the bytes of a light, with the light tracer's
// batch growth, plus the tree's nodes and build scratch for the tree methods,
// times the VRL sets.
// With --light-paths the count is not known in advance and this returns 0.
uint64_t estimateLightMemoryBytes(const RenderSettings& settings);

}  // namespace vrl
