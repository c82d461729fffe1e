// SampleSums: a tile's (or whole image's) camera samples summed per pixel,
// before they are divided by the sample count: what a pass of a progressive
// render produces, what the coordinator accumulates per tile, and what a
// fixed render resolves into its layers. sample_passes.h defines the order of
// the sums; this file the two operations on them:
//   - addPass folds the sums of pass p (p >= 1) into the sums of passes [0, p);
//   - resolveSamples divides them by the sample count into the layers of an
//     image (render/renderer.h's TileImages order: the image, then the named layers).
// Layers marked per-pixel (perPixel[l] != 0: parts (c), (d) and their cut
// counters when the virtual lights are evaluated once per pixel) hold one
// value per pixel from pass 0: addPass leaves them, resolveSamples copies them.
// The image is layer 0's mean (the path tracer's radiance; zero for the
// virtual-light methods) plus every transport-part layer ("surface", ...,
// "multiple"), added in layer order.
#pragma once

#include "render/image/image.h"

#include <cstdint>
#include <string>
#include <vector>

namespace vrl {

struct SampleSums {
    std::vector<Image> layers;      // layers[0]: the image's own sum, then one per named layer
    std::vector<uint8_t> perPixel;  // per layer: 1 = evaluated once per pixel (in pass 0), not a sum
    uint64_t boundExceeded = 0, boundedEstimates = 0;  // cut estimates above their bound, over the samples

    // Zero sums of `layerCount` width x height layers with these per-pixel flags.
    static SampleSums zeros(int width, int height, const std::vector<uint8_t>& perPixel);
};

// into += pass on every per-sample layer, and the bound counters; throws
// std::invalid_argument when the two differ in layers, sizes or flags.
void addPass(SampleSums& into, const SampleSums& pass);

// Copies rows [y0, y0 + rows) of `tile` into `into` at (x0, y0 + ...) (both must have the same layers).
void copyRows(SampleSums& into, const SampleSums& tile, int x0, int y0, int rows);

// The layers of `sums` over `samples` samples per pixel (>= 1): layer 0 the
// image, then layerNames' layers; throws std::invalid_argument when the
// layer count is not 1 + layerNames.size().
std::vector<Image> resolveSamples(const SampleSums& sums, const std::vector<std::string>& layerNames, int samples);

}  // namespace vrl
