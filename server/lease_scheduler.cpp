#include "server/lease_scheduler.h"

#include "util/strings.h"

#include <algorithm>
#include <set>
#include <vector>

namespace vrl::server {

namespace {

// A lease id this coordinator issued for `tile` of `jobId` ("job:tile:n", n <= lastLease); it may have expired since.
bool leaseWasIssued(const std::string& leaseId, const std::string& jobId, uint32_t tile, uint64_t lastLease) {
    const std::string prefix = jobId + ":" + std::to_string(tile) + ":";
    if (leaseId.size() <= prefix.size() || leaseId.size() > prefix.size() + 19 ||
        leaseId.compare(0, prefix.size(), prefix) != 0)
        return false;
    const std::string number = leaseId.substr(prefix.size());  // 1..19 digits: stoull cannot overflow
    if (!std::all_of(number.begin(), number.end(), [](char c) { return c >= '0' && c <= '9'; })) return false;
    const unsigned long long n = std::stoull(number);
    return n >= 1 && n <= lastLease;
}

}  // namespace

void LeaseScheduler::queueMissing(Job& job) {
    for (uint32_t t = 0; t < job.tiles.size(); ++t)
        if (!job.done[t]) {
            job.pending.push_back(t);
            job.queued[t] = 1;
        }
}

void LeaseScheduler::queueNextPass(Job& job, uint32_t tile, bool passCompleted) {
    const auto queue = [&](uint32_t t) {
        if (job.done[t] || job.queued[t]) return;
        if (job.passes.nextLease(t).count == 0) {
            job.waiting[t] = 1;
            return;
        }
        job.waiting[t] = 0;
        job.queued[t] = 1;
        job.pending.push_back(t);
    };
    if (passCompleted)
        for (uint32_t t = 0; t < job.tiles.size(); ++t)
            if (job.waiting[t]) queue(t);
    queue(tile);
}

v1::LeaseReply LeaseScheduler::lease(const std::string& workerId, uint32_t maxTiles) {
    v1::LeaseReply reply;
    std::vector<Job*> ready;
    const auto now = Clock::now();
    for (const auto& [id, job] : store_.jobs())
        if (job->state == v1::JOB_STATE_RENDERING && !job->pending.empty() && !(job->deadline && now >= *job->deadline))
            ready.push_back(job.get());
    std::sort(ready.begin(), ready.end(), [](const Job* a, const Job* b) {
        return a->spec.priority() != b->spec.priority() ? a->spec.priority() > b->spec.priority()
                                                        : a->sequence < b->sequence;
    });
    const uint32_t wanted = std::clamp<uint32_t>(maxTiles, 1, 64);
    std::set<std::string> described;
    for (Job* job : ready) {
        while (uint32_t(reply.leases_size()) < wanted && !job->pending.empty()) {
            const uint32_t tile = job->pending.front();
            job->pending.pop_front();
            job->queued[tile] = 0;
            if (job->done[tile]) continue;  // accepted since it was queued
            const TilePasses::Range passes = job->passes.nextLease(tile);
            if (passes.count == 0) {  // ahead of the other tiles: queued again when a pass completes
                job->waiting[tile] = 1;
                continue;
            }
            const std::string leaseId = job->id + ":" + std::to_string(tile) + ":" + std::to_string(++nextLease_);
            leases_[leaseId] = Lease{job->id, tile, passes, workerId, Clock::now() + leaseTimeout_};
            auto* lease = reply.add_leases();
            lease->set_lease_id(leaseId);
            lease->set_job_id(job->id);
            const TileRect& r = job->tiles[tile];
            lease->mutable_tile()->set_x0(r.x0);
            lease->mutable_tile()->set_y0(r.y0);
            lease->mutable_tile()->set_x1(r.x1);
            lease->mutable_tile()->set_y1(r.y1);
            lease->set_deadline_ms(uint32_t(leaseTimeout_.count()));
            lease->set_first_pass(uint32_t(passes.first));
            lease->set_pass_count(uint32_t(passes.count));
            if (described.insert(job->id).second) *reply.add_jobs() = job->assets;
        }
        if (uint32_t(reply.leases_size()) >= wanted) break;
    }
    if (reply.leases_size() == 0) reply.set_retry_after_ms(100);
    return reply;
}

const LeaseScheduler::Lease* LeaseScheduler::find(const std::string& leaseId) const {
    const auto it = leases_.find(leaseId);
    return it == leases_.end() ? nullptr : &it->second;
}

const LeaseScheduler::Lease* LeaseScheduler::leaseOf(const v1::TileResult& result, const Job& job) const {
    const Lease* lease = find(result.lease_id());
    if (!lease) return nullptr;
    const auto at = job.tileAt.find({int(result.tile().x0()), int(result.tile().y0())});
    if (lease->jobId != job.id || lease->workerId != result.worker_id() || at == job.tileAt.end() ||
        at->second != lease->tile || result.first_pass() != uint32_t(lease->passes.first) ||
        result.pass_count() != uint32_t(lease->passes.count))
        return nullptr;
    return lease;
}

std::string LeaseScheduler::refuseUnissued(const v1::TileResult& result, const Job& job) const {
    const auto at = job.tileAt.find({int(result.tile().x0()), int(result.tile().y0())});
    if (at == job.tileAt.end() || leaseWasIssued(result.lease_id(), job.id, at->second, nextLease_)) return {};
    return result.lease_id().empty() ? "lease_id is required"
                                     : "lease '" + util::abbreviate(result.lease_id()) + "' was never issued for tile " +
                                           std::to_string(at->second) + " of this job";
}

void LeaseScheduler::erase(const std::string& leaseId) {
    leases_.erase(leaseId);
}

void LeaseScheduler::requeue(const std::string& leaseId, bool front) {
    const auto it = leases_.find(leaseId);
    if (it == leases_.end()) return;
    const Lease lease = it->second;
    leases_.erase(it);
    const auto job = store_.jobs().find(lease.jobId);
    if (job == store_.jobs().end() || job->second->state != v1::JOB_STATE_RENDERING || job->second->done[lease.tile])
        return;
    Job& owner = *job->second;
    if (owner.queued[lease.tile]) return;
    owner.queued[lease.tile] = 1;
    if (front) owner.pending.push_front(lease.tile);
    else owner.pending.push_back(lease.tile);
}

size_t LeaseScheduler::requeueExpired(Clock::time_point now, const WorkerRegistry& workers) {
    std::vector<std::string> expired;
    for (const auto& [id, lease] : leases_)
        if (lease.deadline < now || !workers.known(lease.workerId)) expired.push_back(id);
    for (const auto& id : expired) requeue(id);
    return expired.size();
}

void LeaseScheduler::dropJob(Job& job) {
    job.pending.clear();
    for (auto it = leases_.begin(); it != leases_.end();)
        it = it->second.jobId == job.id ? leases_.erase(it) : std::next(it);
}

}  // namespace vrl::server
