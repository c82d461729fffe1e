// JobClient: the client side of vrl.v1.JobService (service info, upload a scene
// bundle once, submit, watch, fetch the EXR, cancel, list, purge), with a
// deadline on every call. Retrying is the caller's (remote_render.cpp).
#pragma once

#include "service/common/rpc_common.h"
#include "vrl/v1/vrl.grpc.pb.h"

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace vrl::client {

// A call the coordinator refused or that failed; the message names the call and the status.
struct JobClientError : std::runtime_error {
    JobClientError(const std::string& message, grpc::StatusCode code) : std::runtime_error(message), code(code) {}
    grpc::StatusCode code;
};

// watch() was interrupted: its `interrupted` predicate turned true.
struct WatchInterrupted : std::runtime_error {
    WatchInterrupted() : std::runtime_error("watch interrupted") {}
};

class JobClient {
public:
    JobClient(const std::string& address, const rpc::TlsOptions& tls, std::string token);

    // Uploads `blob` unless the coordinator holds it already; returns its SHA-256
    // and sets `uploaded` to whether bytes were sent.
    // Versions, limits, connected workers (deadline `timeout`).
    v1::ServiceInfo serviceInfo(std::chrono::milliseconds timeout = std::chrono::seconds(30));
    std::string uploadBundle(const std::string& blob, bool* uploaded = nullptr);
    std::string submit(const v1::JobSpec& spec);
    // Calls onProgress for each update until the job ends; returns the last progress.
    // `interrupted`, if set, is polled every 100 ms from another thread while the
    // watch waits: once it returns true the call is cancelled and watch throws WatchInterrupted.
    v1::JobProgress watch(const std::string& jobId, const std::function<void(const v1::JobProgress&)>& onProgress,
                          const std::function<bool()>& interrupted = {});
    // Writes the finished image to `path` (via a temporary file), verifying every chunk and the whole;
    // with `partial`, the tiles finished so far (FAILED_PRECONDITION if none can be shown yet).
    void fetchImage(const std::string& jobId, const std::filesystem::path& path, bool partial = false);
    v1::JobState cancel(const std::string& jobId);
    std::vector<v1::JobProgress> list();
    // Purges the finished jobs that ended at least `olderThan` ago (0: all finished ones).
    v1::PurgeJobsReply purge(std::chrono::milliseconds olderThan);

private:
    std::shared_ptr<grpc::Channel> channel_;
    std::unique_ptr<v1::JobService::Stub> stub_;
    std::string token_;
};

// The scene file and every file it references (includes, meshes), found by
// parsing it with `defines`, as a bundle blob; `files`, if given, receives the
// referenced files (not the scene itself). Throws SceneError or BundleError.
std::string collectSceneBundle(const std::filesystem::path& scene, const std::map<std::string, std::string>& defines,
                               std::vector<std::filesystem::path>* files = nullptr);

}  // namespace vrl::client
