#include "client/commands.h"
#include "client/progress_bar.h"

#include "render/exr_io.h"
#include "render/mitsuba_parser.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "render/vrl.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <regex>

namespace vrl {

namespace {

struct RenderCommandOptions {
    std::string scene;
    std::string output;
    std::vector<std::string> defines;
    std::string method = "path";
    int spp = 0;  // 0: the scene's sampleCount
    std::string resolution;  // "WxH", empty: the scene's film
    int threads = 0;         // 0: all cores
    uint64_t seed = 0;
    int maxDepth = -2;  // -2: the scene's integrator maxDepth
    bool jitter = false;
    bool quiet = false;
    uint64_t vrls = 100000;
    uint64_t lightPaths = 0;
    int vrlSamples = 1;
    std::string transport = "surface,single,medium-surface,multiple";
    float error = 0.02f;
    uint32_t maxCut = 4096;
    uint32_t exactDistanceBelow = 32;
    float hgEpsilon = 1.0f;
    uint32_t partitionSize = 2048;
};

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

double peakMemoryMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

int runRender(const RenderCommandOptions& o) {
    if (o.quiet) spdlog::set_level(spdlog::level::warn);
    using Clock = std::chrono::steady_clock;
    ParseOptions parseOptions;
    for (const auto& d : o.defines) {
        const auto eq = d.find('=');
        if (eq == std::string::npos || eq == 0) {
            std::fprintf(stderr, "vrl render: error: -D expects name=value, got '%s'\n", d.c_str());
            return 2;
        }
        parseOptions.defines[d.substr(0, eq)] = d.substr(eq + 1);
    }

    auto t0 = Clock::now();
    SceneDescription description = parseMitsubaScene(o.scene, parseOptions);
    if (!o.resolution.empty()) {
        std::smatch match;
        const std::regex pattern("^([0-9]{1,9})x([0-9]{1,9})$");
        if (!std::regex_match(o.resolution, match, pattern)) {
            std::fprintf(stderr, "vrl render: error: --resolution expects WxH (e.g. 640x480), got '%s'\n",
                         o.resolution.c_str());
            return 2;
        }
        description.sensor.width = std::stoi(match[1]);
        description.sensor.height = std::stoi(match[2]);
    }
    const auto& sensor = description.sensor;
    if (sensor.width < 1 || sensor.height < 1 || sensor.width > kMaxFilmSide || sensor.height > kMaxFilmSide ||
        (long long)sensor.width * sensor.height > kMaxFilmPixels) {
        std::fprintf(stderr,
                     "vrl render: error: resolution %dx%d is outside the supported range (1..%d per side, at most "
                     "%lld pixels)\n",
                     sensor.width, sensor.height, kMaxFilmSide, kMaxFilmPixels);
        return 2;
    }
    RenderSettings settings;
    settings.method = o.method;
    settings.samplesPerPixel = o.spp > 0 ? o.spp : sensor.sampleCount;
    settings.seed = o.seed;
    settings.jitter = o.jitter;
    settings.maxDepth = o.maxDepth >= -1 ? o.maxDepth : description.integrator.maxDepth;
    settings.transports = TransportSelection::parse(o.transport);
    settings.vrlCount = o.vrls;
    settings.lightPaths = o.lightPaths;
    settings.vrlSamples = o.vrlSamples;
    settings.cut.errorThreshold = o.error;
    settings.cut.maxCutSize = o.maxCut;
    settings.cut.bound.exactDistanceBelow = o.exactDistanceBelow;
    settings.cut.bound.anisotropyEpsilon = o.hgEpsilon;
    settings.partitionSize = o.partitionSize;
    const double parseSeconds = secondsSince(t0);

    t0 = Clock::now();
    const auto scene = Scene::build(description);
    const double buildSeconds = secondsSince(t0);

    const int threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
    tbb::task_arena arena(threads);
    // One bar per phase ("light tracing", then "rendering").
    std::mutex barMutex;
    std::unique_ptr<ProgressBar> bar;
    std::string barPhase;
    const ProgressCallback progress = [&](const char* phase, double f) {
        {
            std::lock_guard lock(barMutex);
            if (barPhase != phase) {
                if (bar) bar->finish();
                barPhase = phase;
                bar = std::make_unique<ProgressBar>(phase);
            }
        }
        bar->update(f);
    };
    RenderStatistics stats;
    ImageSet images;
    arena.execute([&] { images = render(*scene, settings, o.quiet ? ProgressCallback{} : progress, &stats); });
    if (bar) bar->finish();

    t0 = Clock::now();
    images.metadata["vrl.version"] = VRL_VERSION;
    images.metadata["vrl.scene"] = o.scene;
    images.metadata["vrl.method"] = settings.method;
    images.metadata["vrl.spp"] = std::to_string(settings.samplesPerPixel);
    images.metadata["vrl.seed"] = std::to_string(settings.seed);
    images.metadata["vrl.maxDepth"] = std::to_string(settings.maxDepth);
    images.metadata["vrl.jitter"] = settings.jitter ? "true" : "false";
    images.metadata["vrl.threads"] = std::to_string(threads);
    std::string defines;
    for (const auto& d : o.defines) defines += (defines.empty() ? "" : " ") + d;
    images.metadata["vrl.defines"] = defines;
    images.metadata["vrl.time.parse"] = std::to_string(parseSeconds);
    images.metadata["vrl.time.build"] = std::to_string(buildSeconds);
    images.metadata["vrl.time.render"] = std::to_string(stats.seconds);
    if (settings.method == "vrl-lightcuts") {
        images.metadata["vrl.error"] = std::to_string(o.error);
        images.metadata["vrl.maxCut"] = std::to_string(o.maxCut);
        images.metadata["vrl.exactDistanceBelow"] = std::to_string(o.exactDistanceBelow);
        images.metadata["vrl.hgEpsilon"] = std::to_string(o.hgEpsilon);
        images.metadata["vrl.partitionSize"] = std::to_string(o.partitionSize);
        images.metadata["vrl.time.treeBuild"] = std::to_string(stats.treeSeconds);
    }
    if (settings.method != "path") {
        images.metadata["vrl.transport"] = settings.transports.toString();
        images.metadata["vrl.vrlSamples"] = std::to_string(settings.vrlSamples);
        images.metadata["vrl.vrlCount"] = std::to_string(stats.vrlCount);
        images.metadata["vrl.lightPaths"] = std::to_string(stats.lightPaths);
        images.metadata["vrl.time.lightTracing"] = std::to_string(stats.tracingSeconds);
    }
    writeExr(o.output, images);
    const double writeSeconds = secondsSince(t0);

    std::fprintf(stderr,
                 "summary: %s, %dx%d, method %s, %d spp, seed %llu, %d threads\n"
                 "  parse  %8.3f s\n  build  %8.3f s (%zu shapes, %zu media, %zu emitters)\n"
                 "  render %8.3f s (%llu camera samples, %.3g samples/s)\n  write  %8.3f s -> %s\n"
                 "  peak memory %.1f MiB\n",
                 o.scene.c_str(), sensor.width, sensor.height, settings.method.c_str(), settings.samplesPerPixel,
                 (unsigned long long)settings.seed, threads, parseSeconds, buildSeconds, scene->shapes().size(),
                 scene->media().size(), scene->emitters().size(), stats.seconds,
                 (unsigned long long)stats.cameraSamples,
                 stats.seconds > 0 ? double(stats.cameraSamples) / stats.seconds : 0.0, writeSeconds,
                 o.output.c_str(), peakMemoryMiB());
    if (settings.method != "path") {
        std::fprintf(stderr, "  light tracing %.3f s: %llu light paths -> %llu VRLs, %.1f MiB (%zu bytes each)\n",
                     stats.tracingSeconds, (unsigned long long)stats.lightPaths, (unsigned long long)stats.vrlCount,
                     double(stats.vrlBytes) / (1024.0 * 1024.0), sizeof(Vrl));
        std::fprintf(stderr, "  transport parts: %s\n", settings.transports.toString().c_str());
    }
    if (settings.method == "vrl-lightcuts") {
        std::fprintf(stderr, "  light tree %.3f s, %.1f MiB; per pixel: #Eval %.1f, #Inter %.1f, cut size %.1f\n",
                     stats.treeSeconds, double(stats.treeBytes) / (1024.0 * 1024.0), stats.meanEvaluated,
                     stats.meanIntersected, stats.meanCutSize);
        std::fprintf(stderr, "  bound exceeded by %llu of %llu cluster estimates (%.4f%%)\n",
                     (unsigned long long)stats.boundExceeded, (unsigned long long)stats.boundedEstimates,
                     stats.boundedEstimates ? 100.0 * double(stats.boundExceeded) / double(stats.boundedEstimates) : 0.0);
    }
    return 0;
}

}  // namespace

void registerRenderCommand(CLI::App& app, int& exitCode) {
    auto o = std::make_shared<RenderCommandOptions>();
    auto* cmd = app.add_subcommand("render", "Render a Mitsuba 0.5/0.6 XML scene to an OpenEXR image");
    cmd->add_option("scene", o->scene, "Scene file (Mitsuba 0.5/0.6 XML subset)")->required();
    cmd->add_option("-o,--output", o->output, "Output OpenEXR file")->required();
    cmd->add_option("-D,--define", o->defines, "Override a scene <default>: -D name=value (repeatable)");
    cmd->add_option("--method", o->method,
                    "Rendering method: path (volumetric path tracer, the reference), vrl (transport parts "
                    "(a)-(c) by path sampling, multiple scattering (d) by plain VRLs) or vrl-lightcuts (the same, "
                    "(d) by cuts through a VRL light tree)")
        ->check(CLI::IsMember(kRenderMethods));
    cmd->add_option("--spp", o->spp, "Samples per pixel (default: the scene's sampler sampleCount)")
        ->check(CLI::Range(1, kMaxSampleCount));
    cmd->add_option("--resolution", o->resolution, "Image size WxH, overriding the scene's film (e.g. 640x480)");
    cmd->add_option("--threads", o->threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 4096));
    cmd->add_option("--seed", o->seed, "Random seed; equal seeds give bit-identical images (default 0)");
    cmd->add_option("--max-depth", o->maxDepth,
                    "Path length as Mitsuba's maxDepth: 1 emitters only, 2 direct + single scattering, -1 unlimited "
                    "(default: the scene's integrator)")
        ->check(CLI::Validator(
            [](std::string& value) {
                const int depth = std::atoi(value.c_str());
                return depth == -1 || (depth >= 1 && depth <= 100000) ? std::string()
                                                                     : std::string("must be -1 or 1..100000");
            },
            "-1 or 1..100000"));
    cmd->add_option("--vrls", o->vrls, "vrl: target number of VRLs; whole light paths are traced until reached")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 32));
    cmd->add_option("--light-paths", o->lightPaths, "vrl: trace exactly this many light paths (overrides --vrls)")
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40));
    cmd->add_option("--vrl-samples", o->vrlSamples, "vrl: (u, v) samples per VRL and camera segment (default 1)")
        ->check(CLI::Range(1, 1 << 16));
    cmd->add_option("--transport", o->transport,
                    "vrl: parts to render, comma-separated: surface (a), single (b), medium-surface (c), multiple (d); "
                    "each is also written as an EXR layer (default: all four)");
    cmd->add_option("--error", o->error,
                    "vrl-lightcuts: relative error threshold; a node is refined while its bound exceeds this times "
                    "the current estimate (default 0.02)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd->add_option("--max-cut", o->maxCut, "vrl-lightcuts: most nodes in one cut, a safety valve (default 4096)")
        ->check(CLI::Range(1u, 1u << 30));
    cmd->add_option("--exact-distance-below", o->exactDistanceBelow,
                    "vrl-lightcuts: nodes with at most this many VRLs take their distance to the camera ray from "
                    "their VRLs rather than their box (default 32)")
        ->check(CLI::Range(0u, 1u << 20));
    cmd->add_option("--hg-epsilon", o->hgEpsilon,
                    "vrl-lightcuts: Henyey-Greenstein media multiply the isotropic bound by (1 + this) (default 1)")
        ->check(CLI::Range(0.0f, 1e6f));
    cmd->add_option("--partition-size", o->partitionSize,
                    "vrl-lightcuts: VRLs per partition before agglomerative clustering (default 2048)")
        ->check(CLI::Range(2u, 1u << 30));
    cmd->add_flag("--jitter", o->jitter, "Jitter camera rays inside pixels (default: through pixel centres)");
    cmd->add_flag("-q,--quiet", o->quiet, "No progress bar and no informational logs");
    cmd->callback([o, &exitCode] {
        try {
            exitCode = runRender(*o);
        } catch (const SceneError& e) {
            std::fprintf(stderr, "vrl render: scene error: %s\n", e.what());
            exitCode = 2;
        } catch (const std::invalid_argument& e) {
            std::fprintf(stderr, "vrl render: error: %s\n", e.what());
            exitCode = 2;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "vrl render: error: %s\n", e.what());
            exitCode = 1;
        }
    });
}

}  // namespace vrl
