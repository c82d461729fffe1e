// server/: the coordinator program: a stateless gRPC shell (coordinator_service.h)
// over the Coordinator and its parts (job store, preparation, leases, workers, tiles).
//
// Coordinator: the job side of the service, without gRPC (coordinator_service.h
// puts it on the network). It keeps scene bundles by SHA-256, prepares each job
// once (parse, light tracing, light tree, serialisation) on a background thread,
// hands tiles to workers as leases, takes each tile's result exactly once, and
// writes the finished EXR under the state directory.
//
// Leases: a lease not completed by its deadline, or held by a worker whose
// heartbeats stopped, goes back to the queue; a tile's first valid result is
// merged (even a late one, if the tile is still missing: the pixels are the
// same), any later one is dropped, never merged twice; results are checked
// (registered worker, a lease issued for the tile, tile, layers, sizes, finite
// values) before they are accepted. A tile refused or given up maxTileRejections times fails its job.
//
// What survives a restart (same --state-dir): uploaded bundles, every job's
// spec and submit time, finished jobs (their EXR, record and finish time), and the accepted tiles of
// unfinished jobs (a checkpoint log): such jobs are prepared again (the light
// tree is deterministic) and resume with only their missing tiles.
//
// Retention: finished jobs older than options.retention (by finish time) are
// purged at start and then every min(retention / 10, 10 min), with their files
// and the bundles no remaining job uses; purgeJobs does the same on demand.
//
// The work is done by its parts: JobStore (job_store.h: jobs, state directory,
// checkpoints, blobs), JobPreparation (job_preparation.h), LeaseScheduler
// (lease_scheduler.h), WorkerRegistry (worker_registry.h) and tile assembly
// (tile_assembly.h), each on the Job record (job.h). None of them locks: the
// Coordinator owns them, the one mutex and condition variable and the two
// threads (preparation, reaper), and calls them with the mutex held.
#pragma once

#include "server/job.h"
#include "server/job_preparation.h"
#include "server/job_store.h"
#include "server/lease_scheduler.h"
#include "server/worker_registry.h"
#include "service/common/limits.h"
#include "service/common/service_error.h"
#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace vrl::server {

using rpc::ErrorKind;
using rpc::ServiceError;

struct CoordinatorOptions {
    std::filesystem::path stateDir = "vrl-state";
    std::chrono::milliseconds leaseTimeout{30000};      // a tile not returned by then is leased again
    std::chrono::milliseconds heartbeatInterval{2000};  // asked of workers
    std::chrono::milliseconds heartbeatTimeout{10000};  // a silent worker is forgotten, its leases requeued
    int maxTileRejections = 3;                          // invalid results for one tile before the job fails
    rpc::ServiceLimits limits;
    std::chrono::milliseconds retention{std::chrono::hours(24 * 7)};  // 0: keep finished jobs for ever
};

// Counters for logs and the benchmark.
struct CoordinatorStatistics {
    uint64_t tilesLeased = 0, tilesAccepted = 0, duplicatesDropped = 0, tilesRejected = 0, leasesExpired = 0;
    double leaseSeconds = 0.0, submitSeconds = 0.0;  // time spent in those calls (coordinator overhead)
};

class Coordinator {
public:
    explicit Coordinator(CoordinatorOptions options);
    ~Coordinator();
    Coordinator(const Coordinator&) = delete;
    Coordinator& operator=(const Coordinator&) = delete;

    // --- clients
    bool hasBundle(const std::string& sha256) const;
    // Verifies the hash, validates (limits, paths, links) and stores the bundle.
    void storeBundle(const std::string& sha256, const std::string& blob);
    std::string submitJob(const v1::JobSpec& spec);
    v1::JobProgress jobProgress(const std::string& jobId) const;
    // Waits until the job changes after version `seen` (or `timeout`); returns its version.
    uint64_t waitForChange(const std::string& jobId, uint64_t seen, std::chrono::milliseconds timeout) const;
    v1::JobState cancelJob(const std::string& jobId);
    std::vector<v1::JobProgress> listJobs() const;
    // The finished job's EXR; FailedPrecondition while it is not done.
    std::filesystem::path imageFile(const std::string& jobId) const;
    // The tiles finished so far as EXR bytes (tile_assembly.h: assemblePartialImage); a done job's
    // whole image; FailedPrecondition before rendering starts or once the job failed or was cancelled.
    std::string partialImage(const std::string& jobId) const;
    // Purges the finished jobs that ended at least `olderThan` ago (0: all finished jobs).
    v1::PurgeJobsReply purgeJobs(std::chrono::milliseconds olderThan);
    // Versions, limits, connected workers, retention (not whether a token is required: the gRPC layer knows).
    v1::ServiceInfo serviceInfo() const;

    // --- workers
    // Refuses (FailedPrecondition) another protocol or program version, naming both.
    v1::RegisterReply registerWorker(const v1::RegisterRequest& request);
    v1::HeartbeatReply heartbeat(const std::string& workerId);
    v1::LeaseReply leaseTiles(const v1::LeaseRequest& request);
    // A blob a worker needs (bundle or lights) by SHA-256; NotFound if no live job uses it.
    std::shared_ptr<const std::string> asset(const std::string& sha256) const;
    // A refused result (accepted false) sets `malformed` unless it was a duplicate or its job is no longer
    // rendering: the gRPC front answers those with INVALID_ARGUMENT.
    v1::SubmitTileReply submitTile(const v1::TileResult& result, bool* malformed = nullptr);
    void releaseLeases(const v1::ReleaseRequest& request);

    // --- shutdown: lease nothing more; outstanding leases still complete.
    void beginDrain();
    bool draining() const;
    size_t activeLeases() const;
    CoordinatorStatistics statistics() const;
    const rpc::ServiceLimits& limits() const { return options_.limits; }

private:
    void prepareLoop();  // the preparation thread
    void reaperLoop();   // the reaper thread: silent workers, expired leases
    // Prepares the job without the lock, then puts it to rendering under the lock.
    void prepare(Job& job);
    void finishJob(Job& job);  // lock held: all tiles done
    void endJob(Job& job, v1::JobState state, const std::string& message);  // lock held
    void countFailure(Job& job, uint32_t tile, const std::string& reason);  // lock held
    void touch(Job& job);                                                    // lock held: version++ and notify
    v1::PurgeJobsReply purgeLocked(std::chrono::milliseconds olderThan);      // lock held

    CoordinatorOptions options_;
    // The one lock: every part below is called with it held (except JobStore's and
    // JobPreparation's disk-only work, which their headers name).
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;  // a job changed, a job was queued, or stopping
    JobStore store_;
    WorkerRegistry workers_;
    LeaseScheduler leases_;
    JobPreparation preparation_;
    const Job* preparing_ = nullptr;  // the job prepare() works on without the lock: never purged
    std::chrono::steady_clock::time_point nextPurge_;
    bool draining_ = false, stopping_ = false;
    CoordinatorStatistics statistics_;
    std::thread preparer_, reaper_;
};

}  // namespace vrl::server
