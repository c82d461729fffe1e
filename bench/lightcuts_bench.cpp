// lightcuts_bench: VRL Lightcuts against plain VRLs on a scene (default: the
// default scene), for several VRL counts, for part (d) (medium-to-medium, the
// paper's) or, with --part medium-surface, part (c) (VRL-lit surfaces). Prints, per N: light tracing time,
// hybrid tree build time and memory, the global agglomerative build's time and
// the hybrid tree's extra gathering cost against it (N <= --global-max), and the
// shading time of part (d) with plain VRLs and with Lightcuts at the error
// threshold, their ratio, the relative RMSE between the two images and #Eval,
// #Inter and cut size per pixel (the paper's Table 1). Timings are wall-clock,
// one run each, on whatever cores TBB gets: compare ratios, not seconds.
// With --build-only it traces and builds the tree only, handing the VRLs over to
// the build as the renderer does, and prints the process's peak resident set so
// far (the scale of the tree: 10^7 VRLs and more); -v logs the build's phases.
// plain_ns and cut_ns: shading time per VRL estimate and core (wall time x TBB's
// threads / estimates): plain VRLs make one estimate per VRL and shaded pixel
// (one camera segment per pixel, as in the default scene: every ray ends on a
// wall), the cut #Eval; the kernel's cost, with the cut's overhead in cut_ns.
// With --hg-compare (scenes with Henyey-Greenstein media) it compares the two HG
// bounds of VRL cuts (cluster_bound.h), the proven cone bound and the paper's
// (1 + --hg-epsilon) heuristic, over the error thresholds of --errors: per
// threshold and bound, the cut's time, its relative RMSE against plain VRLs of
// the same set and streams, #Eval, cut size and the share of cluster estimates
// above their bound; then, at each heuristic point, the cone bound's time at
// the same relative RMSE (log-log interpolation between its bracketing points)
// over the heuristic's time: the "slower at equal error" ratio.
#include "bench/bench_lights.h"
#include "bench/bench_scene_arguments.h"
#include "render/core/timing.h"
#include "render/description/scene_description.h"
#include "render/image/image_metrics.h"
#include "render/integrators/transport_integrator.h"
#include "render/lightcuts/tree/light_tree.h"
#include "render/image/exr_io.h"
#include "render/lightcuts/cuts/lightcuts_estimator.h"
#include "render/scene/scene.h"
#include "render/scene_io/mitsuba/mitsuba_parser.h"
#include "render/vrl/light_tracer.h"
#include "render/vrl/vrl_kernel.h"
#include "tests/support/test_scenes.h"
#include "util/command_line.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <tuple>
#include <vector>

using namespace vrl;

namespace {

struct Shading {
    Image image;
    double seconds = 0.0;
    CutStatistics total;
    uint64_t boundExceeded = 0, boundedEstimates = 0;
};

// Part (d) or (c) on every `stride`-th pixel in x and y (the others stay black).
Shading shade(const Scene& scene, const VrlSet& vrls, const LightTree* tree, float error, int stride, uint64_t seed,
              bool surfacePart, const ClusterBoundSettings& bound = {}) {
    TransportIntegratorSettings settings;
    settings.transports = TransportSelection::parse(surfacePart ? "medium-surface" : "multiple");
    settings.cut.errorThreshold = error;
    settings.cut.bound = bound;
    const TransportIntegrator integrator(scene, vrls, settings, tree);
    const PerspectiveCamera& camera = scene.camera();
    Shading out;
    out.image = Image(camera.width(), camera.height());
    std::atomic<uint64_t> evaluated{0}, intersected{0}, cutSize{0}, exceeded{0}, bounded{0};
    const auto start = std::chrono::steady_clock::now();
    tbb::parallel_for(0, (camera.height() + stride - 1) / stride, [&](int row) {
        const int y = row * stride;
        for (int x = 0; x < camera.width(); x += stride) {
            Rng rng(seed, uint64_t(y) * camera.width() + x);
            CutStatistics stats;
            const auto parts = integrator.virtualLightParts(camera.generateRay(x + 0.5f, y + 0.5f), rng, &stats, &stats);
            out.image.at(x, y) = surfacePart ? parts.mediumSurface : parts.multiple;
            evaluated += stats.evaluated, intersected += stats.intersected, cutSize += stats.cutSize;
            exceeded += stats.boundExceeded, bounded += stats.boundedEstimates;
        }
    });
    out.seconds = secondsSince(start);
    out.total = {uint32_t(evaluated.load()), uint32_t(intersected.load()), uint32_t(cutSize.load())};
    out.boundExceeded = exceeded.load(), out.boundedEstimates = bounded.load();
    return out;
}

struct HgPoint {
    float error;
    double seconds, relativeRmse, evaluated, cutSize, exceededShare;
};

// Time at relative RMSE `target` on the curve `points` (log-log interpolation between
// the two points that bracket it); negative when no two points do.
double secondsAtError(const std::vector<HgPoint>& points, double target) {
    for (size_t i = 0; i < points.size(); ++i)
        for (size_t j = 0; j < points.size(); ++j) {
            const HgPoint &a = points[i], &b = points[j];
            if (!(a.relativeRmse <= target && target <= b.relativeRmse) || a.relativeRmse == b.relativeRmse) continue;
            const double t = std::log(target / a.relativeRmse) / std::log(b.relativeRmse / a.relativeRmse);
            return std::exp(std::log(a.seconds) + t * (std::log(b.seconds) - std::log(a.seconds)));
        }
    return -1.0;
}

// --hg-compare: the two HG bounds over the error thresholds, against plain VRLs.
void compareHgBounds(const Scene& scene, const VrlSet& vrls, const LightTree& tree, const std::vector<float>& errors,
                     float epsilon, int stride, double pixels, bool surfacePart) {
    const Shading plain = shade(scene, vrls, nullptr, 0.0f, stride, 1, surfacePart);
    std::printf("  plain VRLs: %.2f s\n", plain.seconds);
    std::printf("  %-8s %8s %8s %9s %8s %8s %10s\n", "bound", "error", "cuts_s", "relRMSE", "#Eval", "cut",
                "exceeded%");
    std::vector<HgPoint> curves[2];
    for (float error : errors) {
        for (int b = 0; b < 2; ++b) {
            ClusterBoundSettings bound;
            bound.hgBound = b == 0 ? HgBound::Cones : HgBound::Epsilon;
            bound.anisotropyEpsilon = epsilon;
            const Shading cut = shade(scene, vrls, &tree, error, stride, 1, surfacePart, bound);
            const HgPoint p{error, cut.seconds, compareImages(plain.image, cut.image).relativeRmse,
                            cut.total.evaluated / pixels, cut.total.cutSize / pixels,
                            100.0 * double(cut.boundExceeded) / double(std::max<uint64_t>(1, cut.boundedEstimates))};
            curves[b].push_back(p);
            std::printf("  %-8s %8.3f %8.2f %9.5f %8.0f %8.0f %10.4f\n", b == 0 ? "cones" : "epsilon", error, p.seconds,
                        p.relativeRmse, p.evaluated, p.cutSize, p.exceededShare);
            std::fflush(stdout);
        }
    }
    for (const HgPoint& e : curves[1]) {
        const double cones = secondsAtError(curves[0], e.relativeRmse);
        if (cones > 0.0)
            std::printf("  at relRMSE %.5f (epsilon, error %.3f: %.2f s) the cone bound takes %.2f s: %.2fx\n",
                        e.relativeRmse, e.error, e.seconds, cones, cones / e.seconds);
        else
            std::printf("  at relRMSE %.5f (epsilon, error %.3f) the cone bound's curve does not reach: no ratio\n",
                        e.relativeRmse, e.error);
    }
}

// Peak resident set of this process so far, in MB.
double peakResidentMb() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) * 1024.0 / 1e6;
}

// --build-only: light tracing and the hybrid build, nothing else.
void buildOnly(const Scene& scene, int maxDepth, const std::vector<uint64_t>& counts) {
    std::printf("%9s %8s %9s %8s %9s\n", "VRLs", "trace_s", "build_s", "tree_MB", "peak_MB");
    for (uint64_t n : counts) {
        LightTracingSettings tracing;
        tracing.targetVrls = n;
        tracing.maxDepth = maxDepth;
        auto start = std::chrono::steady_clock::now();
        VrlSet vrls = traceVrls(scene, tracing);
        const double traceSeconds = secondsSince(start);
        const size_t count = vrls.vrls.size();
        start = std::chrono::steady_clock::now();
        const LightTree tree = LightTree::build(std::move(vrls.vrls));
        const double buildSeconds = secondsSince(start);
        std::printf("%9zu %8.3f %9.3f %8.1f %9.1f\n", count, traceSeconds, buildSeconds, tree.memoryBytes() / 1e6,
                    peakResidentMb());
        std::fflush(stdout);
    }
    std::printf("peak_MB: the process's peak resident set so far (getrusage)\n");
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"VRL Lightcuts against plain VRLs (part (d), or part (c))"};
    std::string part = "multiple";
    std::string scenePath = "scenes/smoke-room.xml";
    std::vector<uint64_t> counts = {10000, 100000, 1000000};
    std::string resolution = "64x48";
    float error = 0.02f;
    uint64_t globalMax = 100000;
    uint64_t strideAbove = 200000;
    int stride = 4;
    std::vector<std::string> defines;
    bool buildOnlyMode = false, verbose = false, hgCompare = false;
    std::vector<float> errors = {0.005f, 0.01f, 0.02f, 0.05f, 0.1f, 0.2f, 0.5f, 1.0f, 2.0f};
    float hgEpsilon = 1.0f;
    float sphereBeyond = 0.0f;
    app.add_option("--scene", scenePath,
                   "Scene file (default scenes/smoke-room.xml), or lit-room / infinite: the tests' lit room with its "
                   "occluder, a point light in an unbounded medium (-D g=... for HG)");
    app.add_option("-D,--define", defines, "Override a scene <default>: -D name=value (repeatable)");
    app.add_option("--vrls", counts, "VRL counts to run (default 10000 100000 1000000)");
    app.add_option("--resolution", resolution, "Image size WxH for shading (default 64x48)");
    app.add_option("--error", error, "Lightcuts error threshold (default 0.02)");
    app.add_option("--global-max", globalMax, "Largest N for the global agglomerative baseline (default 100000)");
    app.add_option("--stride-above", strideAbove, "Above this N, shade every --stride-th pixel in x and y (default 200000)");
    app.add_option("--stride", stride, "Pixel stride for large N (default 4: 1/16 of the pixels)");
    app.add_option("--part", part, "Transport part: multiple (d, default) or medium-surface (c)")
        ->check(CLI::IsMember({"multiple", "medium-surface"}));
    app.add_flag("--build-only", buildOnlyMode, "Trace and build the light tree only: build time, tree size, peak memory");
    app.add_flag("--hg-compare", hgCompare,
                 "Compare the proven HG cone bound with the (1 + --hg-epsilon) heuristic over --errors");
    app.add_option("--errors", errors, "--hg-compare: error thresholds (default 0.005 ... 2: the cone bound needs larger ones for the same error)");
    app.add_option("--hg-epsilon", hgEpsilon,
                   "--hg-compare: the heuristic's epsilon (default 1); otherwise, given: the cuts bound HG media by "
                   "this heuristic instead of the proven bound (as builds before the proven bound did)");
    app.add_option("--sphere-beyond", sphereBeyond,
                   "Nodes above the exact-distance size take h_min from their bounding sphere when it is beyond this "
                   "many radii (default 0: always the box)");
    std::string plainExr;
    app.add_option("--plain-exr", plainExr,
                   "Write each N's plain-VRL image to PREFIX-N.exr (to compare builds with `vrl compare`)");
    app.add_flag("-v,--verbose", verbose, "Log the light tree build's phases (spdlog debug)");
    CLI11_PARSE(app, argc, argv);
    const bool surfacePart = part == "medium-surface";
    if (verbose) spdlog::set_level(spdlog::level::debug);

    const auto arguments = bench::parseSceneArguments(defines, resolution);
    if (!arguments) return 2;
    const ParseOptions& parseOptions = arguments->parseOptions;
    const int w = arguments->width, h = arguments->height;
    // The built-in test scenes (tests/support/test_scenes.h): `lit-room`, the lit room
    // with its occluder (isotropic, sigma_s 0.4, sigma_a 0.1; -D g=... sets HG), and
    // `infinite`, a point light in an unbounded medium (no surfaces: no occlusion rays).
    const auto builtinG = [&] {
        const auto g = parseOptions.defines.find("g");
        return g == parseOptions.defines.end() ? 0.0f : std::stof(g->second);
    };
    SceneDescription description =
        scenePath == "lit-room"   ? test::litRoomWithOccluder(Rgb(0.4f), Rgb(0.1f), builtinG())
        : scenePath == "infinite" ? test::pointLightInInfiniteMedium(Rgb(10.0f), Vec3(0.0f), Rgb(0.4f), Rgb(0.1f), builtinG())
                                  : parseMitsubaScene(scenePath, parseOptions);
    description.sensor.width = w;
    description.sensor.height = h;
    const auto scene = Scene::build(description);
    std::string defined;
    for (const auto& d : defines) defined += " -D " + d;
    if (buildOnlyMode) {
        std::printf("scene %s%s, light tree build only\n", scenePath.c_str(), defined.c_str());
        buildOnly(*scene, description.integrator.maxDepth, counts);
        return 0;
    }
    if (hgCompare) {
        std::printf("scene %s%s, %dx%d, part %s only: HG bounds, cones against epsilon = %g\n", scenePath.c_str(),
                    defined.c_str(), w, h, surfacePart ? "(c) medium-to-surface" : "(d) medium-to-medium", hgEpsilon);
        for (uint64_t n : counts) {
            const bench::BenchLights lights = bench::traceAndBuild(*scene, n, description.integrator.maxDepth);
            const int s = n > strideAbove ? stride : 1;
            std::printf("%zu VRLs%s\n", lights.vrls.vrls.size(), s > 1 ? " (1/16 of the pixels)" : "");
            compareHgBounds(*scene, lights.vrls, lights.tree, errors, hgEpsilon, s, double((w + s - 1) / s) * ((h + s - 1) / s),
                            surfacePart);
        }
        return 0;
    }
    ClusterBoundSettings bound;
    if (app.count("--hg-epsilon") > 0) bound.hgBound = HgBound::Epsilon, bound.anisotropyEpsilon = hgEpsilon;
    bound.sphereDistanceBeyond = sphereBeyond;
    std::printf("scene %s%s, %dx%d, error threshold %.3f, part %s only\n", scenePath.c_str(), defined.c_str(), w, h,
                error, surfacePart ? "(c) medium-to-surface" : "(d) medium-to-medium");
    if (bound.hgBound == HgBound::Epsilon)
        std::printf("HG media: the heuristic bound, isotropic x (1 + %g)\n", double(bound.anisotropyEpsilon));
    std::printf("VRL kernel: %s lanes; plain_ns, cut_ns: ns per VRL estimate and core (1e9 / that: estimates per second "
                "and core)\n", vrlKernelTarget());
    std::printf("%9s %8s %9s %8s %9s %10s %9s %9s %8s %9s %8s %8s %8s %9s %8s\n", "VRLs", "trace_s", "build_s", "tree_MB",
                "global_s", "gatherX", "plain_s", "cuts_s", "speedup", "relRMSE", "#Eval", "#Inter", "cut", "plain_ns",
                "cut_ns");
    const double cores = double(tbb::info::default_concurrency());
    for (uint64_t n : counts) {
        const bench::BenchLights lights = bench::traceAndBuild(*scene, n, description.integrator.maxDepth);
        const VrlSet& vrls = lights.vrls;
        const LightTree& tree = lights.tree;
        const double traceSeconds = lights.traceSeconds, buildSeconds = lights.buildSeconds;
        const int s = n > strideAbove ? stride : 1;
        const double pixels = double((w + s - 1) / s) * ((h + s - 1) / s);
        const Shading cuts = shade(*scene, vrls, &tree, error, s, 1, surfacePart, bound);
        const Shading plain = shade(*scene, vrls, nullptr, error, s, 1, surfacePart);
        std::string global = "-", gather = "-";
        if (n <= globalMax) {
            const auto start = std::chrono::steady_clock::now();
            const LightTree globalTree = LightTree::build(vrls.vrls, LightTreeSettings{uint32_t(vrls.vrls.size()), 0});
            global = std::to_string(secondsSince(start)).substr(0, 7);
            const Shading globalCuts = shade(*scene, vrls, &globalTree, error, s, 1, surfacePart, bound);
            gather = std::to_string(double(cuts.total.evaluated) / std::max(1u, globalCuts.total.evaluated)).substr(0, 5);
        }
        const ImageErrorMetrics m = compareImages(plain.image, cuts.image);
        if (!plainExr.empty()) {
            ImageSet set;
            set.image = plain.image;
            writeExr(plainExr + "-" + std::to_string(n) + ".exr", set);
        }
        const double plainNs = plain.seconds * cores * 1e9 / (pixels * double(vrls.vrls.size()));
        const double cutNs = cuts.seconds * cores * 1e9 / std::max(1.0, double(cuts.total.evaluated));
        std::printf("%9zu %8.3f %9.3f %8.1f %9s %10s %9.2f %9.2f %8.1f %9.5f %8.0f %8.0f %8.0f %9.0f %8.0f%s\n",
                    vrls.vrls.size(), traceSeconds, buildSeconds, tree.memoryBytes() / 1e6, global.c_str(),
                    gather.c_str(), plain.seconds, cuts.seconds, plain.seconds / cuts.seconds, m.relativeRmse,
                    cuts.total.evaluated / pixels, cuts.total.intersected / pixels, cuts.total.cutSize / pixels, plainNs,
                    cutNs, s > 1 ? "  (1/16 of the pixels)" : "");
        std::fflush(stdout);
    }
    std::printf("gatherX: #Eval of the hybrid tree over #Eval of the global agglomerative tree (paper: 1.25)\n");
    return 0;
}
