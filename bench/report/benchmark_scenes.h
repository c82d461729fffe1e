// The benchmark scenes of the error-against-time report and the settings each
// method is run with (full and --quick). Paths to the paper's scenes are
// relative to the shared scene folder; our own are in the repository.
#pragma once

#include "render/renderer.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace vrl::report {

// A reference half is rendered in kReferenceChunks chunks (part (d): at least
// that many, BenchmarkScene::partReferenceChunks), each with its own seeds (so its
// own random streams and, for part (d), its own VRL sets), saved after each chunk:
// a long reference can be built over several runs.
constexpr int kReferenceChunks = 8;

// One render of the sweep. `lights`: VRLs or VPLs (0 for the path tracer);
// `spp`: samples per pixel (path tracer; parts (a)-(c) of the virtual-light
// methods; for stochastic VRL Lightcuts also parts (c) and (d): each sample
// draws new cuts); `cutSize`: stochastic VRL Lightcuts' K (0 for the others);
// `distanceSamples`: VPL Lightcuts' distance samples per camera segment (0: the
// renderer's default, 32; the label shows any other value as "D=...").
struct MethodRun {
    RenderMethod method = RenderMethod::Path;
    uint64_t lights = 0;
    int spp = 1;
    float errorThreshold = 0.02f;
    uint32_t cutSize = 0;
    int distanceSamples = 0;
    bool multipleOnly = false;  // part (d) alone (the paper's Figure 3 comparison), against the (d) reference
    // Renders of this point, each from its own seed: the point's error is the
    // root-mean-square of their RMSEs (the square root of an estimate of the
    // expected MSE, what falls as 1/time for an unbiased method) and its time
    // their mean. More than one for the cheapest points, where one render's error
    // moves most with the seed and a repeat costs least.
    int repeats = 1;
    std::string label() const;  // no commas (a CSV field)
    // The curve the run belongs to: method, and threshold or cut size where a method has several.
    std::string curve() const;
    // The run's seed in scene `scene`: a hash of the scene's name, the curve and the
    // label, so that every run has its own random streams (no two share the noise of
    // parts (a)-(c)) and keeps them when runs are added to or removed from the sweep.
    // Render `repeat` (0 to repeats - 1) of the point: repeat 0 has that hash, the
    // others hash "\nrepeat k" after it too.
    uint64_t seed(const std::string& scene, int repeat = 0) const;
};

struct BenchmarkScene {
    std::string name;
    std::string description;
    std::filesystem::path file;     // absolute, or relative to the shared scenes / the repository
    bool shared = false;            // from ../shared/scenes (skipped with a reason when absent)
    std::map<std::string, std::string> defines;
    std::string medium;             // --medium fill, or empty
    // Its part (d) reference is checked against another method's estimate
    // (stochastic VRL Lightcuts over independent VRL sets; stored beside it).
    bool checkPartReference = false;
    int width = 64, height = 48;
    int maxDepth = 12;              // the paper's "maximum path length is 12 for all the scenes"
    int referenceSpp = 256;         // path tracer; two independent halves of referenceSpp / 2
    // > 0: the whole image's reference is light tracing connected to the camera
    // (render/integrators/light_tracing_reference.h), this many light paths in all,
    // plus referenceSpp camera samples per pixel for what light tracing cannot
    // connect (the camera seeing glass, mirrors or emitters). For scenes lit
    // through specular surfaces, where the path tracer's reference is fireflies.
    uint64_t referenceLightPaths = 0;
    // Part (d)'s reference: plain VRLs (1 spp) over independent VRL sets, so that it
    // converges to the true transport; partReferenceSets sets of partReferenceVrls
    // VRLs in each of its chunks of each half (measured on bathroom at 320x180:
    // for the same noise, 2x less time than stochastic VRL Lightcuts over sets).
    uint64_t partReferenceVrls = 4000;
    int partReferenceSets = 5;
    // Chunks per half of part (d)'s reference (at least kReferenceChunks). More: built
    // in a second stage from the kReferenceChunks-chunk reference (`vrl_report --references`); until
    // then a report uses the 8-chunk one and says that it is short.
    int partReferenceChunks = kReferenceChunks;
    std::vector<MethodRun> runs;    // the whole image, then part (d) alone (multipleOnly)
    uint64_t tableLights = 100000;  // N of the Table 1 / Figure 6 runs (both Lightcuts at the default threshold)
    std::vector<uint64_t> speedupLights;  // N of the Figure 4 speed-up measurement
};

// The scene list. `repository`: the source tree (for scenes/); `shared`: the
// shared scene folder (may not exist). Every scene passes checkScene.
std::vector<BenchmarkScene> benchmarkScenes(bool quick, const std::filesystem::path& repository,
                                            const std::filesystem::path& shared);

// Throws std::logic_error naming the scene where two runs have the same curve and
// label (the same render under the same seed), a run has fewer than one render, or
// partReferenceChunks is below kReferenceChunks.
void checkScene(const BenchmarkScene& s);

// The settings `run` renders with in scene `s` (`seed`: its random streams).
RenderSettings settingsFor(const BenchmarkScene& s, const MethodRun& run, uint64_t seed);
// Render `repeat` of a run of the report: settingsFor with the run's own seed,
// run.seed(s.name, repeat), so the same run renders the same images wherever it
// stands in the sweep.
RenderSettings runSettings(const BenchmarkScene& s, const MethodRun& run, int repeat = 0);

}  // namespace vrl::report
