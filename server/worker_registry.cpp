#include "server/worker_registry.h"

#include "service/common/rpc_common.h"
#include "service/common/service_error.h"
#include "util/random_id.h"
#include "util/strings.h"

#include <spdlog/spdlog.h>

namespace vrl::server {

using rpc::ErrorKind;
using rpc::ServiceError;

void requireWorkerId(const std::string& workerId) {
    if (workerId.empty())
        throw ServiceError(ErrorKind::InvalidArgument, "worker_id is required (the id Register returned)");
}

void WorkerRegistry::checkRegistration(const v1::RegisterRequest& request) {
    if (request.protocol_version() != rpc::kProtocolVersion || request.program_version() != VRL_VERSION)
        throw ServiceError(ErrorKind::FailedPrecondition,
                           "version mismatch: the worker runs vrlcuts " + util::abbreviate(request.program_version()) +
                               " (protocol " + std::to_string(request.protocol_version()) +
                               ") but this coordinator runs vrlcuts " + VRL_VERSION + " (protocol " +
                               std::to_string(rpc::kProtocolVersion) + "); run workers of the coordinator's release");
    if (request.threads() == 0 || request.threads() > 4096)
        throw ServiceError(ErrorKind::InvalidArgument, "a worker must announce 1..4096 threads");
}

v1::RegisterReply WorkerRegistry::add(const v1::RegisterRequest& request) {
    const std::string id = "w" + std::to_string(++nextWorker_) + "-" + util::randomHex(6);
    WorkerRecord& worker = workers_[id];
    worker.name = request.name().empty() ? id : request.name().substr(0, 128);
    worker.threads = request.threads();
    worker.lastHeartbeat = Clock::now();
    spdlog::info("worker {} ('{}', {} threads) registered", id, worker.name, worker.threads);
    v1::RegisterReply reply;
    reply.set_worker_id(id);
    reply.set_heartbeat_interval_ms(uint32_t(heartbeatInterval_.count()));
    reply.set_coordinator_version(VRL_VERSION);
    return reply;
}

void WorkerRegistry::requireKnown(const std::string& workerId) const {
    if (!known(workerId))
        throw ServiceError(ErrorKind::FailedPrecondition,
                           "unknown worker '" + util::abbreviate(workerId) + "'; register again");
}

bool WorkerRegistry::beat(const std::string& workerId) {
    const auto it = workers_.find(workerId);
    if (it == workers_.end()) return false;
    it->second.lastHeartbeat = Clock::now();
    return true;
}

std::string WorkerRegistry::nameOf(const std::string& workerId) const {
    const auto it = workers_.find(workerId);
    return it != workers_.end() ? it->second.name : workerId;
}

void WorkerRegistry::forgetSilent(Clock::time_point now) {
    for (auto it = workers_.begin(); it != workers_.end();) {
        if (now - it->second.lastHeartbeat > heartbeatTimeout_) {
            spdlog::warn("worker {} ('{}') missed its heartbeats; its leases go back to the queue", it->first,
                         it->second.name);
            it = workers_.erase(it);
        } else {
            ++it;
        }
    }
}

}  // namespace vrl::server
