// Tile assembly: a job's image from its workers' tile results. mergeTile checks
// a result against the job's tiling (seconds, position, bounds, layer names and
// sizes, finite values) and copies its pixels into the job's layers;
// writeJobImage assembles the finished image, writes its metadata (the one
// writer, writeRenderMetadata) and the EXR at <job dir>/image.exr.
//
// Duplicate tiles: a tile takes its first valid result only; a later one is
// refused as a duplicate (no fault of its sender) and never merged twice.
//
// Not thread-safe by itself: the Coordinator calls these with its mutex held.
#pragma once

#include "server/job.h"
#include "vrl/v1/vrl.pb.h"

#include <cstdint>
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

}  // namespace vrl::server
