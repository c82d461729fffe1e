// worker/: the worker program: leases tiles from a coordinator and shades them.
//
// Worker: registers with a coordinator, leases tiles, downloads and verifies
// each job's assets once (cached by hash; several jobs at once, no process-wide
// state), builds the job's Embree scene and shades tiles with the same
// TileShader as an embedded render, so its pixels are bit-identical. One lease
// loop per thread keeps every thread busy while others talk to the coordinator.
#pragma once

#include "service/common/health_service.h"
#include "service/common/limits.h"
#include "service/common/rpc_common.h"
#include "worker/asset_fetcher.h"

#include <atomic>
#include <condition_variable>
#include <filesystem>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace vrl::worker {

struct WorkerOptions {
    std::string coordinator = "localhost:50051";
    rpc::TlsOptions tls;
    std::string token;
    int threads = 0;                    // 0: all cores
    std::string name;                   // shown in job progress; default: host name and pid
    std::filesystem::path cacheDir;     // extracted bundles; empty: a temporary folder removed at exit
    size_t maxCachedJobs = 4;           // jobs whose scene and lights stay loaded
    std::string healthListen;           // serve grpc.health.v1 here (e.g. 0.0.0.0:50052); empty: no
    rpc::ServiceLimits limits;
    // What the handshake announces (tests set other values to check refusal).
    uint32_t protocolVersion = rpc::kProtocolVersion;
    std::string programVersion = VRL_VERSION;
};

// The coordinator refused this worker (version, token, certificate): retrying cannot help.
struct WorkerRefused : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct WorkerStatistics {
    uint64_t tilesSubmitted = 0, tilesAccepted = 0, jobsLoaded = 0;
    FetchStatistics assets;
};

class Worker {
public:
    explicit Worker(WorkerOptions options);
    ~Worker();
    Worker(const Worker&) = delete;
    Worker& operator=(const Worker&) = delete;

    // Serves until stop() or kill(). Throws WorkerRefused, or std::runtime_error
    // when the coordinator stays unreachable at start.
    void run();
    // Graceful: tiles being shaded are finished and returned, nothing new is leased.
    void stop();
    // Dies at once (for tests of worker failure): no more heartbeats, results
    // or releases; the coordinator must notice by itself.
    void kill();
    WorkerStatistics statistics() const;
    const std::string& workerId() const { return workerId_; }

private:
    struct JobContext;
    void registerWorker();
    void heartbeatLoop();
    void leaseLoop();
    std::shared_ptr<const JobContext> loadJob(const std::string& jobId, const std::string& assetsBytes);
    bool sleepUnlessStopping(std::chrono::milliseconds duration);

    WorkerOptions options_;
    std::shared_ptr<grpc::Channel> channel_;
    std::unique_ptr<AssetFetcher> fetcher_;
    rpc::HealthService health_;  // SERVING while registered, NOT_SERVING while starting or draining
    std::unique_ptr<grpc::Server> healthServer_;
    std::filesystem::path cacheDir_;
    bool ownsCacheDir_ = false;
    std::string workerId_;
    std::atomic<int64_t> heartbeatIntervalMs_{2000};
    std::atomic<bool> stopping_{false}, killed_{false}, reregister_{false};
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::map<std::string, std::shared_future<std::shared_ptr<const JobContext>>> jobs_;
    std::vector<std::string> jobOrder_;  // oldest first, for eviction
    std::mutex registerMutex_;
    WorkerStatistics statistics_;
};

}  // namespace vrl::worker
