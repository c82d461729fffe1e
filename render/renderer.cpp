#include "render/renderer.h"

#include "render/path_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>

namespace vrl {

ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                RenderStatistics* statistics) {
    if (std::find(kRenderMethods.begin(), kRenderMethods.end(), settings.method) == kRenderMethods.end()) {
        std::string valid;
        for (const auto& m : kRenderMethods) valid += (valid.empty() ? "" : ", ") + m;
        throw std::invalid_argument("unknown method '" + settings.method + "' (valid: " + valid + ")");
    }
    if (settings.samplesPerPixel < 1) throw std::invalid_argument("samples per pixel must be at least 1");
    const auto start = std::chrono::steady_clock::now();
    const PerspectiveCamera& camera = scene.camera();
    const int width = camera.width(), height = camera.height(), tile = std::max(1, settings.tileSize);
    const int tilesX = (width + tile - 1) / tile, tilesY = (height + tile - 1) / tile;

    ImageSet result;
    result.image = Image(width, height);
    const VolumetricPathTracer tracer(scene, PathTracerSettings{settings.maxDepth});
    std::atomic<long long> pixelsDone{0};
    const double totalPixels = double(width) * height;

    tbb::parallel_for(tbb::blocked_range<int>(0, tilesX * tilesY, 1), [&](const tbb::blocked_range<int>& range) {
        for (int t = range.begin(); t < range.end(); ++t) {
            const int x0 = (t % tilesX) * tile, y0 = (t / tilesX) * tile;
            const int x1 = std::min(width, x0 + tile), y1 = std::min(height, y0 + tile);
            for (int y = y0; y < y1; ++y) {
                for (int x = x0; x < x1; ++x) {
                    const uint64_t pixelIndex = uint64_t(y) * uint64_t(width) + uint64_t(x);
                    Rng rng(settings.seed, pixelIndex);
                    Rgb sum(0.0f);
                    for (int s = 0; s < settings.samplesPerPixel; ++s) {
                        const float jx = settings.jitter ? rng.next() : 0.5f;
                        const float jy = settings.jitter ? rng.next() : 0.5f;
                        const Ray ray = camera.generateRay(float(x) + jx, float(y) + jy);
                        sum += tracer.radiance(ray, scene.cameraMedium(), rng);
                    }
                    result.image.at(x, y) = sum / float(settings.samplesPerPixel);
                }
            }
            const long long done = pixelsDone.fetch_add(static_cast<long long>((x1 - x0) * (y1 - y0))) + (x1 - x0) * (y1 - y0);
            if (progress) progress(double(done) / totalPixels);
        }
    });

    if (statistics) {
        statistics->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        statistics->cameraSamples = uint64_t(width) * height * settings.samplesPerPixel;
    }
    return result;
}

}  // namespace vrl
