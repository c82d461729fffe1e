#include "server/coordinator.h"

#include "render/core/timing.h"
#include "server/tile_assembly.h"
#include "service/common/limits_proto.h"
#include "service/common/rpc_common.h"
#include "service/job/job_scene.h"
#include "util/strings.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

namespace vrl::server {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr size_t kMaxMessageBytes = 4096;  // a job's failure message as stored and shown
constexpr auto kOrphanBundleAge = std::chrono::hours(1);  // a bundle no job uses is kept this long after its upload

std::chrono::milliseconds purgePeriod(std::chrono::milliseconds retention) {
    return std::clamp<std::chrono::milliseconds>(retention / 10, std::chrono::milliseconds(100), std::chrono::minutes(10));
}

}  // namespace

Coordinator::Coordinator(CoordinatorOptions options)
    : options_(std::move(options)),
      store_(options_.stateDir, options_.limits),  // creates the state directory, loads its jobs
      workers_(options_.heartbeatInterval, options_.heartbeatTimeout),
      leases_(store_, options_.leaseTimeout),
      preparation_(store_, options_.limits) {
    if (options_.retention.count() > 0) purgeLocked(options_.retention);  // no thread runs yet
    nextPurge_ = Clock::now() + purgePeriod(options_.retention);
    preparer_ = std::thread([this] { prepareLoop(); });
    reaper_ = std::thread([this] { reaperLoop(); });
}

Coordinator::~Coordinator() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    preparer_.join();
    reaper_.join();
}

// ------------------------------------------------------------------ bundles and jobs

bool Coordinator::hasBundle(const std::string& sha256) const {
    return store_.hasBundle(sha256);
}

void Coordinator::storeBundle(const std::string& sha256, const std::string& blob) {
    store_.storeBundle(sha256, blob);
}

std::string Coordinator::submitJob(const v1::JobSpec& spec) {
    try {
        rpc::validateJobSpec(spec, options_.limits);
    } catch (const rpc::JobSpecError& e) {
        throw ServiceError(ErrorKind::InvalidArgument, e.what());
    }
    requireHash(spec.bundle_sha256(), "bundle_sha256");
    if (!hasBundle(spec.bundle_sha256()))
        throw ServiceError(ErrorKind::NotFound, "no scene bundle " + spec.bundle_sha256() + " here; upload it first");
    auto job = store_.newJob(spec);
    if (draining()) throw ServiceError(ErrorKind::FailedPrecondition, "the coordinator is shutting down");
    store_.writeSpec(*job);
    store_.writeRecord(*job);  // its submit time, kept across restarts
    const std::string id = job->id;
    {
        std::lock_guard lock(mutex_);
        store_.add(std::move(job));
    }
    changed_.notify_all();
    spdlog::info("{}: submitted ('{}', {}, priority {})", id, spec.name(),
                 spec.parameters().method().empty() ? "the scene's or the headline method" : spec.parameters().method(),
                 spec.priority());
    return id;
}

v1::JobProgress Coordinator::jobProgress(const std::string& jobId) const {
    std::lock_guard lock(mutex_);
    return progressOf(store_.find(jobId));
}

uint64_t Coordinator::waitForChange(const std::string& jobId, uint64_t seen, std::chrono::milliseconds timeout) const {
    std::unique_lock lock(mutex_);
    (void)store_.find(jobId);
    // Looked up again on each wake-up: a finished job may be purged meanwhile (then NotFound).
    changed_.wait_for(lock, timeout, [&] {
        const auto it = store_.jobs().find(jobId);
        return it == store_.jobs().end() || it->second->version != seen || stopping_;
    });
    return store_.find(jobId).version;
}

std::vector<v1::JobProgress> Coordinator::listJobs() const {
    std::lock_guard lock(mutex_);
    std::vector<v1::JobProgress> out;
    for (const Job* job : store_.bySequence()) out.push_back(progressOf(*job));
    return out;
}

v1::JobState Coordinator::cancelJob(const std::string& jobId) {
    std::lock_guard lock(mutex_);
    Job& job = store_.find(jobId);
    if (!isTerminal(job.state)) endJob(job, v1::JOB_STATE_CANCELLED, "cancelled by a client");
    return job.state;
}

fs::path Coordinator::imageFile(const std::string& jobId) const {
    std::lock_guard lock(mutex_);
    const Job& job = store_.find(jobId);
    if (job.state != v1::JOB_STATE_DONE)
        throw ServiceError(ErrorKind::FailedPrecondition, "job '" + jobId + "' has no image yet (state " +
                                                              v1::JobState_Name(job.state) + ")");
    return job.dir / "image.exr";
}

std::string Coordinator::partialImage(const std::string& jobId) const {
    PartialImageInput input;
    {
        std::lock_guard lock(mutex_);
        const Job& job = store_.find(jobId);
        if (job.state == v1::JOB_STATE_DONE) return rpc::readFileText((job.dir / "image.exr").string());
        if (job.state != v1::JOB_STATE_RENDERING)
            throw ServiceError(ErrorKind::FailedPrecondition, "job '" + jobId + "' has no tiles to show (state " +
                                                                  v1::JobState_Name(job.state) + ")");
        input = partialImageInput(job);  // a copy: assembled and encoded without the lock
    }
    return assemblePartialImage(std::move(input), store_.stateDir() / "jobs" / jobId);
}

v1::PurgeJobsReply Coordinator::purgeJobs(std::chrono::milliseconds olderThan) {
    std::lock_guard lock(mutex_);
    return purgeLocked(olderThan);
}

v1::PurgeJobsReply Coordinator::purgeLocked(std::chrono::milliseconds olderThan) {
    v1::PurgeJobsReply reply;
    const int64_t before = unixMillisecondsNow() - olderThan.count();
    std::vector<std::string> ids;
    for (const Job* job : store_.bySequence()) {
        if (!isTerminal(job->state) || job == preparing_) continue;
        // A job finished before finish times were recorded counts as finished at its submission.
        const int64_t finished = job->finishedUnixMs > 0 ? job->finishedUnixMs : job->submittedUnixMs;
        if (olderThan.count() > 0 && finished > before) continue;
        *reply.add_purged() = progressOf(*job);
        ids.push_back(job->id);
    }
    uint32_t bundles = 0;
    reply.set_bytes_freed(store_.purge(ids, kOrphanBundleAge, &bundles));
    reply.set_bundles_removed(bundles);
    if (!ids.empty() || bundles > 0)
        spdlog::info("purged {} finished jobs and {} bundles ({} bytes)", ids.size(), bundles, reply.bytes_freed());
    if (!ids.empty()) changed_.notify_all();  // watchers of a purged job learn it is gone
    return reply;
}

v1::ServiceInfo Coordinator::serviceInfo() const {
    v1::ServiceInfo info;
    info.set_program_version(VRL_VERSION);
    info.set_protocol_version(rpc::kProtocolVersion);
    *info.mutable_limits() = rpc::toProto(options_.limits);
    info.set_retention_ms(options_.retention.count());
    std::lock_guard lock(mutex_);
    info.set_workers_connected(uint32_t(workers_.count()));
    return info;
}

void Coordinator::touch(Job& job) {
    ++job.version;
    changed_.notify_all();
}

void Coordinator::endJob(Job& job, v1::JobState state, const std::string& message) {
    job.state = state;
    job.finishedUnixMs = unixMillisecondsNow();
    job.message = util::abbreviate(message, kMaxMessageBytes);  // shown in every listing: bounded
    leases_.dropJob(job);
    job.passes.clear();
    store_.closeCheckpoint(job);
    store_.writeRecord(job);
    store_.pruneAssets();
    touch(job);
    if (state == v1::JOB_STATE_FAILED) spdlog::error("{}: failed: {}", job.id, message);
    else spdlog::info("{}: {}", job.id, v1::JobState_Name(state));
}

// ------------------------------------------------------------------ preparation

void Coordinator::prepareLoop() {
    while (true) {
        Job* next = nullptr;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] { return stopping_ || (next = preparation_.next()) != nullptr; });
            if (stopping_) return;
            next->state = v1::JOB_STATE_PREPARING;
            preparing_ = next;  // not purged while prepare() holds it, even if cancelled meanwhile
            touch(*next);
        }
        prepare(*next);
        std::lock_guard lock(mutex_);
        preparing_ = nullptr;
    }
}

void Coordinator::prepare(Job& job) {
    try {
        const PreparedJob prepared = preparation_.prepare(job, [&](const char* phase, double f) {
            std::lock_guard lock(mutex_);
            if (job.preparingPhase != phase || std::abs(f - job.preparingFraction) >= 0.01 || f >= 1.0) {
                if (job.preparingPhase != phase && !job.preparingPhase.empty())
                    job.preparingPhasesDone.push_back(job.preparingPhase);
                job.preparingPhase = phase;
                job.preparingFraction = f;
                touch(job);
            }
        });

        std::lock_guard lock(mutex_);
        if (job.state != v1::JOB_STATE_PREPARING) return;  // cancelled meanwhile
        if (!job.preparingPhase.empty()) job.preparingPhasesDone.push_back(job.preparingPhase);
        preparation_.install(job, prepared);
        store_.publishAsset(job.spec.bundle_sha256(), prepared.bundle);
        if (prepared.lights) store_.publishAsset(prepared.lightsSha, prepared.lights);
        for (const auto& result : prepared.replay)  // accepted before a restart: checked again, not logged again
            if (mergeTile(job, result).duplicate) ++statistics_.duplicatesDropped;
        job.doneAtStart = job.doneCount;
        leases_.queueMissing(job);
        store_.openCheckpoint(job);
        job.renderStart = Clock::now();  // a restarted coordinator gives a time-limited job its whole limit again
        if (job.settings.timeLimitSeconds > 0.0)
            job.deadline = job.renderStart + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double>(job.settings.timeLimitSeconds));
        spdlog::info("{}: prepared in {:.3f} s: {}x{}, {} tiles ({} restored), {} VRLs, lights blob {} bytes", job.id,
                     secondsSince(prepared.start), prepared.width, prepared.height, prepared.tiles.size(),
                     job.doneCount, prepared.statistics.vrlCount, prepared.lights ? prepared.lights->size() : 0);
        touch(job);
        if (job.passes.passesDone() == job.passes.passesTotal()) finishJob(job);
    } catch (const std::exception& e) {
        std::lock_guard lock(mutex_);
        if (job.state == v1::JOB_STATE_PREPARING) endJob(job, v1::JOB_STATE_FAILED, e.what());
    }
}

// ------------------------------------------------------------------ workers

v1::RegisterReply Coordinator::registerWorker(const v1::RegisterRequest& request) {
    WorkerRegistry::checkRegistration(request);
    std::lock_guard lock(mutex_);
    return workers_.add(request);
}

v1::HeartbeatReply Coordinator::heartbeat(const std::string& workerId) {
    requireWorkerId(workerId);
    std::lock_guard lock(mutex_);
    v1::HeartbeatReply reply;
    reply.set_known(workers_.beat(workerId));
    reply.set_draining(draining_);
    return reply;
}

v1::LeaseReply Coordinator::leaseTiles(const v1::LeaseRequest& request) {
    const auto start = Clock::now();
    requireWorkerId(request.worker_id());
    std::lock_guard lock(mutex_);
    workers_.requireKnown(request.worker_id());
    workers_.beat(request.worker_id());
    if (draining_) {
        v1::LeaseReply reply;
        reply.set_draining(true);
        reply.set_retry_after_ms(1000);
        return reply;
    }
    v1::LeaseReply reply = leases_.lease(request.worker_id(), request.max_tiles());
    statistics_.tilesLeased += uint64_t(reply.leases_size());
    statistics_.leaseSeconds += secondsSince(start);
    return reply;
}

std::shared_ptr<const std::string> Coordinator::asset(const std::string& sha256) const {
    requireHash(sha256, "sha256");
    std::lock_guard lock(mutex_);
    return store_.asset(sha256);
}

v1::SubmitTileReply Coordinator::submitTile(const v1::TileResult& result, bool* malformed) {
    const auto start = Clock::now();
    if (malformed) *malformed = false;
    requireWorkerId(result.worker_id());
    std::lock_guard lock(mutex_);
    v1::SubmitTileReply reply;
    Job& job = store_.find(result.job_id());
    workers_.requireKnown(result.worker_id());
    // The lease counts only if it is this worker's lease on this job's tile.
    const LeaseScheduler::Lease* lease = leases_.leaseOf(result, job);
    if (job.state != v1::JOB_STATE_RENDERING) {
        if (lease) leases_.erase(result.lease_id());
        reply.set_reason("job is " + v1::JobState_Name(job.state));
        return reply;
    }
    std::string refused;
    if (!lease)  // no live lease: a late result still counts, one for a lease never issued not
        refused = leases_.refuseUnissued(result, job);
    bool duplicate = false;
    TileMerge merge;
    if (refused.empty()) {
        merge = mergeTile(job, result);
        refused = merge.refusal;
        duplicate = merge.duplicate;
        if (duplicate) ++statistics_.duplicatesDropped;
        if (refused.empty()) {
            creditWorker(job, workers_.nameOf(result.worker_id()), result, merge.tile);
            store_.appendCheckpoint(job, result);
        }
    }
    if (refused.empty()) {
        reply.set_accepted(true);
        ++statistics_.tilesAccepted;
        if (lease) leases_.erase(result.lease_id());  // other leases on the tile expire harmlessly
        leases_.queueNextPass(job, merge.tile, merge.passCompleted);
        touch(job);
        if (job.passes.passesDone() == job.passes.passesTotal()) finishJob(job);
    } else {
        reply.set_reason(refused);
        if (!duplicate) {
            if (malformed) *malformed = true;
            ++statistics_.tilesRejected;
            spdlog::warn("{}: tile result from {} refused: {}", job.id, result.worker_id(), refused);
            if (lease) {
                const uint32_t tile = lease->tile;
                leases_.requeue(result.lease_id(), false);
                countFailure(job, tile, refused);
            }
        } else if (lease) {
            leases_.erase(result.lease_id());
        }
    }
    statistics_.submitSeconds += secondsSince(start);
    return reply;
}

// A tile refused or given up maxTileRejections times fails its job.
void Coordinator::countFailure(Job& job, uint32_t tile, const std::string& reason) {
    if (job.state != v1::JOB_STATE_RENDERING || ++job.rejections[tile] < options_.maxTileRejections) return;
    endJob(job, v1::JOB_STATE_FAILED,
           "tile " + std::to_string(tile) + " failed " + std::to_string(job.rejections[tile]) + " times (last: " +
               reason + ")");
}

void Coordinator::releaseLeases(const v1::ReleaseRequest& request) {
    requireWorkerId(request.worker_id());
    const std::string failure = util::abbreviate(request.failure(), 1024);
    std::lock_guard lock(mutex_);
    for (const auto& id : request.lease_ids()) {
        const LeaseScheduler::Lease* lease = leases_.find(id);
        if (!lease || lease->workerId != request.worker_id()) continue;
        const std::string jobId = lease->jobId;
        const uint32_t tile = lease->tile;
        leases_.requeue(id, request.failure().empty());  // given back: soon again; could not shade it: others first
        if (!request.failure().empty())
            if (const auto job = store_.jobs().find(jobId); job != store_.jobs().end())
                countFailure(*job->second, tile, "a worker could not shade it: " + failure);
    }
}

void Coordinator::reaperLoop() {
    const auto period = std::clamp(options_.leaseTimeout / 4, std::chrono::milliseconds(20), std::chrono::milliseconds(250));
    std::unique_lock lock(mutex_);
    while (!stopping_) {
        changed_.wait_for(lock, period);
        if (stopping_) break;
        const auto now = Clock::now();
        workers_.forgetSilent(now);
        statistics_.leasesExpired += leases_.requeueExpired(now, workers_);
        // Time-limited jobs past their limit end with the passes complete by then.
        std::vector<Job*> expired;
        for (const auto& [id, job] : store_.jobs())
            if (job->state == v1::JOB_STATE_RENDERING && job->deadline && now >= *job->deadline) expired.push_back(job.get());
        for (Job* job : expired) finishJob(*job);
        if (options_.retention.count() > 0 && now >= nextPurge_) {
            purgeLocked(options_.retention);
            nextPurge_ = now + purgePeriod(options_.retention);
        }
    }
}

// ------------------------------------------------------------------ the end of a job

void Coordinator::finishJob(Job& job) {
    if (job.passes.passesDone() == 0 && job.passes.tilesInCurrentPass() == 0) {
        endJob(job, v1::JOB_STATE_FAILED,
               "the time limit of " + std::to_string(job.settings.timeLimitSeconds) +
                   " s ran out before any tile was rendered; give a longer --time-limit");
        return;
    }
    if (const auto error = writeJobImage(job)) {
        endJob(job, v1::JOB_STATE_FAILED, "cannot write the image: " + *error);
        return;
    }
    endJob(job, v1::JOB_STATE_DONE, "");
}

// ------------------------------------------------------------------ shutdown

void Coordinator::beginDrain() {
    std::lock_guard lock(mutex_);
    draining_ = true;
    changed_.notify_all();
}

bool Coordinator::draining() const {
    std::lock_guard lock(mutex_);
    return draining_;
}

size_t Coordinator::activeLeases() const {
    std::lock_guard lock(mutex_);
    return leases_.active();
}

CoordinatorStatistics Coordinator::statistics() const {
    std::lock_guard lock(mutex_);
    return statistics_;
}

}  // namespace vrl::server
