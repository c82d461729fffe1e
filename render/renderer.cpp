#include "render/renderer.h"

#include "render/core/timing.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <stdexcept>
#include <utility>

namespace vrl {

std::vector<TileRect> imageTiles(int width, int height, int tileSize) {
    const int tile = std::max(1, tileSize);
    std::vector<TileRect> tiles;
    for (int y0 = 0; y0 < height; y0 += tile)
        for (int x0 = 0; x0 < width; x0 += tile)
            tiles.push_back({x0, y0, std::min(width, x0 + tile), std::min(height, y0 + tile)});
    return tiles;
}

int balancedTileSize(int width, int height, int tileSize, int threads) {
    int tile = std::max(1, tileSize);
    const auto count = [&](int side) { return int64_t((width + side - 1) / side) * ((height + side - 1) / side); };
    const int64_t wanted = int64_t(kTilesPerThread) * std::max(1, threads);
    while (tile / 2 >= kMinBalancedTileSize && count(tile) < wanted) tile /= 2;
    return tile;
}

ImageSet assembleImageSet(std::vector<Image> layers, const std::vector<std::string>& layerNames,
                          RenderStatistics* statistics) {
    if (layers.size() != layerNames.size() + 1) throw std::invalid_argument("assembleImageSet: layer count mismatch");
    // The statistics each counter layer's mean goes to (per pixel; vrl-stochastic: per pixel and sample).
    const std::pair<std::string_view, double RenderStatistics::*> means[] = {
        {kCutLayerNames[0], &RenderStatistics::meanEvaluated},
        {kCutLayerNames[1], &RenderStatistics::meanIntersected},
        {kCutLayerNames[2], &RenderStatistics::meanCutSize},
        {kSurfaceCutLayerNames[0], &RenderStatistics::surfaceMeanEvaluated},
        {kSurfaceCutLayerNames[1], &RenderStatistics::surfaceMeanIntersected},
        {kSurfaceCutLayerNames[2], &RenderStatistics::surfaceMeanCutSize},
        {kStochasticLayerNames[1], &RenderStatistics::meanImportance},
        {kSurfaceStochasticLayerNames[1], &RenderStatistics::surfaceMeanImportance},
        {kSurfaceVplCutLayerNames[0], &RenderStatistics::surfaceVplMeanEvaluated},
        {kSurfaceVplCutLayerNames[1], &RenderStatistics::surfaceVplMeanIntersected},
        {kSurfaceVplCutLayerNames[2], &RenderStatistics::surfaceVplMeanCutSize},
    };
    ImageSet result;
    result.image = std::move(layers[0]);
    for (size_t l = 0; l < layerNames.size(); ++l) {
        const std::string& name = layerNames[l];
        if (statistics) {
            double sum = 0.0;
            for (const auto& p : layers[l + 1].pixels()) sum += p.x;
            const double mean = layers[l + 1].pixelCount() ? sum / double(layers[l + 1].pixelCount()) : 0.0;
            for (const auto& [layer, field] : means)
                if (name == layer) statistics->*field = mean;
        }
        result.layers.emplace_back(name, std::move(layers[l + 1]));
        for (const CounterLayerNames* counters : kAllCounterLayerNames)
            for (std::string_view counter : *counters)
                if (name == counter) result.singleChannelLayers.insert(name);
    }
    return result;
}

namespace {

// Passes [firstPass, firstPass + passCount) of every tile, in parallel (TBB),
// into whole-image sums; a tile stopped midway keeps its finished rows.
struct TilesShaded {
    SampleSums sums;
    std::vector<int> tileRows;  // rows shaded per tile
    int tilesDone = 0;
};
TilesShaded shadeTiles(const TileShader& shader, const std::vector<TileRect>& tiles, int width, int height,
                       int firstPass, int passCount, const RenderStop& stop, const ProgressCallback& progress,
                       const std::string& phase) {
    TilesShaded out;
    out.sums = SampleSums::zeros(width, height, shader.layerPerPixel());
    out.tileRows.assign(tiles.size(), 0);
    std::atomic<uint64_t> boundExceeded{0}, boundedEstimates{0};
    std::atomic<long long> pixelsDone{0};
    std::atomic<int> tilesDone{0};
    const double totalPixels = double(width) * height;
    if (progress) progress(phase.c_str(), 0.0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles.size(), 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t t = range.begin(); t < range.end(); ++t) {
            if (stop()) return;
            const TileRect& tile = tiles[t];
            const TileSums shaded = shader.shadeTile(tile, firstPass, passCount, stop);
            const int rows = shaded.interrupted ? shaded.rowsDone : tile.height();
            out.tileRows[t] = rows;
            copyRows(out.sums, shaded.sums, tile.x0, tile.y0, rows);
            if (shaded.interrupted) return;
            ++tilesDone;
            boundExceeded += shaded.sums.boundExceeded;
            boundedEstimates += shaded.sums.boundedEstimates;
            const long long count = static_cast<long long>(tile.width()) * tile.height();
            const long long done = pixelsDone.fetch_add(count) + count;
            if (progress) progress(phase.c_str(), double(done) / totalPixels);
        }
    });
    out.tilesDone = tilesDone.load();
    out.sums.boundExceeded = boundExceeded.load();
    out.sums.boundedEstimates = boundedEstimates.load();
    return out;
}

void fillCoverage(RenderCoverage& coverage, const std::vector<TileRect>& tiles, const std::vector<int>& tileRows,
                  int tilesDone, int width, int height) {
    coverage.tilesTotal = int(tiles.size());
    coverage.tilesDone = tilesDone;
    coverage.rowsDone = 0;
    coverage.covered.assign(size_t(width) * height, 0);
    for (size_t t = 0; t < tiles.size(); ++t) {
        coverage.rowsDone += tileRows[t];
        for (int y = tiles[t].y0; y < tiles[t].y0 + tileRows[t]; ++y)
            std::fill_n(&coverage.covered[size_t(y) * width + tiles[t].x0], tiles[t].width(), uint8_t(1));
    }
}

}  // namespace

ImageSet render(const Scene& scene, const RenderSettings& settings, const ProgressCallback& progress,
                RenderStatistics* statistics, const RenderStop& stop, RenderCoverage* coverage) {
    validateRenderSettings(settings);
    RenderStatistics stats;
    const auto stopRequested = [&] { return stop(); };
    // Light tracing runs in TBB tasks; an exception from its progress callback
    // cancels them and reaches the caller.
    const ProgressCallback preparing = [&](const char* phase, double fraction) {
        if (stopRequested()) throw RenderInterrupted();
        if (progress) progress(phase, fraction);
    };
    const RenderLights lights = prepareLights(scene, settings, preparing, &stats);
    if (stopRequested()) throw RenderInterrupted();
    const auto start = std::chrono::steady_clock::now();
    const TileShader shader(scene, settings, lights);
    const int width = scene.camera().width(), height = scene.camera().height();
    const std::vector<TileRect> tiles = imageTiles(
        width, height, balancedTileSize(width, height, settings.tileSize, tbb::this_task_arena::max_concurrency()));
    const int cap = settings.samplesPerPixel;
    SampleSums sums;
    std::vector<int> tileRows(tiles.size(), 0);
    int tilesDone = 0, passes = 0, samples = cap;
    if (settings.timeLimitSeconds <= 0.0) {
        // A fixed render: every pass of a tile at once, tile after tile.
        TilesShaded shaded = shadeTiles(shader, tiles, width, height, 0, passesFor(cap), stop, progress, "rendering");
        sums = std::move(shaded.sums);
        tileRows = std::move(shaded.tileRows);
        tilesDone = shaded.tilesDone;
        passes = passesFor(cap);
    } else {
        // Progressive: pass after pass over the whole image until the time limit.
        const auto deadline =
            start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(settings.timeLimitSeconds));
        const RenderStop passStop{[&] { return stop() || std::chrono::steady_clock::now() >= deadline; }};
        sums = SampleSums::zeros(width, height, shader.layerPerPixel());
        while (samplesAfter(passes, cap) < cap && !passStop()) {
            const SamplePass pass = samplePass(passes, cap);
            const std::string phase = "rendering pass " + std::to_string(passes + 1) + " (" +
                                      std::to_string(pass.count) + " spp, " +
                                      std::to_string(pass.first + pass.count) + " in all)";
            TilesShaded shaded = shadeTiles(shader, tiles, width, height, passes, 1, passStop, progress, phase);
            const bool complete = shaded.tilesDone == int(tiles.size());
            if (passes == 0) {  // a first pass cut short is kept, as an interrupt keeps its rows
                sums = std::move(shaded.sums);
                tileRows = std::move(shaded.tileRows);
                tilesDone = shaded.tilesDone;
            } else if (complete) {
                addPass(sums, shaded.sums);
            }
            if (!complete) break;
            ++passes;
        }
        if (passes > 0) {
            tilesDone = int(tiles.size());
            for (size_t t = 0; t < tiles.size(); ++t) tileRows[t] = tiles[t].height();
        }
        samples = std::max(1, samplesAfter(passes, cap));
    }
    if (coverage) fillCoverage(*coverage, tiles, tileRows, tilesDone, width, height);
    ImageSet result = assembleImageSet(resolveSamples(sums, shader.layerNames(), samples), shader.layerNames(), &stats);
    stats.boundExceeded = sums.boundExceeded;
    stats.boundedEstimates = sums.boundedEstimates;
    stats.seconds = secondsSince(start);
    stats.cameraSamples = uint64_t(width) * height * uint64_t(samples);
    stats.samplesPerPixel = samples;
    stats.passes = passes;
    if (statistics) *statistics = stats;
    return result;
}

}  // namespace vrl
