#include "render/integrators/light_tracing_reference.h"

#include "render/core/rng.h"
#include "render/integrators/path_tracer.h"
#include "render/vrl/light_tracer.h"

#include <spdlog/spdlog.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <string>
#include <stdexcept>
#include <vector>

namespace vrl {

namespace {

constexpr uint64_t kPathsPerChunk = 512;
constexpr uint64_t kChunksPerBatch = 64;

// One connection's value, for pixel `pixel` (row-major in the image).
struct Splat {
    uint32_t pixel;
    Rgb value;
};

// Part 1: every light path's scattering vertices connected to the camera, summed
// into `sum` (not yet divided by the path count). Returns how many connections had
// a non-finite value and were left out (none in a sound scene: see the caller).
uint64_t traceToCamera(const Scene& scene, const LightTracingReferenceSettings& settings,
                       std::vector<std::array<double, 3>>& sum) {
    const PerspectiveCamera& camera = scene.camera();
    LightTracingSettings tracing;
    tracing.seed = settings.seed;
    tracing.maxDepth = settings.maxDepth;
    const LightPathWalker walker(scene, tracing);
    const float footprint = settings.pixelFootprint, perArea = 1.0f / (footprint * footprint);
    std::atomic<uint64_t> nonFinite{0};
    const auto connect = [&](const LightPathVertex& v, std::vector<Splat>& out) {
        const auto seen = camera.project(v.position);
        if (!seen || !(seen->distance > 0.0f)) return;
        if (std::abs(seen->offsetX) * 2.0f > footprint || std::abs(seen->offsetY) * 2.0f > footprint) return;
        const Vec3 toCamera = (camera.position() - v.position) / seen->distance;
        Rgb f(0.0f);
        Vec3 from = v.position;
        int medium = v.medium;
        if (v.surface) {
            const Bsdf& bsdf = scene.shapes()[v.surface->shape].bsdf;
            f = bsdf.eval(v.surface->shadingPoint(), -v.direction, toCamera, TransportMode::Importance);
            if (isBlack(f)) return;
            from = Scene::offsetOrigin(*v.surface, toCamera);
            medium = scene.mediumAfter(*v.surface, toCamera, medium);
        } else {
            f = Rgb(scene.media()[size_t(v.medium)].phase().eval(v.direction, toCamera));
        }
        const Rgb tr = scene.transmittance(from, seen->rayOrigin, medium);
        if (isBlack(tr)) return;
        const Rgb value = v.weight * f * tr * (seen->importance * perArea / (seen->distance * seen->distance));
        if (!isFinite(value)) {  // project() keeps the vertex beyond the near clip plane: a NaN or inf from upstream
            nonFinite.fetch_add(1, std::memory_order_relaxed);
            return;
        }
        out.push_back({uint32_t(seen->y) * uint32_t(camera.width()) + uint32_t(seen->x), value});
    };
    std::vector<std::vector<Splat>> chunks(kChunksPerBatch);
    for (uint64_t first = 0; first < settings.lightPaths; first += kPathsPerChunk * kChunksPerBatch) {
        tbb::parallel_for(uint64_t(0), kChunksPerBatch, [&](uint64_t c) {
            std::vector<Splat>& out = chunks[c];
            out.clear();
            const uint64_t begin = std::min(settings.lightPaths, first + c * kPathsPerChunk);
            const uint64_t end = std::min(settings.lightPaths, begin + kPathsPerChunk);
            const std::function<void(const LightPathVertex&)> visit = [&](const LightPathVertex& v) { connect(v, out); };
            for (uint64_t i = begin; i < end; ++i) walker.walk(i, visit);
        });
        for (const std::vector<Splat>& chunk : chunks)  // in chunk order: the same sums on any thread count
            for (const Splat& s : chunk)
                for (int k = 0; k < 3; ++k) sum[s.pixel][size_t(k)] += double(s.value[k]);
    }
    return nonFinite.load();
}

}  // namespace

Image renderLightTracingReference(const Scene& scene, const LightTracingReferenceSettings& settings) {
    const auto invalid = [](const std::string& what) {
        return std::invalid_argument("light-tracing reference: " + what);
    };
    if (settings.samplesPerPixel < 0)
        throw invalid("samples per pixel must not be negative, not " + std::to_string(settings.samplesPerPixel));
    if (settings.maxDepth < -1)
        throw invalid("the maximum depth must be -1 (unlimited) or at least 0, not " + std::to_string(settings.maxDepth));
    if (!(settings.pixelFootprint > 0.0f && settings.pixelFootprint <= 1.0f))
        throw invalid("the pixel footprint must be in (0, 1], not " + std::to_string(settings.pixelFootprint));
    if (settings.pixelFootprint < 1.0f && !settings.pixelCentres && settings.samplesPerPixel > 0)
        throw invalid("a pixel footprint below 1 measures near pixel centres, so part 2 must trace through them "
                      "too (pixelCentres); jittered, it would average over whole pixels");
    if (settings.lightPaths == 0 && settings.samplesPerPixel == 0)
        throw invalid("it needs light paths, camera samples or both; both are 0");
    const PerspectiveCamera& camera = scene.camera();
    const int width = camera.width(), height = camera.height();
    std::vector<std::array<double, 3>> lightSum(size_t(width) * size_t(height), {0.0, 0.0, 0.0});
    if (settings.lightPaths > 0)
        if (const uint64_t dropped = traceToCamera(scene, settings, lightSum); dropped > 0)
            spdlog::warn("light-tracing reference: {} of the camera connections of {} light paths had a NaN or "
                         "infinite value and were left out; the image lacks their light (a degenerate emitter, "
                         "BSDF or medium in the scene?)",
                         dropped, settings.lightPaths);

    Image image(width, height);
    const double perPath = settings.lightPaths > 0 ? 1.0 / double(settings.lightPaths) : 0.0;
    const VolumetricPathTracer tracer(scene, PathTracerSettings{settings.maxDepth});
    PathStart start;
    start.firstSegmentTransmittanceOnly = true;
    start.emissionOnFirstHit = true;
    start.diracAtFirstSurfaceOnly = true;
    const uint64_t cameraSeed = Rng::combine(settings.seed, 0x706174682d32ULL);  // part 2's streams, apart from part 1's
    tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y)
            for (int x = 0; x < width; ++x) {
                const size_t i = size_t(y) * size_t(width) + size_t(x);
                std::array<double, 3> pixel = {lightSum[i][0] * perPath, lightSum[i][1] * perPath, lightSum[i][2] * perPath};
                if (settings.samplesPerPixel > 0) {
                    const uint64_t filmPixel = camera.filmPixelIndex(x, y);
                    std::array<double, 3> traced = {0.0, 0.0, 0.0};
                    for (int s = 0; s < settings.samplesPerPixel; ++s) {
                        Rng rng(cameraSeed, Rng::combine(filmPixel, uint64_t(s)));
                        const float jx = settings.pixelCentres ? 0.5f : rng.next();
                        const float jy = settings.pixelCentres ? 0.5f : rng.next();
                        const Ray ray = camera.generateRay(float(x + camera.cropX0()) + jx, float(y + camera.cropY0()) + jy);
                        const Rgb L = tracer.radiance(ray, scene.cameraMedium(), rng, start);
                        for (int k = 0; k < 3; ++k) traced[size_t(k)] += double(L[k]);
                    }
                    for (int k = 0; k < 3; ++k) pixel[size_t(k)] += traced[size_t(k)] / double(settings.samplesPerPixel);
                }
                image[i] = Rgb(float(pixel[0]), float(pixel[1]), float(pixel[2]));
            }
    });
    return image;
}

}  // namespace vrl
