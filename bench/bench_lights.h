// Light tracing and the light tree as the benchmarks use them: about N VRLs from
// the light tracer's default stream, the default hybrid tree over a copy of them
// (the VRL set stays for plain shading), and the wall time of each step.
#pragma once

#include "render/core/timing.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/scene/scene.h"
#include "render/vrl/light_tracer.h"

#include <chrono>
#include <cstdint>

namespace vrl::bench {

struct BenchLights {
    VrlSet vrls;
    LightTree tree;
    double traceSeconds = 0.0, buildSeconds = 0.0;
};

inline BenchLights traceAndBuild(const Scene& scene, uint64_t vrlCount, int maxDepth) {
    BenchLights lights;
    LightTracingSettings tracing;
    tracing.targetVrls = vrlCount;
    tracing.maxDepth = maxDepth;
    auto start = std::chrono::steady_clock::now();
    lights.vrls = traceVrls(scene, tracing);
    lights.traceSeconds = secondsSince(start);
    start = std::chrono::steady_clock::now();
    lights.tree = LightTree::build(lights.vrls.vrls);
    lights.buildSeconds = secondsSince(start);
    return lights;
}

}  // namespace vrl::bench
