// LeaseScheduler: which tile a worker renders next, and until when. Each
// rendering job queues its missing tiles (Job::pending, Job::queued); lease()
// takes them from the jobs in order of priority, then of submission, and lends
// each to the asking worker until now + leaseTimeout under an id
// "<job>:<tile>:<n>" (n counts every lease this coordinator issued).
//
// Lease semantics:
// - a lease not completed by its deadline, or held by a worker that the
//   registry forgot, goes back to the front of its job's queue (soon again);
// - a refused result's tile goes to the back (others first); a released lease
//   to the front, or to the back if the worker could not shade the tile;
// - a tile sits at most once in its queue, and one accepted since it was queued
//   is skipped when popped; a job that ends loses its queue and its leases;
// - a result whose lease expired still counts if the lease was issued for that
//   tile (wasIssued): the pixels are the same. tile_assembly.h takes each
//   tile's first valid result for each pass only;
// - a lease covers the passes TilePasses::nextLease gives (tile_passes.h): all
//   of them, or for a time-limited job the tile's next pass; a tile too far
//   ahead of the others waits (Job::waiting) and is queued again when a pass
//   completes over the image; a time-limited job past its deadline is leased nothing.
//
// Not thread-safe by itself: the Coordinator calls it with its mutex held.
#pragma once

#include "server/job.h"
#include "server/job_store.h"
#include "server/worker_registry.h"
#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <cstdint>
#include <map>
#include <string>

namespace vrl::server {

class LeaseScheduler {
public:
    using Clock = std::chrono::steady_clock;
    struct Lease {
        std::string jobId;
        uint32_t tile = 0;
        TilePasses::Range passes;
        std::string workerId;
        Clock::time_point deadline;
    };

    LeaseScheduler(JobStore& store, std::chrono::milliseconds leaseTimeout)
        : store_(store), leaseTimeout_(leaseTimeout) {}

    // Queues every tile of the job not yet done, in tile order.
    void queueMissing(Job& job);
    // After a result of `tile` was merged: queues its next pass, or marks it
    // waiting; when the result completed a pass, queues every waiting tile too.
    void queueNextPass(Job& job, uint32_t tile, bool passCompleted);
    // Up to clamp(maxTiles, 1, 64) leases for the worker, with the assets of each job
    // among them; none: retry_after_ms is set.
    v1::LeaseReply lease(const std::string& workerId, uint32_t maxTiles);

    const Lease* find(const std::string& leaseId) const;  // null if not live
    // The result's live lease if it is this worker's lease on this job's tile; null otherwise.
    const Lease* leaseOf(const v1::TileResult& result, const Job& job) const;
    // For a result without a live lease: why its lease id was never issued for its tile
    // of this job; empty if it was (or the tile is not one of the job's).
    std::string refuseUnissued(const v1::TileResult& result, const Job& job) const;
    void erase(const std::string& leaseId);
    // Ends the lease and queues its tile again, unless its job stopped rendering, the
    // tile is done or already queued. front: an expired lease (soon again); back: a
    // refused tile (others first).
    void requeue(const std::string& leaseId, bool front = true);
    // Requeues (front) the leases past their deadline or held by a worker no longer
    // registered; returns how many.
    size_t requeueExpired(Clock::time_point now, const WorkerRegistry& workers);
    // The job ended: empties its queue and forgets its leases.
    void dropJob(Job& job);
    size_t active() const { return leases_.size(); }

private:
    JobStore& store_;
    std::chrono::milliseconds leaseTimeout_;
    std::map<std::string, Lease> leases_;
    uint64_t nextLease_ = 0;
};

}  // namespace vrl::server
