#include "render/renderer.h"

#include "render/light_tracer.h"
#include "render/light_tree.h"
#include "render/path_tracer.h"
#include "render/vrl_integrator.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>

namespace vrl {

namespace {

// Runs `shadePixel(x, y, rng)` over all pixels in parallel tiles, each pixel with
// its own stream (seed, pixel index).
template <class ShadePixel>
void forEachPixel(int width, int height, const RenderSettings& settings, const ProgressCallback& progress,
                  ShadePixel&& shadePixel) {
    const int tile = std::max(1, settings.tileSize);
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;
    std::atomic<long long> pixelsDone{0};
    const double totalPixels = double(width) * height;
    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& range) {
        for (int t = range.begin(); t < range.end(); ++t) {
            const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
            const int x1 = std::min(width, x0 + tile), y1 = std::min(height, y0 + tile);
            for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x) {
                    Rng rng(settings.seed, uint64_t(y) * uint64_t(width) + uint64_t(x));
                    shadePixel(x, y, rng);
                }
            }
            const long long count = static_cast<long long>(x1 - x0) * (y1 - y0);
            const long long done = pixelsDone.fetch_add(count) + count;
            if (progress) progress("rendering", double(done) / totalPixels);
        }
    });
}

Ray cameraRay(const PerspectiveCamera& camera, const RenderSettings& settings, int x, int y, Rng& rng) {
    const float jx = settings.jitter ? rng.next() : 0.5f;
    const float jy = settings.jitter ? rng.next() : 0.5f;
    return camera.generateRay(float(x) + jx, float(y) + jy);
}

ImageSet renderPath(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress) {
    const PerspectiveCamera& camera = scene.camera();
    ImageSet result;
    result.image = Image(camera.width(), camera.height());
    const VolumetricPathTracer tracer(scene, PathTracerSettings{settings.maxDepth});
    forEachPixel(camera.width(), camera.height(), settings, progress, [&](int x, int y, Rng& rng) {
        Rgb sum(0.0f);
        for (int s = 0; s < settings.samplesPerPixel; ++s)
            sum += tracer.radiance(cameraRay(camera, settings, x, y, rng), scene.cameraMedium(), rng);
        result.image.at(x, y) = sum / float(settings.samplesPerPixel);
    });
    return result;
}

ImageSet renderVrl(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                   RenderStatistics& statistics, bool lightcuts) {
    VrlSet vrls;
    if (settings.transports.has(TransportPart::Multiple)) {
        LightTracingSettings tracing;
        tracing.lightPaths = settings.lightPaths;
        tracing.targetVrls = settings.vrlCount;
        tracing.maxDepth = settings.maxDepth;
        tracing.seed = settings.seed ^ 0x5bd1e995ULL;  // a stream family apart from the camera's
        vrls = traceVrls(scene, tracing, [&](double f) {
            if (progress) progress("light tracing", f);
        });
        statistics.vrlCount = vrls.vrls.size();
        statistics.lightPaths = vrls.lightPaths;
        statistics.vrlBytes = vrls.memoryBytes();
        statistics.tracingSeconds = vrls.tracingSeconds;
    }
    LightTree tree;
    if (lightcuts && !vrls.vrls.empty()) {
        if (progress) progress("building the light tree", 0.0);
        const auto treeStart = std::chrono::steady_clock::now();
        // The tree takes the VRLs over: shading reads them from it.
        tree = LightTree::build(std::move(vrls.vrls), LightTreeSettings{settings.partitionSize, settings.seed});
        vrls.vrls = {};
        statistics.treeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - treeStart).count();
        statistics.treeBytes = tree.memoryBytes();
        if (progress) progress("building the light tree", 1.0);
    }
    const auto start = std::chrono::steady_clock::now();
    const PerspectiveCamera& camera = scene.camera();
    const int width = camera.width(), height = camera.height();
    const VrlIntegratorSettings integratorSettings{settings.transports, settings.maxDepth, settings.vrlSamples,
                                                   settings.cut};
    const VrlIntegrator integrator(scene, vrls, integratorSettings, lightcuts ? &tree : nullptr);
    std::array<Image, 4> parts;
    for (auto& part : parts) part = Image(width, height);
    std::array<Image, 3> cutLayers;  // eval, inter, cut
    std::atomic<uint64_t> boundExceeded{0}, boundedEstimates{0};
    if (lightcuts)
        for (auto& layer : cutLayers) layer = Image(width, height);
    forEachPixel(width, height, settings, progress, [&](int x, int y, Rng& rng) {
        std::array<Rgb, 4> sum{Rgb(0.0f), Rgb(0.0f), Rgb(0.0f), Rgb(0.0f)};
        for (int s = 0; s < settings.samplesPerPixel; ++s) {
            const auto sample = integrator.samplePathParts(cameraRay(camera, settings, x, y, rng), rng);
            for (size_t p = 0; p < 3; ++p) sum[p] += sample[p];
        }
        for (size_t p = 0; p < 3; ++p) parts[p].at(x, y) = sum[p] / float(settings.samplesPerPixel);
        // (d) once per pixel: its cost is per VRL, not per camera sample.
        CutStatistics cut;
        parts[3].at(x, y) = integrator.multipleScattering(cameraRay(camera, settings, x, y, rng), rng, &cut);
        if (lightcuts) {
            cutLayers[0].at(x, y) = Rgb(float(cut.evaluated));
            cutLayers[1].at(x, y) = Rgb(float(cut.intersected));
            cutLayers[2].at(x, y) = Rgb(float(cut.cutSize));
            boundExceeded += cut.boundExceeded;
            boundedEstimates += cut.boundedEstimates;
        }
    });
    ImageSet result;
    result.image = Image(width, height);
    for (size_t p = 0; p < parts.size(); ++p) {
        if (!settings.transports.enabled[p]) continue;
        for (size_t i = 0; i < result.image.pixelCount(); ++i) result.image[i] += parts[p][i];
        result.layers.emplace_back(std::string(kTransportPartNames[p]), std::move(parts[p]));
    }
    if (lightcuts) {
        double sums[3] = {0, 0, 0};
        for (size_t l = 0; l < 3; ++l)
            for (const auto& p : cutLayers[l].pixels()) sums[l] += p.x;
        const double n = double(width) * height;
        statistics.meanEvaluated = sums[0] / n;
        statistics.meanIntersected = sums[1] / n;
        statistics.meanCutSize = sums[2] / n;
        statistics.boundExceeded = boundExceeded.load();
        statistics.boundedEstimates = boundedEstimates.load();
        const char* names[] = {"eval", "inter", "cut"};
        for (size_t l = 0; l < 3; ++l) result.layers.emplace_back(names[l], std::move(cutLayers[l]));
    }
    statistics.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace

ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                RenderStatistics* statistics) {
    if (std::find(kRenderMethods.begin(), kRenderMethods.end(), settings.method) == kRenderMethods.end()) {
        std::string valid;
        for (const auto& m : kRenderMethods) valid += (valid.empty() ? "" : ", ") + m;
        throw std::invalid_argument("unknown method '" + settings.method + "' (valid: " + valid + ")");
    }
    if (settings.samplesPerPixel < 1) throw std::invalid_argument("samples per pixel must be at least 1");
    if (settings.vrlSamples < 1) throw std::invalid_argument("samples per VRL must be at least 1");
    RenderStatistics stats;
    ImageSet result;
    if (settings.method == "vrl" || settings.method == "vrl-lightcuts") {
        if (!(settings.cut.errorThreshold >= 0.0f)) throw std::invalid_argument("the error threshold must be >= 0");
        result = renderVrl(scene, settings, progress, stats, settings.method == "vrl-lightcuts");
    } else {
        const auto start = std::chrono::steady_clock::now();
        result = renderPath(scene, settings, progress);
        stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    stats.cameraSamples = uint64_t(scene.camera().width()) * scene.camera().height() * settings.samplesPerPixel;
    if (statistics) *statistics = stats;
    return result;
}

}  // namespace vrl
