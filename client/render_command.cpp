#include "client/command_line_job.h"
#include "client/commands.h"
#include "client/job_client.h"
#include "client/local_cluster.h"
#include "client/progress_bar.h"
#include "client/remote_render.h"
#include "client/render_options.h"
#include "service/job/job_scene.h"
#include "service/job/scene_bundle.h"
#include "util/system_memory.h"
#include "util/termination_signals.h"

#include "render/core/timing.h"
#include "render/image/exr_io.h"
#include "render/image/partial_image.h"
#include "render/image/preview_image.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"
#include "render/render_metadata.h"
#include "render/renderer.h"
#include "render/scene/scene.h"
#include "render/vrl/vrl.h"

#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <csignal>
#include <chrono>
#include <thread>
#include <cstdio>
#include <memory>
#include <mutex>

namespace vrl::client {

namespace {

double coveredFraction(const RenderCoverage& coverage) {
    size_t covered = 0;
    for (const uint8_t c : coverage.covered) covered += c != 0;
    return coverage.covered.empty() ? 0.0 : double(covered) / double(coverage.covered.size());
}

const char* signalName(int signal) { return signal == SIGTERM ? "SIGTERM" : "SIGINT"; }

double peakMemoryMiB() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

// `--workers N`: the same render through a coordinator and N worker processes on loopback.
int runLocalCluster(const RenderCommandOptions& o, const CommandLineJob& job) {
    const int cores = tbb::info::default_concurrency();
    const int threadsPerWorker = o.threads > 0 ? o.threads : std::max(1, cores / o.workers);
    if (!o.quiet)
        std::fprintf(stderr, "starting a local coordinator and %d workers (%d threads each)\n", o.workers,
                     threadsPerWorker);
    // Ctrl-C / SIGTERM: keep the finished tiles as a partial EXR, then stop (a second one: at once).
    util::TerminationSignals signals;
    LocalCluster cluster(o.workers, threadsPerWorker, "warn");
    RemoteOptions remote;
    remote.address = cluster.address();
    remote.token = cluster.token();
    remote.retryFor = std::chrono::seconds(0);  // the local coordinator does not come back
    remote.noWorkerWarning = std::chrono::milliseconds(0);
    remote.partialOnSignal = true;
    // If every worker dies, cancel the job rather than wait for ever (a dead coordinator ends the watch by itself).
    std::atomic<bool> finished{false};
    std::thread watchdog([&] {
        while (!finished) {
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
            size_t workersExited = 0;
            for (const auto& name : cluster.exitedProcesses()) workersExited += name.rfind("worker", 0) == 0;
            if (workersExited < size_t(o.workers) || finished) continue;
            std::fprintf(stderr, "vrl render: error: every local worker exited (see their messages above)\n");
            try {
                JobClient client(remote.address, {}, remote.token);
                for (const auto& job : client.list()) client.cancel(job.job_id());
            } catch (const std::exception&) {
            }
            return;
        }
    });
    int code = 1;
    try {
        code = runRemoteRender(o, remote, signals, &job);
    } catch (...) {
        finished = true;
        watchdog.join();
        throw;
    }
    finished = true;
    watchdog.join();
    return code;
}

int runRender(const RenderCommandOptions& o, const CLI::App& command) {
    if (o.quiet) spdlog::set_level(spdlog::level::warn);
    using Clock = std::chrono::steady_clock;
    // Every refusal before any work: the outputs, the scene and the flags, checked
    // with the builder the coordinator uses (service/job/job_scene.h), so that bad
    // input exits 2 before a process starts or a light is traced.
    auto t0 = Clock::now();
    const CommandLineJob job = resolveCommandLineJob(o);
    const SceneDescription& description = job.resolved.description;
    const RenderSettings& settings = job.resolved.settings;
    const double parseSeconds = secondsSince(t0);
    warnIneffectiveFlags(command, settings.method, o.workers > 0);
    checkLightMemory(settings, util::physicalMemoryBytes());
    if (o.workers > 0) return runLocalCluster(o, job);

    t0 = Clock::now();
    const auto scene = Scene::build(description);
    const double buildSeconds = secondsSince(t0);

    const int threads = o.threads > 0 ? o.threads : tbb::info::default_concurrency();
    tbb::task_arena arena(threads);
    // SIGINT/SIGTERM stop the render between tiles; what is finished is written
    // below as a partial image. A second signal quits at once.
    const util::TerminationSignals signals;
    const RenderStop stop{[&] { return signals.received() != 0; }};
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
    RenderCoverage coverage;
    try {
        arena.execute([&] {
            images = render(*scene, settings, o.quiet ? ProgressCallback{} : progress, &stats, stop, &coverage);
        });
    } catch (const RenderInterrupted&) {
        if (bar) bar->finish();
        std::fprintf(stderr, "vrl render: %s during light preparation: no tile was rendered, no image written\n",
                     signalName(signals.received()));
        return util::TerminationSignals::exitCode(signals.received());
    }
    if (bar) bar->finish();
    const bool progressive = settings.timeLimitSeconds > 0.0;
    const int signal = signals.received();
    if (!coverage.complete()) {
        if (coverage.rowsDone == 0) {
            // Only a signal stops a render before its first row: a time limit lets the first pass start.
            std::fprintf(stderr, "vrl render: %s before any pixel row was finished: no image written\n",
                         signal ? signalName(signal) : "the time limit ran out");
            return signal ? util::TerminationSignals::exitCode(signal) : 1;
        }
        markPartial(images, coverage.covered, coverage.tilesDone, coverage.tilesTotal);
    }

    t0 = Clock::now();
    RenderRecord record;
    record.scene = o.scene;
    record.defines.insert(job.spec.defines().begin(), job.spec.defines().end());
    record.medium = o.medium;
    record.sceneNotes = sceneNotes(description);
    record.settings = settings;
    record.statistics = stats;
    record.phases = {{"parse", parseSeconds}, {"build", buildSeconds}};
    record.run = {{"threads", int32_t(threads)}, {"workers", int32_t(0)}};
    writeRenderMetadata(record, scene->camera(), images.metadata);
    writeExr(o.output, images);
    if (!o.preview.empty()) writePreviewPng(images.image, o.preview, autoExposure(images.image));
    const double writeSeconds = secondsSince(t0);
    if (!coverage.complete()) {
        std::fprintf(stderr,
                     "vrl render: %s: stopped; wrote what was finished to %s: %d of %d tiles whole, %.1f%% of the "
                     "pixels (a partial image: unfinished pixels are 0, see its 'coverage' layer and vrl.partial)\n",
                     signal ? signalName(signal) : "the time limit ran out in the first pass", o.output.c_str(),
                     coverage.tilesDone, coverage.tilesTotal, 100.0 * coveredFraction(coverage));
        return signal ? util::TerminationSignals::exitCode(signal) : 0;
    }
    if (signal && progressive) {  // stopped between passes: its completed passes are a whole image
        std::fprintf(stderr, "vrl render: %s: stopped; wrote the %d completed passes (%d spp) to %s\n",
                     signalName(signal), stats.passes, stats.samplesPerPixel, o.output.c_str());
        return util::TerminationSignals::exitCode(signal);
    }
    if (o.quiet) return 0;

    std::fprintf(stderr,
                 "summary: %s, %dx%d, method %s, %d spp, seed %llu, %d threads\n"
                 "  parse  %8.3f s\n  build  %8.3f s (%zu shapes, %zu media, %zu emitters)\n"
                 "  render %8.3f s (%llu camera samples, %.3g samples/s)\n  write  %8.3f s -> %s\n"
                 "  peak memory %.1f MiB\n",
                 o.scene.c_str(), scene->camera().width(), scene->camera().height(), std::string(methodName(settings.method)).c_str(), stats.samplesPerPixel,
                 (unsigned long long)settings.seed, threads, parseSeconds, buildSeconds, scene->shapes().size(),
                 scene->media().size(), scene->emitters().size(), stats.seconds,
                 (unsigned long long)stats.cameraSamples,
                 stats.seconds > 0 ? double(stats.cameraSamples) / stats.seconds : 0.0, writeSeconds,
                 o.output.c_str(), peakMemoryMiB());
    if (progressive)
        std::fprintf(stderr, "  progressive: %d passes completed in the %.3g s time limit -> %d spp (cap %d)\n",
                     stats.passes, settings.timeLimitSeconds, stats.samplesPerPixel, settings.samplesPerPixel);
    if (usesVirtualLights(settings.method)) {
        std::fprintf(stderr, "  light tracing %.3f s: %llu light paths -> %llu %s, %.1f MiB (%zu bytes each)\n",
                     stats.tracingSeconds, (unsigned long long)stats.lightPaths, (unsigned long long)stats.vrlCount,
                     usesVpls(settings.method) ? "VPLs" : "VRLs",
                     double(stats.vrlBytes) / (1024.0 * 1024.0), sizeof(Vrl));
        if (usesVpls(settings.method))
            std::fprintf(stderr, "  %d distance samples per camera segment\n", settings.vplDistanceSamples);
        if (settings.vrlSets > 1)
            std::fprintf(stderr, "  %d independent VRL sets (counts above are over all of them); sample s uses set s mod %d\n",
                         settings.vrlSets, settings.vrlSets);
        std::fprintf(stderr, "  transport parts: %s\n", settings.transports.toString().c_str());
        if (settings.shadingPointsPerSide > 1 && settings.method != RenderMethod::VrlStochastic)
            std::fprintf(stderr, "  (c), (d) and (b)'s surface VPLs at %dx%d shading points per pixel\n",
                         settings.shadingPointsPerSide, settings.shadingPointsPerSide);
        const char* vplParts = surfaceVplsLightSingle(settings) && surfaceVplsLightSurfaces(settings) ? "(a), (b)"
                               : surfaceVplsLightSurfaces(settings)                                 ? "(a)"
                                                                                                    : "(b)";
        if (usesSurfaceVpls(settings) && stats.surfaceVplPaths < stats.lightPaths)
            std::fprintf(stderr, "  %s surface light from %llu surface VPLs of the first %llu of the same light paths "
                         "(limit %llu)\n", vplParts, (unsigned long long)stats.surfaceVplCount,
                         (unsigned long long)stats.surfaceVplPaths, (unsigned long long)surfaceVplLimit(settings));
        else if (usesSurfaceVpls(settings))
            std::fprintf(stderr, "  %s surface light from %llu surface VPLs of the same light paths\n", vplParts,
                         (unsigned long long)stats.surfaceVplCount);
        if (surfaceVplsLightSurfaces(settings))
            std::fprintf(stderr, "  (a) samples %u surface VPLs per camera sample, the inverse square clamped at %.4g "
                         "scene units (path tracing adds the rest)\n", kSurfaceVplSamples,
                         double(stats.surfaceVplRadius));
        else if (settings.surfaceVplLimit == 0 && settings.transports.has(TransportPart::Single))
            std::fprintf(stderr, "  (b) surface light path-sampled (--surface-vpls 0)\n");
    }
    if (usesLightTree(settings.method)) {
        std::fprintf(stderr, "  light tree %.3f s, %.1f MiB\n", stats.treeSeconds,
                     double(stats.treeBytes) / (1024.0 * 1024.0));
        const bool stochastic = settings.method == RenderMethod::VrlStochastic;
        if (stochastic) {
            if (settings.transports.has(TransportPart::Multiple))
                std::fprintf(stderr, "  per pixel and sample, (d) medium-to-medium: #Eval %.1f, importances %.1f, cut size %.1f\n",
                             stats.meanEvaluated, stats.meanImportance, stats.meanCutSize);
            if (settings.transports.has(TransportPart::MediumSurface))
                std::fprintf(stderr, "  per pixel and sample, (c) medium-to-surface: #Eval %.1f, importances %.1f, cut size %.1f\n",
                             stats.surfaceMeanEvaluated, stats.surfaceMeanImportance, stats.surfaceMeanCutSize);
            return 0;
        }
        if (settings.transports.has(TransportPart::Multiple))
            std::fprintf(stderr, "  per pixel, (d) medium-to-medium: #Eval %.1f, #Inter %.1f, cut size %.1f\n",
                         stats.meanEvaluated, stats.meanIntersected, stats.meanCutSize);
        if (settings.transports.has(TransportPart::MediumSurface) && !usesVpls(settings.method))
            std::fprintf(stderr, "  per pixel, (c) medium-to-surface: #Eval %.1f, #Inter %.1f, cut size %.1f\n",
                         stats.surfaceMeanEvaluated, stats.surfaceMeanIntersected, stats.surfaceMeanCutSize);
        if (surfaceVplsLightSingle(settings))
            std::fprintf(stderr, "  per pixel, (b) surface VPLs: #Eval %.1f, #Inter %.1f, cut size %.1f\n",
                         stats.surfaceVplMeanEvaluated, stats.surfaceVplMeanIntersected, stats.surfaceVplMeanCutSize);
        std::fprintf(stderr, "  bound exceeded by %llu of %llu cluster estimates (%.4f%%)\n",
                     (unsigned long long)stats.boundExceeded, (unsigned long long)stats.boundedEstimates,
                     stats.boundedEstimates ? 100.0 * double(stats.boundExceeded) / double(stats.boundedEstimates) : 0.0);
        if (settings.method == RenderMethod::VrlLightcuts) {
            if (settings.cut.bound.hgBound == HgBound::Cones)
                std::fprintf(stderr, "  Henyey-Greenstein media: the proven bound (cones of directions)\n");
            else
                std::fprintf(stderr, "  Henyey-Greenstein media: the heuristic bound, isotropic x (1 + %g)\n",
                             double(settings.cut.bound.anisotropyEpsilon));
            if (settings.transports.has(TransportPart::MediumSurface))
                std::fprintf(stderr, "  (c) at glossy surfaces: %s\n",
                             settings.cut.bound.glossyBound == GlossyBound::Cones
                                 ? "the proven bound (cones of directions) for rough plastic and conductor (Beckmann, GGX)"
                                 : "the heuristic bound (corners x 2)");
        }
    }
    return 0;
}

}  // namespace

void registerRenderCommand(CLI::App& app, int& exitCode) {
    auto o = std::make_shared<RenderCommandOptions>();
    auto* cmd = app.add_subcommand("render", "Render a Mitsuba 0.5/0.6 XML scene to an OpenEXR image");
    addRenderOptions(*cmd, *o);
    cmd->add_option("--workers", o->workers,
                    "Render with a local coordinator and this many worker processes on loopback (default 0: "
                    "everything in this process); the image is bit-identical")
        ->check(CLI::Range(0, 256));
    cmd->add_option("--tile-size", o->tileSize, "With --workers: tile side in pixels (default 32)")
        ->check(CLI::Range(1u, 256u));
    cmd->callback([o, cmd, &exitCode] {
        try {
            exitCode = runRender(*o, *cmd);
        } catch (const SceneError& e) {
            std::fprintf(stderr, "vrl render: scene error: %s\n", e.what());
            exitCode = 2;
        } catch (const rpc::JobSpecError& e) {
            std::fprintf(stderr, "vrl render: error: %s\n", e.what());
            exitCode = 2;
        } catch (const rpc::BundleError& e) {
            std::fprintf(stderr, "vrl render: error: %s\n", e.what());
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

}  // namespace vrl::client
