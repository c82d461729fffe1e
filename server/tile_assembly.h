// Tile assembly: a job's image from its workers' tile results. mergeTile checks
// a result against the job's tiling (seconds, position, bounds, the passes the
// tile needs next, layer names, sizes and per-pixel flags, finite values) and
// hands its sample sums to the job's TilePasses (tile_passes.h);
// writeJobImage resolves the sums of the completed passes into the image, writes its
// metadata (the one writer, writeRenderMetadata) and the EXR at <job dir>/image.exr;
// assemblePartialImage does the same for a job still rendering: its completed
// passes if any (a whole image), else the tiles done so far, unfinished pixels
// zero and a "coverage" layer (render/image/partial_image.h). A time-limited job
// whose limit ran out in its first pass ends with that partial image too.
//
// Duplicate results: a tile takes each of its passes' first valid result only; a later one is
// refused as a duplicate (no fault of its sender) and never merged twice.
//
// Not thread-safe by itself: the Coordinator calls these with its mutex held.
#pragma once

#include "server/job.h"
#include "vrl/v1/vrl.pb.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace vrl::server {

// What became of a tile result.
struct TileMerge {
    std::string refusal;     // why it was refused; empty if merged
    bool duplicate = false;  // refused because the tile was already accepted
    uint32_t tile = 0;       // the result's tile, once found
    bool passCompleted = false;  // merged, and it completed a pass over the whole image
};

// Checks the result and, if it is valid and brings the passes its tile needs
// next, merges its sums (and bound counters); marks the tile done with its last pass.
TileMerge mergeTile(Job& job, const v1::TileResult& result);
// Adds a merged tile to its worker's share (tiles, pixels, seconds) in the job's progress.
void creditWorker(Job& job, const std::string& workerName, const v1::TileResult& result, uint32_t tile);
// Every pass done, or a time limit past: assembles the image of the completed
// passes (freeing the sums), writes its metadata and the EXR (atomically) and
// records the "render" phase. Returns why the EXR could not be written; nothing on success.
std::optional<std::string> writeJobImage(Job& job);

// A copy of what a partial image needs from a rendering job (taken under the lock).
struct PartialImageInput {
    std::string id;
    v1::JobSpec spec;
    int width = 0, height = 0;
    std::vector<TileRect> tiles;
    SampleSums sums;                    // TilePasses::imageSums
    std::vector<uint8_t> tilesCovered;  // per tile, when no pass is complete: its sums are in `sums`
    int passes = 0;                     // complete over the image
    std::vector<std::string> layerNames;
    std::map<std::string, std::string> sceneNotes;
    RenderSettings settings;
    std::optional<PerspectiveCamera> camera;
    RenderStatistics statistics;
    std::vector<std::pair<std::string, double>> phases;
    size_t workers = 0;
};
PartialImageInput partialImageInput(const Job& job);
// The image of `input` (its sums resolved, freed), with its metadata: whole when
// it has completed passes, else partial (markPartial) over the covered tiles.
ImageSet assembleJobImage(PartialImageInput& input);
// The finished tiles as EXR bytes: unfinished pixels 0, markPartial's coverage layer
// and vrl.partial / vrl.tilesTotal. Writes through a temporary file in `scratchDir`.
std::string assemblePartialImage(PartialImageInput input, const std::filesystem::path& scratchDir);

}  // namespace vrl::server
