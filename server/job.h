// Job: the coordinator's record of one job, from its spec to its end. Plain
// data: the parts (job_store.h, job_preparation.h, lease_scheduler.h,
// tile_assembly.h) read and change it, and the Coordinator serialises every
// access with its mutex, except `id`, `spec` and `dir`, which are set before the
// job is stored and never change (so preparation may read them without the lock).
//
// Lifecycle: QUEUED -> PREPARING -> RENDERING -> DONE, or FAILED / CANCELLED from
// any state before DONE. A finished job may be purged (Coordinator::purgeJobs):
// only then is it erased, so a Job& of an unfinished job stays valid.
#pragma once

#include "render/image/image.h"
#include "render/renderer.h"
#include "render/scene/camera.h"
#include "server/tile_passes.h"
#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vrl::server {

// Progress phases whose times are also in RenderStatistics (tracingSeconds, treeSeconds).
inline constexpr const char* kLightTracingPhase = "light tracing";
inline constexpr const char* kLightTreePhase = "light tree";

struct Job {
    std::string id;
    v1::JobSpec spec;
    uint64_t sequence = 0;  // submission order, ties between equal priorities
    std::filesystem::path dir;
    v1::JobState state = v1::JOB_STATE_QUEUED;
    std::string message;
    uint64_t version = 0;  // bumped on every change that waitForChange reports
    double preparingFraction = 0.0;  // of preparingPhase
    std::string preparingPhase;
    std::vector<std::string> preparingPhasesDone;  // in order; the last one once the job is prepared
    int64_t submittedUnixMs = 0;  // wall clock, persisted in record.pb
    int64_t finishedUnixMs = 0;   // 0 while unfinished
    std::vector<std::pair<std::string, double>> phases;
    // Set once prepared:
    int width = 0, height = 0;
    std::vector<TileRect> tiles;
    std::map<std::pair<int, int>, uint32_t> tileAt;  // (x0, y0) -> tile
    std::vector<std::string> layerNames;
    std::map<std::string, std::string> sceneNotes;  // EXR metadata: approximations, ignored plugins
    RenderSettings settings;                        // as resolved by loadJobScene
    std::optional<PerspectiveCamera> camera;        // for the EXR's camera matrices
    v1::JobAssets assets;
    std::deque<uint32_t> pending;  // may hold tiles done since they were queued: skipped when popped
    std::vector<uint8_t> queued;   // tile is in `pending`
    std::vector<uint8_t> waiting;  // progressive: tile is ahead of the others; queued again when a pass completes
    std::vector<uint8_t> done;     // every pass of the tile accepted
    std::vector<int> rejections;
    uint32_t doneCount = 0;
    TilePasses passes;             // the tiles' sample sums, pass by pass
    RenderStatistics renderStatistics;
    std::chrono::steady_clock::time_point renderStart;
    // A time-limited job: no lease after this; then it ends with the passes complete by then.
    std::optional<std::chrono::steady_clock::time_point> deadline;
    uint32_t doneAtStart = 0;  // tiles restored from the checkpoint
    struct WorkerShare {
        uint64_t tiles = 0, pixels = 0;
        double seconds = 0.0;
    };
    std::map<std::string, WorkerShare> workers;  // by worker name
    std::ofstream checkpoint;                    // tiles.log, open while rendering
};

bool isTerminal(v1::JobState state);

// Milliseconds since the Unix epoch, now (the times jobs record).
int64_t unixMillisecondsNow();

// The job as clients see it: state, tiles, ETA, each worker's share, phase times.
v1::JobProgress progressOf(const Job& job);

}  // namespace vrl::server
