// Renderer: turns a Scene into an image with a chosen method, in parallel tiles
// (TBB). Every pixel's random stream is seeded from (seed, pixel index), so the
// image is bit-identical whatever the thread count or tile order.
#pragma once

#include "render/image.h"
#include "render/scene.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vrl {

// Methods the renderer knows; `vrl render --method` takes these names.
inline const std::vector<std::string> kRenderMethods = {"path"};

struct RenderSettings {
    std::string method = "path";
    int samplesPerPixel = 1;
    uint64_t seed = 0;
    bool jitter = false;  // false: rays through pixel centres (the paper's setting)
    int maxDepth = -1;    // Mitsuba meaning (see path_tracer.h)
    int tileSize = 16;
};

struct RenderStatistics {
    double seconds = 0.0;
    uint64_t cameraSamples = 0;
};

// Called from worker threads with the fraction of pixels done; must be thread-safe.
using ProgressCallback = std::function<void(double fraction)>;

// Throws std::invalid_argument for an unknown method or non-positive sample count.
ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
                RenderStatistics* statistics = nullptr);

}  // namespace vrl
