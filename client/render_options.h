// The render flags shared by `vrl render` and `vrl submit`, and their
// translation into the service's RenderParameters.
#pragma once

#include "render/renderer.h"
#include "vrl/v1/vrl.pb.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace vrl::client {

struct RenderCommandOptions {
    std::string scene;
    std::string output;
    std::vector<std::string> defines;
    std::string medium;   // --medium "sigmaS=..,sigmaA=..[,g=..]": fill a scene without media
    std::string preview;  // --preview out.png: a tone-mapped PNG beside the EXR
    std::string method;  // empty: the scene's <integrator> if it names one of ours, else the headline method
    int spp = 0;  // 0: the scene's sampleCount (with --time-limit: the cap, 0 none)
    double timeLimit = 0.0;  // --time-limit SECONDS: > 0 renders progressive passes until then
    std::string resolution;  // "WxH", empty: the scene's film
    std::string crop;        // "x,y,w,h" of the (resolved) film, empty: the scene's crop window if any
    int threads = 0;         // 0: all cores
    uint64_t seed = 0;
    int maxDepth = -2;  // -2: the scene's integrator maxDepth
    bool pixelCentres = false;  // rays through pixel centres (the paper's setting) instead of jittered
    bool quiet = false;
    uint64_t vrls = 100000;
    uint64_t lightPaths = 0;
    int vrlSamples = 1;
    std::string transport = "surface,single,medium-surface,multiple";
    float error = 0.02f;
    uint32_t maxCut = 4096;
    uint32_t exactDistanceBelow = 32;
    bool glossyHeuristic = false;  // vrl-lightcuts: part (c)'s glossy receivers by the heuristic bound
    std::optional<float> hgEpsilon;  // given: vrl-lightcuts use the (1 + epsilon) heuristic in HG media; default 1
    uint32_t partitionSize = 2048;
    uint32_t cutSize = 32;  // vrl-stochastic
    uint32_t vrlSets = 1;   // vrl-stochastic
    uint32_t distanceSamples = kDefaultVplDistanceSamples;  // vpl, vpl-lightcuts: per camera segment
    uint32_t shadingPoints = 1;  // vrl, vrl-lightcuts, vpl, vpl-lightcuts: K x K points per pixel for (c), (d)
    std::optional<uint64_t> surfaceVpls;  // vrl, vrl-lightcuts: the most surface VPLs; 0: none; empty: the default
    // Distributed rendering (render --workers, submit)
    int workers = 0;       // render: 0 embedded, N: a local coordinator and N worker processes
    uint32_t tileSize = 32;
};

// Registers the scene, output and every render flag on `cmd`.
void addRenderOptions(CLI::App& cmd, RenderCommandOptions& o);

// Warns (spdlog, naming the flag and the method) about every flag given on
// `command` that has no effect on `method` (e.g. --error with path; --tile-size
// without --workers when `distributed` is false).
void warnIneffectiveFlags(const CLI::App& command, RenderMethod method, bool distributed);

// Throws std::invalid_argument, with the estimate, when the VRL set and light
// tree of `settings` (estimateLightMemoryBytes) would not fit in `memoryBytes`.
void checkLightMemory(const RenderSettings& settings, uint64_t memoryBytes);

// The job's parameters (width/height 0 when no --resolution); throws
// std::invalid_argument for a malformed or out-of-range --resolution or a
// malformed --crop (the crop is checked against the film by rpc::resolveJob).
v1::RenderParameters toRenderParameters(const RenderCommandOptions& o);
// The whole job spec of the flags (name, `defines`, medium, parameters, tile
// size; no bundle): what `vrl render` resolves in-process and what `--workers`
// and `vrl submit` send (command_line_job.h builds it once).
v1::JobSpec makeJobSpec(const RenderCommandOptions& o, const std::map<std::string, std::string>& defines);

}  // namespace vrl::client
