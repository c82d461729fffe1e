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
// spec, finished jobs (their EXR and record), and the accepted tiles of
// unfinished jobs (a checkpoint log): such jobs are prepared again (the light
// tree is deterministic) and resume with only their missing tiles.
#pragma once

#include "proto/service_limits.h"
#include "render/image.h"
#include "render/renderer.h"
#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace vrl::server {

// An error for the caller, with the gRPC-independent kind of status it maps to.
enum class ErrorKind { InvalidArgument, NotFound, FailedPrecondition, ResourceExhausted };
struct ServiceError : std::runtime_error {
    ServiceError(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind(kind) {}
    ErrorKind kind;
};

struct CoordinatorOptions {
    std::filesystem::path stateDir = "vrl-state";
    std::chrono::milliseconds leaseTimeout{30000};      // a tile not returned by then is leased again
    std::chrono::milliseconds heartbeatInterval{2000};  // asked of workers
    std::chrono::milliseconds heartbeatTimeout{10000};  // a silent worker is forgotten, its leases requeued
    int maxTileRejections = 3;                          // invalid results for one tile before the job fails
    rpc::ServiceLimits limits;
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
    struct Job;
    struct Lease {
        std::string jobId;
        uint32_t tile = 0;
        std::string workerId;
        std::chrono::steady_clock::time_point deadline;
    };
    struct WorkerRecord {
        std::string name;
        uint32_t threads = 0;
        std::chrono::steady_clock::time_point lastHeartbeat;
    };

    void loadState();
    void prepareLoop();
    void reaperLoop();
    void prepare(Job& job);  // called without the lock
    Job& findJob(const std::string& jobId) const;  // lock held; NotFound
    v1::JobProgress progressOf(const Job& job) const;  // lock held
    // Checks and applies a tile result; returns the reason it was refused, empty if taken. Lock held.
    std::string applyTile(Job& job, const v1::TileResult& result, bool replay);
    void finishJob(Job& job);                     // lock held: all tiles done
    void endJob(Job& job, v1::JobState state, const std::string& message);  // lock held
    // Lock held. front: an expired lease (soon again); back: a refused tile (others first).
    void requeue(const std::string& leaseId, bool front = true);
    void countFailure(Job& job, uint32_t tile, const std::string& reason);  // lock held
    void pruneAssets();                           // lock held
    void touch(Job& job);                         // lock held: version++ and notify

    CoordinatorOptions options_;
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;
    std::map<std::string, std::unique_ptr<Job>> jobs_;
    std::map<std::string, Lease> leases_;
    std::map<std::string, WorkerRecord> workers_;
    std::map<std::string, std::shared_ptr<const std::string>> assets_;
    uint64_t nextSequence_ = 0, nextLease_ = 0, nextWorker_ = 0;
    bool draining_ = false, stopping_ = false;
    CoordinatorStatistics statistics_;
    std::thread preparer_, reaper_;
};

}  // namespace vrl::server
