// Renderer: turns a Scene into an image with a chosen method, in parallel tiles
// (TBB). Every pixel's random stream is seeded from (seed, pixel index), so the
// image is bit-identical whatever the thread count or tile order.
#pragma once

#include "render/cut.h"
#include "render/image.h"
#include "render/scene.h"
#include "render/transport.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace vrl {

// Methods the renderer knows; `vrl render --method` takes these names.
//   path: the volumetric path tracer (reference), one image
//   vrl:  the four transport parts, multiple scattering by plain VRLs; one layer per part
//   vrl-lightcuts: the same, multiple scattering by cuts through a VRL light tree,
//         plus per-pixel layers "eval", "inter" and "cut" (statistics)
inline const std::vector<std::string> kRenderMethods = {"path", "vrl", "vrl-lightcuts"};

struct RenderSettings {
    std::string method = "path";
    int samplesPerPixel = 1;  // path: per pixel; vrl: for parts (a)-(c)
    uint64_t seed = 0;
    bool jitter = false;  // false: rays through pixel centres (the paper's setting)
    int maxDepth = -1;    // Mitsuba meaning (see path_tracer.h)
    int tileSize = 16;
    // vrl method
    TransportSelection transports;
    uint64_t vrlCount = 100000;  // target VRLs (whole light paths are kept)
    uint64_t lightPaths = 0;     // if > 0: trace exactly this many light paths instead
    int vrlSamples = 1;          // (u, v) samples per VRL and camera segment
    // vrl-lightcuts method
    CutSettings cut;             // error threshold, maximum cut, bound parameters
    uint32_t partitionSize = 2048;  // light tree: VRLs per partition of the median-split phase
};

struct RenderStatistics {
    double seconds = 0.0;  // shading (after light tracing)
    uint64_t cameraSamples = 0;
    // vrl method
    uint64_t vrlCount = 0;
    uint64_t lightPaths = 0;
    size_t vrlBytes = 0;
    double tracingSeconds = 0.0;
    // vrl-lightcuts method
    double treeSeconds = 0.0;
    size_t treeBytes = 0;
    double meanEvaluated = 0.0, meanIntersected = 0.0, meanCutSize = 0.0;  // per pixel
    uint64_t boundExceeded = 0, boundedEstimates = 0;  // inner-node estimates above their bound
};

// Called from worker threads with the fraction done of a phase ("light tracing",
// "rendering"); must be thread-safe.
using ProgressCallback = std::function<void(const char* phase, double fraction)>;

// Throws std::invalid_argument for an unknown method or non-positive sample count.
// The vrl method returns the sum in .image and each selected part as a layer.
ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
                RenderStatistics* statistics = nullptr);

}  // namespace vrl
