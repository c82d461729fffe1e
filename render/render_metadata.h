// The one writer of a render's metadata: what every EXR of ours says about how
// it was made, whether it was rendered in this process (`vrl render`), by a
// coordinator and its workers (`--workers`, `vrl submit`) or by the benchmark
// report. One writer, so that the same job gives the same keys and values
// whichever way it ran; only vrl.time.* (timings) and vrl.run.* (threads,
// workers, job id: how it ran) may differ.
//
// Keys and types (EXR attribute types; numbers are never strings):
//   vrl.version, vrl.scene, vrl.method, vrl.defines ("a=1 b=2", sorted), vrl.medium,
//   vrl.approximations, vrl.ignored                                   string
//   vrl.seed                                        string (a 64-bit value: no EXR int holds it)
//   vrl.spp, vrl.maxDepth, vrl.jitter (0/1), vrl.width, vrl.height    int (the image: the crop's size)
//   progressive renders only (a time limit): vrl.spp is the samples per pixel of the completed
//     passes (statistics.samplesPerPixel); vrl.progressive.passes, vrl.progressive.sppCap (int:
//     the completed passes, the cap asked for), vrl.progressive.timeLimit (double seconds)
//   cropped renders only: vrl.crop ("x0,y0,width,height" in film pixels), vrl.film ("WxH")  string
//   methods with virtual lights: vrl.transport (string), vrl.vrlSamples (int),
//     vrl.vrls or vrl.vpls, vrl.lightPaths (double: counts beyond 2^31)
//   Lightcuts: vrl.error, vrl.hgEpsilon (float); vrl.maxCut, vrl.exactDistanceBelow,
//     vrl.partitionSize (int); vrl.meanEval, vrl.meanInter, vrl.meanCut,
//     vrl.boundExceeded, vrl.boundedEstimates (double); with part (c) by VRLs:
//     vrl.surface.meanEval, vrl.surface.meanInter, vrl.surface.meanCut (double)
//   VPL methods: vrl.vplDistanceSamples (int)
//   vrl.time.<phase> (double seconds): lightTracing, treeBuild, render, and the caller's phases
//   vrl.run.<name>: the caller's (threads, workers, job)
//   worldToCamera, worldToNDC (M44f): OpenEXR's standard camera attributes (camera.h);
//     worldToNDC spans the image written (the crop window when cropped)
#pragma once

#include "render/image/metadata.h"
#include "render/renderer.h"

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vrl {

class PerspectiveCamera;

// What went into a render and how it went.
struct RenderRecord {
    std::string scene;                              // the scene file as the user named it
    std::map<std::string, std::string> defines;     // -D name=value
    std::string medium;                             // --medium, empty if none
    std::map<std::string, std::string> sceneNotes;  // sceneNotes(description): approximations, ignored plugins
    RenderSettings settings;                        // as resolved (the scene's spp and depth filled in)
    RenderStatistics statistics;                    // light tracing, tree, shading, cut statistics
    std::vector<std::pair<std::string, double>> phases;  // further vrl.time.<phase> entries (parse, build, ...)
    Metadata run;                                   // vrl.run.<key> entries
};

// Writes the record's keys into `metadata` (replacing entries of the same key).
void writeRenderMetadata(const RenderRecord& record, const PerspectiveCamera& camera, Metadata& metadata);

}  // namespace vrl
