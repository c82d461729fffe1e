// Renderer: the render library's front door. It turns a Scene into an image with
// a chosen method (render_method.h: the one table of what each method runs), in
// parallel tiles (TBB). The phases are public so that the service can split
// them: the coordinator runs prepareLights once (render_lights.h), workers run
// TileShader on leased tiles and passes (tile_shader.h).
//
// Camera sample s of pixel (x, y) draws from its own random stream, keyed by
// (seed, film pixel index, s), and the virtual-light parts evaluated once per
// pixel from (seed, film pixel index, ~0); the samples are taken and summed in
// passes (sample_passes.h). So the image is bit-identical whatever the thread
// count, tile size or order, or process that shades a tile, a crop window
// (camera.h) equals that window of the full film, and a progressive render
// (RenderSettings::timeLimitSeconds) that completed P passes equals the fixed
// render of 2^P - 1 samples.
#pragma once

#include "render/image/image.h"
#include "render/lightcuts/cuts/surface_vpl_lightcuts_estimator.h"  // part (a)'s kSurfaceVplSamples, surfaceVplRadius
#include "render/render_lights.h"
#include "render/render_method.h"
#include "render/render_settings.h"
#include "render/sample_passes.h"
#include "render/sample_sums.h"
#include "render/scene/scene.h"
#include "render/tile_shader.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl {

// The image cut into tileSize x tileSize tiles, row by row from the top left.
std::vector<TileRect> imageTiles(int width, int height, int tileSize);
// The embedded render's tile side for `threads` threads: tileSize, halved (to no less
// than kMinBalancedTileSize) while the image holds fewer than kTilesPerThread tiles per
// thread. Tiles differ in cost (a floor whose cuts reach the cap against a dark wall),
// and with a few tiles per thread the last heavy ones leave the other threads idle:
// small tiles keep every thread busy to the end on small films. The image does not
// depend on it (renderer_test).
inline constexpr int kTilesPerThread = 16;
inline constexpr int kMinBalancedTileSize = 4;
int balancedTileSize(int width, int height, int tileSize, int threads);

// Whole-image layers (one per TileShader layer, image first) into an ImageSet,
// filling the cut statistics of `statistics` from the cuts' counter layers
// (render_method.h), which it marks single-channel.
ImageSet assembleImageSet(std::vector<Image> layers, const std::vector<std::string>& layerNames,
                          RenderStatistics* statistics = nullptr);

struct RenderInterrupted : std::runtime_error {
    RenderInterrupted() : std::runtime_error("interrupted before any tile was shaded") {}
};
// What a render finished: `covered` has one entry per pixel (row-major, 1 where
// the pixel was shaded: finished tiles and the finished rows of tiles stopped
// midway), for partial_image.h's markPartial; tilesDone counts whole tiles.
struct RenderCoverage {
    std::vector<uint8_t> covered;
    int tilesDone = 0, tilesTotal = 0;
    int rowsDone = 0;  // pixel rows shaded, over all tiles (0: nothing to keep)
    bool complete() const { return tilesDone == tilesTotal; }
};

// prepareLights, then every tile in parallel (TBB), then assembleImageSet.
// A virtual-light method returns the sum in .image and each selected part as a layer.
// With `stop`, tiles not started when it fires are skipped (zero) and
// `coverage`, if given, says which were finished. With a time limit, the
// passes run one after the other over the whole image (each in parallel
// tiles) until the limit, `stop` or the sample cap; statistics->passes and
// ->samplesPerPixel say what the image holds (a first pass cut short leaves a
// partial image of 1 sample per pixel and passes 0, as an interrupt does).
ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress = {},
                RenderStatistics* statistics = nullptr, const RenderStop& stop = {},
                RenderCoverage* coverage = nullptr);

}  // namespace vrl
