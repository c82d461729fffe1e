// TileShader: shades tiles of the image (the worker's part in the service, every
// tile of an embedded render), in image pixels (the crop window's, if any).
// Camera sample s of pixel (x, y) draws from its own random stream, keyed by
// (seed, film pixel index, s); the virtual-light parts evaluated once per pixel
// from (seed, film pixel index, kPixelLightsSample - m) for shading point m. So
// a tile's pixels equal those of a whole-image (and whole-film) render bit for
// bit, whatever the thread, tile or process that shades them.
#pragma once

#include "render/image/image.h"
#include "render/render_lights.h"
#include "render/render_settings.h"
#include "render/sample_sums.h"
#include "render/scene/scene.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace vrl {

class TransportIntegrator;
class VolumetricPathTracer;

// Pixels [x0, x1) x [y0, y1) of the image.
struct TileRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    bool operator==(const TileRect&) const = default;
};

// Stopping a render early (an interrupt): `requested` is polled from the
// light-tracing progress, before each tile and before each row of a tile. A
// tile stopped midway keeps its finished rows (the rest stay zero); when it
// fires during light preparation, render throws RenderInterrupted. A
// progressive render keeps its completed passes and drops the one stopped,
// unless it is the first (then its finished rows are kept, as above).
struct RenderStop {
    std::function<bool()> requested;
    bool operator()() const { return requested && requested(); }
};

// Layers of a tile or image, in order: the image itself, then the method's layers.
struct TileImages {
    std::vector<Image> layers;  // each tile-sized; layers[0] is the image
    uint64_t boundExceeded = 0, boundedEstimates = 0;
    bool interrupted = false;  // `stop` fired before the last row: only the first `rowsDone` rows are shaded
    int rowsDone = 0;
};

// Sample s of pixel (x, y) of a tile draws from the stream
// (seed, Rng::combine(camera.filmPixelIndex(x, y), s)) only.
// The once-per-pixel parts' stream: sample index kPixelLightsSample - m for shading point m.
inline constexpr uint64_t kPixelLightsSample = ~uint64_t(0);

// A tile's sample sums (sample_sums.h) and how far it got.
struct TileSums {
    SampleSums sums;
    bool interrupted = false;  // `stop` fired before the last row: only the first `rowsDone` rows are shaded
    int rowsDone = 0;
};

// renderTile and shadeTile are const and thread-safe; `lights` must outlive the TileShader.
class TileShader {
public:
    // Throws std::invalid_argument for invalid settings or lights that do not belong to the scene.
    TileShader(const Scene& scene, const RenderSettings& settings, const RenderLights& lights);
    ~TileShader();
    // Names of the layers after the image ("surface", ..., "eval", "inter", "cut": renderLayerNames).
    const std::vector<std::string>& layerNames() const { return layerNames_; }
    // Per layer (image first): 1 where it holds one value per pixel rather than a sum over samples.
    const std::vector<uint8_t>& layerPerPixel() const { return layerPerPixel_; }
    // The fixed render's tile: passes [0, passesFor(samplesPerPixel)) resolved.
    TileImages renderTile(const TileRect& tile, const RenderStop& stop = {}) const;
    // The sums of passes [firstPass, firstPass + passCount) folded in pass order
    // (sample_passes.h), the samples capped at samplesPerPixel; a range must
    // start at pass 0 or hold one pass (throws std::invalid_argument otherwise),
    // so that addPass of its result onto passes [0, firstPass) is the canonical fold.
    TileSums shadeTile(const TileRect& tile, int firstPass, int passCount, const RenderStop& stop = {}) const;

private:
    // Where shadeTile writes each value: the layer index (image = 0) of each selected
    // transport part, of "single-vpl", and of the first of each cut's three counters; -1: none.
    struct Layout {
        int part[4] = {-1, -1, -1, -1};
        int singleVpl = -1;
        int counters = -1, surfaceCounters = -1, surfaceVplCounters = -1;
    };
    // The virtual-light parts (c), (d), (b)'s surface VPLs of one pixel, once per pixel (pass 0).
    void shadePixelLights(int x, int y, uint64_t pixel, float firstSampleLuminance, std::vector<Rgb>& total,
                          SampleSums& sums) const;

    const Scene& scene_;
    RenderSettings settings_;
    std::vector<std::string> layerNames_;
    std::vector<uint8_t> layerPerPixel_;
    Layout layout_;
    bool lightsPerSample_ = false;
    std::unique_ptr<TransportIntegrator> integrator_;  // set 0's (and the path-sampled parts)
    std::vector<std::unique_ptr<TransportIntegrator>> moreIntegrators_;  // sets 1 ... vrlSets - 1
    std::unique_ptr<VolumetricPathTracer> tracer_;
};

}  // namespace vrl
