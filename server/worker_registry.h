// WorkerRegistry: the workers the coordinator knows. A worker registers once
// (same protocol and program version as the coordinator, 1..4096 threads) and
// gets an id ("w<n>-<6 hex>"); each heartbeat or lease request proves it alive;
// one silent for longer than heartbeatTimeout is forgotten (its leases then go
// back to the queue: lease_scheduler.h) and must register again.
//
// Not thread-safe by itself: the Coordinator calls it with its mutex held
// (checkRegistration and requireWorkerId use nothing but their arguments).
#pragma once

#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <cstdint>
#include <map>
#include <string>

namespace vrl::server {

// Refuses (InvalidArgument) an empty worker id.
void requireWorkerId(const std::string& workerId);

class WorkerRegistry {
public:
    using Clock = std::chrono::steady_clock;

    WorkerRegistry(std::chrono::milliseconds heartbeatInterval, std::chrono::milliseconds heartbeatTimeout)
        : heartbeatInterval_(heartbeatInterval), heartbeatTimeout_(heartbeatTimeout) {}

    // Refuses (FailedPrecondition) another protocol or program version, naming both, and
    // (InvalidArgument) a thread count outside 1..4096.
    static void checkRegistration(const v1::RegisterRequest& request);
    // Registers a checked request; the reply carries the new id and the heartbeat interval.
    v1::RegisterReply add(const v1::RegisterRequest& request);

    bool known(const std::string& workerId) const { return workers_.count(workerId) != 0; }
    size_t count() const { return workers_.size(); }  // registered and not (yet) forgotten
    // FailedPrecondition for a worker not (or no longer) registered: it must register again.
    void requireKnown(const std::string& workerId) const;
    // Notes that the worker is alive; false if it is not registered.
    bool beat(const std::string& workerId);
    // The name the worker registered with (its id if it gave none, or if it is gone).
    std::string nameOf(const std::string& workerId) const;
    // Forgets the workers silent since before now - heartbeatTimeout, with a warning each.
    void forgetSilent(Clock::time_point now);

private:
    struct WorkerRecord {
        std::string name;
        uint32_t threads = 0;
        Clock::time_point lastHeartbeat;
    };

    std::chrono::milliseconds heartbeatInterval_, heartbeatTimeout_;
    std::map<std::string, WorkerRecord> workers_;
    uint64_t nextWorker_ = 0;
};

}  // namespace vrl::server
