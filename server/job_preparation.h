// JobPreparation: turns a queued job into one ready to render, once per job
// (and again after a restart: the light tree is deterministic, so the tiles in
// its checkpoint still fit). prepare() reads the bundle, loads the scene
// (rpc::loadJobScene, the one builder of RenderSettings), traces the lights,
// builds their trees, encodes them for the workers (rpc::encodeJobLights),
// tiles the image (at most limits.maxTiles tiles) and reads the checkpoint;
// install() puts the result on the job. Queuing the missing tiles, replaying
// the checkpoint and publishing the blobs are the Coordinator's
// (lease_scheduler.h, tile_assembly.h, job_store.h).
//
// Not thread-safe by itself: the Coordinator calls next() and install() with its
// mutex held, and prepare() without it, on its preparation thread; prepare()
// reads only the job's id, spec and directory, which never change.
#pragma once

#include "render/renderer.h"
#include "render/scene/camera.h"
#include "server/job.h"
#include "server/job_store.h"
#include "service/common/limits.h"
#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vrl::server {

// What prepare() computed for a job, not yet on the job.
struct PreparedJob {
    std::chrono::steady_clock::time_point start;  // when preparation began
    std::vector<std::pair<std::string, double>> phases;  // "load scene", "light tracing", ...
    int width = 0, height = 0;
    std::vector<TileRect> tiles;
    std::vector<std::string> layerNames;
    std::map<std::string, std::string> sceneNotes;
    RenderSettings settings;
    std::optional<PerspectiveCamera> camera;
    RenderStatistics statistics;  // of the light work
    std::shared_ptr<const std::string> bundle;  // the bundle's blob, for workers
    std::shared_ptr<const std::string> lights;  // the lights blob (job_lights_blob.h); null if there is none
    std::string lightsSha;                      // its SHA-256; empty if none
    std::vector<v1::TileResult> replay;         // accepted tiles from before a restart
};

class JobPreparation {
public:
    JobPreparation(JobStore& store, const rpc::ServiceLimits& limits) : store_(store), limits_(limits) {}

    // The queued job to prepare next (highest priority, then first submitted); null if none.
    Job* next() const;
    // Throws (rpc::JobSpecError, scene errors, I/O) if the job cannot be rendered.
    PreparedJob prepare(const Job& job, const ProgressCallback& progress) const;
    // Sets the job's image, tiles, layers, assets and phases from `prepared`, all
    // tiles missing, and its state RENDERING.
    void install(Job& job, const PreparedJob& prepared) const;

private:
    JobStore& store_;
    rpc::ServiceLimits limits_;
};

}  // namespace vrl::server
