// JobClient: the client side of vrl.v1.JobService (upload a scene bundle once,
// submit, watch, fetch the EXR, cancel, list), with a deadline on every call.
#pragma once

#include "service/common/rpc_common.h"
#include "vrl/v1/vrl.grpc.pb.h"

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

class JobClient {
public:
    JobClient(const std::string& address, const rpc::TlsOptions& tls, std::string token);

    // Uploads `blob` unless the coordinator holds it already; returns its SHA-256
    // and sets `uploaded` to whether bytes were sent.
    std::string uploadBundle(const std::string& blob, bool* uploaded = nullptr);
    std::string submit(const v1::JobSpec& spec);
    // Calls onProgress for each update until the job ends; returns the last progress.
    v1::JobProgress watch(const std::string& jobId, const std::function<void(const v1::JobProgress&)>& onProgress);
    // Writes the finished image to `path` (via a temporary file), verifying every chunk and the whole.
    void fetchImage(const std::string& jobId, const std::filesystem::path& path);
    v1::JobState cancel(const std::string& jobId);
    std::vector<v1::JobProgress> list();

private:
    std::shared_ptr<grpc::Channel> channel_;
    std::unique_ptr<v1::JobService::Stub> stub_;
    std::string token_;
};

// The scene file and every file it references (includes, meshes), found by
// parsing it with `defines`, as a bundle blob. Throws SceneError or BundleError.
std::string collectSceneBundle(const std::filesystem::path& scene, const std::map<std::string, std::string>& defines);

}  // namespace vrl::client
