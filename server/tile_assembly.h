// Tile assembly: a job's image from its workers' tile results. mergeTile checks
// a result against the job's tiling (seconds, position, bounds, layer names and
// sizes, finite values) and copies its pixels into the job's layers;
// writeJobImage assembles the finished image, writes its metadata (the one
// writer, writeRenderMetadata) and the EXR at <job dir>/image.exr;
// assemblePartialImage does the same for a job still rendering, with its
// unfinished pixels zero and a "coverage" layer (render/image/partial_image.h).
//
// Duplicate tiles: a tile takes its first valid result only; a later one is
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
};

// Checks the result and, if it is valid and its tile still missing, merges its
// pixels, marks the tile done and adds its bound counters to the job's.
TileMerge mergeTile(Job& job, const v1::TileResult& result);
// Adds a merged tile to its worker's share (tiles, pixels, seconds) in the job's progress.
void creditWorker(Job& job, const std::string& workerName, const v1::TileResult& result, uint32_t tile);
// All tiles done: assembles the image (freeing the layers), writes its metadata and
// the EXR (atomically) and records the "render" phase. Returns why the EXR could not
// be written; nothing on success.
std::optional<std::string> writeJobImage(Job& job);

// A copy of what a partial image needs from a rendering job (taken under the lock).
struct PartialImageInput {
    std::string id;
    v1::JobSpec spec;
    int width = 0, height = 0;
    std::vector<TileRect> tiles;
    std::vector<uint8_t> done;
    uint32_t doneCount = 0;
    std::vector<Image> layers;
    std::vector<std::string> layerNames;
    std::map<std::string, std::string> sceneNotes;
    RenderSettings settings;
    std::optional<PerspectiveCamera> camera;
    RenderStatistics statistics;
    std::vector<std::pair<std::string, double>> phases;
    size_t workers = 0;
};
PartialImageInput partialImageInput(const Job& job);
// The finished tiles as EXR bytes: unfinished pixels 0, markPartial's coverage layer
// and vrl.partial / vrl.tilesTotal. Writes through a temporary file in `scratchDir`.
std::string assemblePartialImage(PartialImageInput input, const std::filesystem::path& scratchDir);

}  // namespace vrl::server
