// Hostile input to the coordinator's gRPC API: every call of JobService and
// WorkerGateway with missing fields, wrong sizes and absurd values, sent over
// loopback to an in-process coordinator. Each must be answered with the right
// status code and a short message naming the problem (every call has a 10 s
// deadline, so a stall shows as DEADLINE_EXCEEDED, never as a hang), and none
// may disturb the coordinator or other jobs: valid jobs submitted alongside the
// barrage still finish with an image.
#include "client/job_client.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "render/image/exr_io.h"
#include "server/coordinator_service.h"
#include "service/common/rpc_common.h"
#include "service/job/job_scene.h"
#include "tests/support/temp_dir.h"
#include "util/hash.h"
#include "vrl/v1/vrl.grpc.pb.h"
#include "worker/worker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <future>
#include <iostream>
#include <limits>
#include <optional>
#include <random>
#include <thread>

namespace vrl {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using client::JobClient;
using client::JobClientError;
using client::collectSceneBundle;
using grpc::StatusCode;

const fs::path kScene = fs::path(VRL_TEST_DATA_DIR) / ".." / "scenes" / "smoke-room.xml";
constexpr const char* kToken = "malformed-requests-token";
constexpr auto kDeadline = 10s;        // every call: a stalled coordinator fails the test instead of hanging it
constexpr size_t kMaxMessage = 1024;   // a refusal's message stays short whatever the request held
constexpr const char* kHostileName = "malformed";  // the name of every spec that must be refused

using test::freshDirectory;

void prepare(grpc::ClientContext& context) { rpc::prepareContext(context, kToken, kDeadline); }

// The status must have `code` and a short message containing `fragment`.
void expectStatus(const grpc::Status& status, StatusCode code, const std::string& fragment, const std::string& what) {
    EXPECT_EQ(status.error_code(), code) << what << ": got " << rpc::describe(status).substr(0, 300);
    EXPECT_NE(status.error_message().find(fragment), std::string::npos)
        << what << ": the message does not name '" << fragment << "': " << status.error_message().substr(0, 300);
    EXPECT_LE(status.error_message().size(), kMaxMessage) << what << ": the message echoes the request";
}

v1::JobSpec makeSpec(const std::string& method, int spp, int width, int height, uint32_t tile) {
    v1::JobSpec spec;
    auto& p = *spec.mutable_parameters();
    p = rpc::defaultRenderParameters(parseRenderMethod(method));
    p.set_samples_per_pixel(spp);
    p.set_seed(1);
    p.set_width(uint32_t(width));
    p.set_height(uint32_t(height));
    p.set_vrl_count(2000);
    spec.set_tile_size(tile);
    spec.set_name("smoke-room.xml");
    return spec;
}

// A coordinator on 127.0.0.1:<free port> holding the default scene's bundle,
// with raw stubs for both services and the health service.
class Harness {
public:
    Harness() : stateDir_(freshDirectory("vrl-malformed-test")) {
        server::CoordinatorOptions options;
        options.stateDir = stateDir_;
        options.leaseTimeout = 20s;  // fake workers hold leases while the cases run
        options.heartbeatInterval = 200ms;
        options.heartbeatTimeout = 20s;
        coordinator_ = std::make_unique<server::Coordinator>(options);
        server::ServerOptions serverOptions;
        serverOptions.listen = "127.0.0.1:0";
        serverOptions.token = kToken;
        server_ = std::make_unique<server::CoordinatorServer>(*coordinator_, serverOptions);
        address_ = "127.0.0.1:" + std::to_string(server_->port());
        const auto channel = rpc::makeChannel(address_, {});
        jobs_ = v1::JobService::NewStub(channel);
        gateway_ = v1::WorkerGateway::NewStub(channel);
        health_ = grpc::health::v1::Health::NewStub(channel);
        bundle_ = JobClient(address_, {}, kToken).uploadBundle(collectSceneBundle(kScene, {}));
    }
    ~Harness() {
        for (auto& w : workers_) w.first->stop();
        for (auto& w : workers_) w.second.join();
        server_.reset();
        coordinator_.reset();
        std::error_code error;
        fs::remove_all(stateDir_, error);
    }

    v1::JobService::Stub& jobs() { return *jobs_; }
    v1::WorkerGateway::Stub& gateway() { return *gateway_; }
    server::Coordinator& coordinator() { return *coordinator_; }
    const std::string& bundle() const { return bundle_; }
    const fs::path& stateDir() const { return stateDir_; }

    std::string submit(v1::JobSpec spec) {
        if (spec.bundle_sha256().empty()) spec.set_bundle_sha256(bundle_);
        grpc::ClientContext context;
        prepare(context);
        v1::SubmitJobReply reply;
        const grpc::Status status = jobs_->SubmitJob(&context, spec, &reply);
        EXPECT_TRUE(status.ok()) << rpc::describe(status);
        return reply.job_id();
    }
    std::string registerWorker(const std::string& name) {
        v1::RegisterRequest hello;
        hello.set_protocol_version(rpc::kProtocolVersion);
        hello.set_program_version(VRL_VERSION);
        hello.set_threads(1);
        hello.set_name(name);
        grpc::ClientContext context;
        prepare(context);
        v1::RegisterReply reply;
        const grpc::Status status = gateway_->Register(&context, hello, &reply);
        EXPECT_TRUE(status.ok()) << rpc::describe(status);
        return reply.worker_id();
    }
    void startWorker(const std::string& name) {
        worker::WorkerOptions o;
        o.coordinator = address_;
        o.token = kToken;
        o.threads = 1;
        o.name = name;
        auto worker = std::make_unique<worker::Worker>(o);
        worker::Worker* raw = worker.get();
        workers_.emplace_back(std::move(worker), std::thread([raw] { raw->run(); }));
    }
    // Polls (no blind sleep) until the job's state satisfies `done`; fails after `timeout`.
    v1::JobProgress waitFor(const std::string& id, const std::function<bool(v1::JobState)>& done,
                            std::chrono::milliseconds timeout = 120s) {
        const auto until = std::chrono::steady_clock::now() + timeout;
        while (true) {
            const v1::JobProgress p = coordinator_->jobProgress(id);
            if (done(p.state())) return p;
            if (std::chrono::steady_clock::now() > until) {
                ADD_FAILURE() << id << " stayed " << v1::JobState_Name(p.state()) << ": " << p.message();
                return p;
            }
            std::this_thread::sleep_for(10ms);
        }
    }
    v1::JobProgress waitForEnd(const std::string& id) {
        return waitFor(id, [](v1::JobState s) {
            return s == v1::JOB_STATE_DONE || s == v1::JOB_STATE_FAILED || s == v1::JOB_STATE_CANCELLED;
        });
    }
    // Health SERVING and a listing, each within the deadline.
    void expectServing() {
        grpc::ClientContext context;
        prepare(context);
        grpc::health::v1::HealthCheckResponse reply;
        const grpc::Status status = health_->Check(&context, grpc::health::v1::HealthCheckRequest(), &reply);
        EXPECT_TRUE(status.ok()) << rpc::describe(status);
        EXPECT_EQ(reply.status(), grpc::health::v1::HealthCheckResponse::SERVING);
        EXPECT_TRUE(listJobs().has_value());
    }
    std::optional<std::vector<v1::JobProgress>> listJobs() {
        grpc::ClientContext context;
        prepare(context);
        v1::ListJobsReply reply;
        const grpc::Status status = jobs_->ListJobs(&context, v1::ListJobsRequest(), &reply);
        EXPECT_TRUE(status.ok()) << "ListJobs: " << rpc::describe(status);
        if (!status.ok()) return std::nullopt;
        return std::vector<v1::JobProgress>(reply.jobs().begin(), reply.jobs().end());
    }
    // The finished job's EXR, fetched over gRPC.
    ImageSet fetchImage(const std::string& id) {
        const fs::path file = stateDir_ / ("fetched-" + id + ".exr");
        JobClient(address_, {}, kToken).fetchImage(id, file);
        return readExr(file);
    }

private:
    fs::path stateDir_;
    std::unique_ptr<server::Coordinator> coordinator_;
    std::unique_ptr<server::CoordinatorServer> server_;
    std::string address_, bundle_;
    std::unique_ptr<v1::JobService::Stub> jobs_;
    std::unique_ptr<v1::WorkerGateway::Stub> gateway_;
    std::unique_ptr<grpc::health::v1::Health::Stub> health_;
    std::vector<std::pair<std::unique_ptr<worker::Worker>, std::thread>> workers_;
};

// ------------------------------------------------------------------ SubmitJob

struct SpecCase {
    std::string what;
    std::function<void(v1::JobSpec&)> mutate;
    StatusCode code;
    std::string fragment;
};

void submitJobCases(Harness& h) {
    constexpr float kNan = std::numeric_limits<float>::quiet_NaN(), kInf = std::numeric_limits<float>::infinity();
    constexpr uint32_t kU32 = std::numeric_limits<uint32_t>::max();
    constexpr int32_t kI32 = std::numeric_limits<int32_t>::max();
    using S = v1::JobSpec;
    auto params = [](S& s) -> v1::RenderParameters& { return *s.mutable_parameters(); };
    const std::vector<SpecCase> cases = {
        {"no parameters", [](S& s) { s.clear_parameters(); }, StatusCode::INVALID_ARGUMENT, "no parameters"},
        {"empty spec", [](S& s) { s = S(); s.set_name(kHostileName); }, StatusCode::INVALID_ARGUMENT, "no parameters"},
        // (An empty method is the headline method, not an error.)
        {"blank method", [&](S& s) { params(s).set_method(" "); }, StatusCode::INVALID_ARGUMENT, "unknown method ' '"},
        {"unknown method", [&](S& s) { params(s).set_method("magic"); }, StatusCode::INVALID_ARGUMENT,
         "unknown method 'magic' (valid: path, vrl, vrl-lightcuts, vrl-stochastic, vpl, vpl-lightcuts)"},
        {"100 kB method", [&](S& s) { params(s).set_method(std::string(100000, 'm')); }, StatusCode::INVALID_ARGUMENT,
         "unknown method"},
        {"empty bundle hash", [](S& s) { s.clear_bundle_sha256(); }, StatusCode::INVALID_ARGUMENT,
         "bundle_sha256 is required"},
        {"short bundle hash", [](S& s) { s.set_bundle_sha256("xyz"); }, StatusCode::INVALID_ARGUMENT,
         "bundle_sha256 'xyz' is not a SHA-256"},
        {"uppercase bundle hash",
         [](S& s) {
             std::string upper = s.bundle_sha256();
             std::transform(upper.begin(), upper.end(), upper.begin(), [](char c) { return char(std::toupper(c)); });
             s.set_bundle_sha256(upper + (upper == s.bundle_sha256() ? "0" : ""));
         },
         StatusCode::INVALID_ARGUMENT, "is not a SHA-256"},
        {"100 kB bundle hash", [](S& s) { s.set_bundle_sha256(std::string(100000, 'a')); },
         StatusCode::INVALID_ARGUMENT, "is not a SHA-256"},
        {"unknown bundle", [](S& s) { s.set_bundle_sha256(std::string(64, '0')); }, StatusCode::NOT_FOUND,
         "upload it first"},
        {"resolution 1e9 x 1e9", [&](S& s) { params(s).set_width(1000000000); params(s).set_height(1000000000); },
         StatusCode::INVALID_ARGUMENT, "resolution 1000000000x1000000000 is outside the supported range"},
        {"resolution 2^32-1 squared", [&](S& s) { params(s).set_width(kU32); params(s).set_height(kU32); },
         StatusCode::INVALID_ARGUMENT, "resolution 4294967295x4294967295"},
        {"side over 16384", [&](S& s) { params(s).set_width(16385); params(s).set_height(8); },
         StatusCode::INVALID_ARGUMENT, "resolution 16385x8"},
        {"pixels over the limit", [&](S& s) { params(s).set_width(16384); params(s).set_height(16384); },
         StatusCode::INVALID_ARGUMENT, "pixels"},
        {"width without height", [&](S& s) { params(s).set_height(0); }, StatusCode::INVALID_ARGUMENT,
         "both width and height"},
        {"height without width", [&](S& s) { params(s).set_width(0); }, StatusCode::INVALID_ARGUMENT,
         "both width and height"},
        {"spp 2^31-1", [&](S& s) { params(s).set_samples_per_pixel(kI32); }, StatusCode::INVALID_ARGUMENT,
         "samples per pixel must be in 0...1048576"},
        {"spp -1", [&](S& s) { params(s).set_samples_per_pixel(-1); }, StatusCode::INVALID_ARGUMENT,
         "samples per pixel"},
        {"2^63 VRLs", [&](S& s) { params(s).set_vrl_count(uint64_t(1) << 63); }, StatusCode::INVALID_ARGUMENT,
         "VRLs or light paths"},
        {"2^64-1 light paths", [&](S& s) { params(s).set_light_paths(~uint64_t(0)); }, StatusCode::INVALID_ARGUMENT,
         "VRLs or light paths"},
        {"no VRLs and no light paths",
         [&](S& s) {
             params(s).set_vrl_count(0);
             params(s).set_light_paths(0);
         },
         StatusCode::INVALID_ARGUMENT, "needs a VRL count"},
        {"error NaN", [&](S& s) { params(s).set_error(kNan); }, StatusCode::INVALID_ARGUMENT, "error threshold"},
        {"error +inf", [&](S& s) { params(s).set_error(kInf); }, StatusCode::INVALID_ARGUMENT, "error threshold"},
        {"error -inf", [&](S& s) { params(s).set_error(-kInf); }, StatusCode::INVALID_ARGUMENT, "error threshold"},
        {"error -0.5", [&](S& s) { params(s).set_error(-0.5f); }, StatusCode::INVALID_ARGUMENT, "error threshold"},
        {"error 1e30", [&](S& s) { params(s).set_error(1e30f); }, StatusCode::INVALID_ARGUMENT, "error threshold"},
        {"hg epsilon NaN", [&](S& s) { params(s).set_hg_epsilon(kNan); }, StatusCode::INVALID_ARGUMENT, "hg epsilon"},
        {"hg epsilon -1", [&](S& s) { params(s).set_hg_epsilon(-1.0f); }, StatusCode::INVALID_ARGUMENT, "hg epsilon"},
        {"max depth 2^31-1", [&](S& s) { params(s).set_max_depth(kI32); }, StatusCode::INVALID_ARGUMENT,
         "max depth must be"},
        {"max depth -2^31", [&](S& s) { params(s).set_max_depth(std::numeric_limits<int32_t>::min()); },
         StatusCode::INVALID_ARGUMENT, "max depth must be"},
        {"max depth 0", [&](S& s) { params(s).set_max_depth(0); }, StatusCode::INVALID_ARGUMENT, "max depth must be"},
        {"VRL samples 0", [&](S& s) { params(s).set_vrl_samples(0); }, StatusCode::INVALID_ARGUMENT, "VRL samples"},
        {"VRL samples 2^31-1", [&](S& s) { params(s).set_vrl_samples(kI32); }, StatusCode::INVALID_ARGUMENT,
         "VRL samples"},
        {"max cut 0", [&](S& s) { params(s).set_max_cut(0); }, StatusCode::INVALID_ARGUMENT, "maximum cut size"},
        {"max cut 2^32-1", [&](S& s) { params(s).set_max_cut(kU32); }, StatusCode::INVALID_ARGUMENT,
         "maximum cut size"},
        {"exact distance 2^32-1", [&](S& s) { params(s).set_exact_distance_below(kU32); },
         StatusCode::INVALID_ARGUMENT, "exact distance below"},
        {"partition size 0", [&](S& s) { params(s).set_partition_size(0); }, StatusCode::INVALID_ARGUMENT,
         "partition size"},
        {"partition size 1", [&](S& s) { params(s).set_partition_size(1); }, StatusCode::INVALID_ARGUMENT,
         "partition size"},
        {"partition size 2^32-1", [&](S& s) { params(s).set_partition_size(kU32); }, StatusCode::INVALID_ARGUMENT,
         "partition size"},
        {"VPL distance samples 2^32-1", [&](S& s) { params(s).set_vpl_distance_samples(kU32); },
         StatusCode::INVALID_ARGUMENT, "VPL distance samples per camera segment must be in 1...4096"},
        {"tile size 2^32-1", [](S& s) { s.set_tile_size(kU32); }, StatusCode::INVALID_ARGUMENT,
         "tile size 4294967295 exceeds the limit of 256"},
        {"tile size 257", [](S& s) { s.set_tile_size(257); }, StatusCode::INVALID_ARGUMENT, "tile size 257"},
        {"a million tiles and more",
         [&](S& s) {
             s.set_tile_size(1);
             params(s).set_width(8192);
             params(s).set_height(8192);
         },
         StatusCode::INVALID_ARGUMENT, "tiles, over the limit"},
        {"define with an empty name", [](S& s) { (*s.mutable_defines())[""] = "1"; }, StatusCode::INVALID_ARGUMENT,
         "invalid define"},
        {"define with a 10 kB name", [](S& s) { (*s.mutable_defines())[std::string(10000, 'n')] = "1"; },
         StatusCode::INVALID_ARGUMENT, "invalid define"},
        {"define with a 100 kB value", [](S& s) { (*s.mutable_defines())["spp"] = std::string(100000, '9'); },
         StatusCode::INVALID_ARGUMENT, "values at most 4096"},
        {"2000 defines",
         [](S& s) {
             for (int i = 0; i < 2000; ++i) (*s.mutable_defines())[std::to_string(i) + "d"] = std::string(1, '1');
         },
         StatusCode::INVALID_ARGUMENT, "2000 defines, over the limit"},
        {"400 kB of defines",
         [](S& s) {
             for (int i = 0; i < 100; ++i) (*s.mutable_defines())[std::to_string(i) + "d"] = std::string(4000, 'v');
         },
         StatusCode::INVALID_ARGUMENT, "the job spec is"},
        {"5 kB name", [](S& s) { s.set_name(kHostileName + std::string(5000, 'x')); }, StatusCode::INVALID_ARGUMENT,
         "the job name is"},
        {"1 MiB name", [](S& s) { s.set_name(kHostileName + std::string(1 << 20, 'x')); },
         StatusCode::INVALID_ARGUMENT, "the job spec is"},
        {"unparsable medium", [](S& s) { s.set_medium("sigmaS=abc"); }, StatusCode::INVALID_ARGUMENT, "medium"},
        {"2 kB medium", [](S& s) { s.set_medium(std::string(2000, 's')); }, StatusCode::INVALID_ARGUMENT,
         "fill medium description is longer than 1024"},
        {"unknown transport part", [&](S& s) { params(s).set_transport("surface,bogus"); },
         StatusCode::INVALID_ARGUMENT, "bogus"},
        {"1 kB transport", [&](S& s) { params(s).set_transport(std::string(1000, 't')); },
         StatusCode::INVALID_ARGUMENT, "the transport list is"},
    };
    for (const std::string method : {"vrl-lightcuts", "vpl-lightcuts"}) {
        for (const auto& c : cases) {
            v1::JobSpec spec = makeSpec(method, 1, 16, 12, 8);
            spec.set_bundle_sha256(h.bundle());
            spec.set_name(kHostileName);
            c.mutate(spec);
            grpc::ClientContext context;
            prepare(context);
            v1::SubmitJobReply reply;
            expectStatus(h.jobs().SubmitJob(&context, spec, &reply), c.code, c.fragment, method + ": " + c.what);
            EXPECT_TRUE(reply.job_id().empty()) << c.what;
        }
    }
    // None of them became a job.
    if (const auto jobs = h.listJobs()) {
        for (const auto& job : *jobs) EXPECT_NE(job.name().substr(0, 9), kHostileName) << job.job_id();
    }
}

// ------------------------------------------------------------------ job references and bundles

// A job id for every call of JobService that takes one; `notDone`: a job without an image yet (or empty).
void jobRefCases(Harness& h, const std::string& notDone) {
    struct Case {
        std::string id;
        StatusCode code;
        std::string fragment;
    };
    std::vector<Case> cases = {{"", StatusCode::INVALID_ARGUMENT, "job_id is required"},
                               {"job-000000000000", StatusCode::NOT_FOUND, "no job 'job-000000000000'"},
                               {std::string(100000, 'j'), StatusCode::NOT_FOUND, "no job"},
                               {std::string("job-\0\x01", 6), StatusCode::NOT_FOUND, "no job"}};
    for (const auto& c : cases) {
        v1::JobRef ref;
        ref.set_job_id(c.id);
        const std::string what = "id of " + std::to_string(c.id.size()) + " bytes";
        {
            grpc::ClientContext context;
            prepare(context);
            auto reader = h.jobs().WatchJob(&context, ref);
            v1::JobProgress progress;
            EXPECT_FALSE(reader->Read(&progress)) << "WatchJob " << what;
            expectStatus(reader->Finish(), c.code, c.fragment, "WatchJob " + what);
        }
        {
            grpc::ClientContext context;
            prepare(context);
            auto reader = h.jobs().FetchImage(&context, ref);
            v1::DataChunk chunk;
            EXPECT_FALSE(reader->Read(&chunk)) << "FetchImage " << what;
            expectStatus(reader->Finish(), c.code, c.fragment, "FetchImage " + what);
        }
        {
            grpc::ClientContext context;
            prepare(context);
            v1::CancelJobReply reply;
            expectStatus(h.jobs().CancelJob(&context, ref, &reply), c.code, c.fragment, "CancelJob " + what);
        }
    }
    {
        // Invalid UTF-8 in a string field: gRPC's parser refuses the request before the coordinator sees it.
        v1::JobRef ref;
        ref.set_job_id(std::string("job-\xff\xfe", 6));
        grpc::ClientContext context;
        prepare(context);
        v1::CancelJobReply reply;
        const grpc::Status status = h.jobs().CancelJob(&context, ref, &reply);
        EXPECT_FALSE(status.ok());
        EXPECT_NE(status.error_code(), StatusCode::DEADLINE_EXCEEDED) << rpc::describe(status);
    }
    if (!notDone.empty()) {
        v1::JobRef ref;
        ref.set_job_id(notDone);
        grpc::ClientContext context;
        prepare(context);
        auto reader = h.jobs().FetchImage(&context, ref);
        v1::DataChunk chunk;
        EXPECT_FALSE(reader->Read(&chunk));
        expectStatus(reader->Finish(), StatusCode::FAILED_PRECONDITION, "has no image yet", "FetchImage of a job not done");
    }
    // HasBundle: a malformed hash is refused, a well-formed unknown one is simply absent.
    for (const auto& [hash, fragment] : std::vector<std::pair<std::string, std::string>>{
             {"", "sha256 is required"}, {"xyz", "'xyz' is not a SHA-256"}, {std::string(100000, 'f'), "is not a SHA-256"},
             {std::string(63, 'a') + "G", "is not a SHA-256"}}) {
        v1::BundleRef ref;
        ref.set_sha256(hash);
        grpc::ClientContext context;
        prepare(context);
        v1::HasBundleReply reply;
        expectStatus(h.jobs().HasBundle(&context, ref, &reply), StatusCode::INVALID_ARGUMENT, fragment,
                     "HasBundle of " + std::to_string(hash.size()) + " bytes");
    }
    v1::BundleRef unknown;
    unknown.set_sha256(std::string(64, 'e'));
    grpc::ClientContext context;
    prepare(context);
    v1::HasBundleReply reply;
    EXPECT_TRUE(h.jobs().HasBundle(&context, unknown, &reply).ok());
    EXPECT_FALSE(reply.present());
}

v1::BundleChunk chunkOf(const std::string& sha256, uint64_t total, uint64_t offset, const std::string& data) {
    v1::BundleChunk chunk;
    chunk.set_sha256(sha256);
    chunk.set_total_size(total);
    chunk.set_offset(offset);
    chunk.set_data(data);
    chunk.set_crc32(util::crc32Of(data));
    return chunk;
}

grpc::Status upload(Harness& h, const std::vector<v1::BundleChunk>& chunks) {
    grpc::ClientContext context;
    prepare(context);
    v1::UploadBundleReply reply;
    auto writer = h.jobs().UploadBundle(&context, &reply);
    for (const auto& chunk : chunks)
        if (!writer->Write(chunk)) break;  // the coordinator refused already
    writer->WritesDone();
    return writer->Finish();
}

std::string blobOf(const v1::SceneBundle& bundle) {
    std::string blob;
    bundle.SerializeToString(&blob);
    return blob;
}

void uploadCases(Harness& h) {
    const std::string scene = "<scene version=\"0.5.0\"><sensor type=\"perspective\"/></scene>";
    v1::SceneBundle good;
    good.set_scene_path("scene.xml");
    good.add_entries()->set_path("scene.xml");
    good.mutable_entries(0)->set_data(scene);
    const std::string blob = blobOf(good), sha = util::sha256Hex(blob);
    const std::string garbage = "\xff\xff\xff\xff\xff";
    v1::SceneBundle missingScene = good;
    missingScene.set_scene_path("missing.xml");
    v1::SceneBundle giantScenePath = good;
    giantScenePath.set_scene_path(std::string(100000, 'p'));
    const std::string empty = blobOf(v1::SceneBundle());
    v1::BundleChunk badCrc = chunkOf(sha, blob.size(), 0, blob);
    badCrc.set_crc32(badCrc.crc32() ^ 1);
    struct Case {
        std::string what;
        std::vector<v1::BundleChunk> chunks;
        StatusCode code;
        std::string fragment;
    };
    const std::vector<Case> cases = {
        {"no chunk at all", {}, StatusCode::INVALID_ARGUMENT, "empty upload"},
        {"no hash", {chunkOf("", blob.size(), 0, blob)}, StatusCode::INVALID_ARGUMENT, "sha256 is required"},
        {"malformed hash", {chunkOf("abc", blob.size(), 0, blob)}, StatusCode::INVALID_ARGUMENT, "is not a SHA-256"},
        {"100 kB hash", {chunkOf(std::string(100000, 'a'), blob.size(), 0, blob)}, StatusCode::INVALID_ARGUMENT,
         "is not a SHA-256"},
        {"hash of other bytes", {chunkOf(std::string(64, 'a'), blob.size(), 0, blob)}, StatusCode::INVALID_ARGUMENT,
         "SHA-256 is " + sha},
        {"announced 2^63 bytes", {chunkOf(sha, uint64_t(1) << 63, 0, blob)}, StatusCode::RESOURCE_EXHAUSTED,
         "exceeds the limit"},
        {"announced 0 bytes", {chunkOf(sha, 0, 0, blob)}, StatusCode::INVALID_ARGUMENT,
         "longer than its announced size"},
        {"shorter than announced", {chunkOf(sha, blob.size() + 10, 0, blob)}, StatusCode::DATA_LOSS, "stopped at"},
        {"a gap", {chunkOf(sha, blob.size(), 5, blob)}, StatusCode::DATA_LOSS, "expected 0"},
        {"an overlap",
         {chunkOf(sha, blob.size(), 0, blob.substr(0, 10)), chunkOf(sha, blob.size(), 3, blob.substr(3))},
         StatusCode::DATA_LOSS, "expected 10"},
        {"a wrong CRC-32", {badCrc}, StatusCode::DATA_LOSS, "CRC-32"},
        {"not a SceneBundle", {chunkOf(util::sha256Hex(garbage), garbage.size(), 0, garbage)},
         StatusCode::INVALID_ARGUMENT, "not a valid vrl.v1.SceneBundle"},
        {"an empty bundle", {chunkOf(util::sha256Hex(empty), empty.size(), 0, empty)}, StatusCode::INVALID_ARGUMENT,
         "is not among its entries"},
        {"scene file missing", {chunkOf(util::sha256Hex(blobOf(missingScene)), blobOf(missingScene).size(), 0,
                                        blobOf(missingScene))},
         StatusCode::INVALID_ARGUMENT, "'missing.xml' is not among its entries"},
        {"100 kB scene path", {chunkOf(util::sha256Hex(blobOf(giantScenePath)), blobOf(giantScenePath).size(), 0,
                                       blobOf(giantScenePath))},
         StatusCode::INVALID_ARGUMENT, "is not among its entries"},
    };
    for (const auto& c : cases) expectStatus(upload(h, c.chunks), c.code, c.fragment, "UploadBundle: " + c.what);

    // An upload that stops sending (but stays open) holds up nothing else; cancelling it ends it.
    grpc::ClientContext context;
    prepare(context);
    v1::UploadBundleReply reply;
    auto writer = h.jobs().UploadBundle(&context, &reply);
    EXPECT_TRUE(writer->Write(chunkOf(sha, blob.size(), 0, blob.substr(0, 10))));
    EXPECT_TRUE(h.listJobs().has_value()) << "a stalled upload blocks the coordinator";
    context.TryCancel();
    EXPECT_EQ(writer->Finish().error_code(), StatusCode::CANCELLED);
}

// ------------------------------------------------------------------ worker calls

// Register, Heartbeat, LeaseTiles, FetchAsset, ReleaseLeases; `liveAsset`: the
// hash of an asset a rendering job uses (or empty).
void workerCases(Harness& h, const std::string& liveAsset) {
    auto registerWith = [&](uint32_t protocol, const std::string& program, uint32_t threads, const std::string& name) {
        v1::RegisterRequest hello;
        hello.set_protocol_version(protocol);
        hello.set_program_version(program);
        hello.set_threads(threads);
        hello.set_name(name);
        grpc::ClientContext context;
        prepare(context);
        v1::RegisterReply reply;
        return h.gateway().Register(&context, hello, &reply);
    };
    const uint32_t current = rpc::kProtocolVersion;
    expectStatus(registerWith(0, VRL_VERSION, 1, "w"), StatusCode::FAILED_PRECONDITION, "(protocol 0)",
                 "Register without a protocol version");
    expectStatus(registerWith(99, VRL_VERSION, 1, "w"), StatusCode::FAILED_PRECONDITION,
                 "(protocol " + std::to_string(current) + ")", "Register with protocol 99");
    expectStatus(registerWith(~0u, VRL_VERSION, 1, "w"), StatusCode::FAILED_PRECONDITION, "protocol 4294967295",
                 "Register with protocol 2^32-1");
    expectStatus(registerWith(current, "", 1, "w"), StatusCode::FAILED_PRECONDITION, "version mismatch",
                 "Register without a program version");
    expectStatus(registerWith(current, std::string(100000, 'v'), 1, "w"), StatusCode::FAILED_PRECONDITION,
                 "version mismatch", "Register with a 100 kB program version");
    expectStatus(registerWith(current, VRL_VERSION, 0, "w"), StatusCode::INVALID_ARGUMENT, "1..4096 threads",
                 "Register with 0 threads");
    expectStatus(registerWith(current, VRL_VERSION, ~0u, "w"), StatusCode::INVALID_ARGUMENT, "1..4096 threads",
                 "Register with 2^32-1 threads");
    EXPECT_TRUE(registerWith(current, VRL_VERSION, 1, std::string(100000, 'n')).ok()) << "a long name is cut, not refused";

    // Heartbeat: no id is refused; an unknown one is told to register again.
    {
        v1::HeartbeatRequest beat;
        grpc::ClientContext context;
        prepare(context);
        v1::HeartbeatReply reply;
        expectStatus(h.gateway().Heartbeat(&context, beat, &reply), StatusCode::INVALID_ARGUMENT, "worker_id is required",
                     "Heartbeat without a worker id");
    }
    {
        v1::HeartbeatRequest beat;
        beat.set_worker_id(std::string(100000, 'w'));
        grpc::ClientContext context;
        prepare(context);
        v1::HeartbeatReply reply;
        EXPECT_TRUE(h.gateway().Heartbeat(&context, beat, &reply).ok());
        EXPECT_FALSE(reply.known());
    }
    // LeaseTiles.
    auto lease = [&](const std::string& workerId, uint32_t maxTiles, v1::LeaseReply* reply) {
        v1::LeaseRequest ask;
        ask.set_worker_id(workerId);
        ask.set_max_tiles(maxTiles);
        grpc::ClientContext context;
        prepare(context);
        return h.gateway().LeaseTiles(&context, ask, reply);
    };
    v1::LeaseReply reply;
    expectStatus(lease("", 1, &reply), StatusCode::INVALID_ARGUMENT, "worker_id is required", "LeaseTiles without a worker id");
    expectStatus(lease("w999-000000", 1, &reply), StatusCode::FAILED_PRECONDITION, "register again",
                 "LeaseTiles of an unknown worker");
    expectStatus(lease(std::string(100000, 'w'), 1, &reply), StatusCode::FAILED_PRECONDITION, "register again",
                 "LeaseTiles of a 100 kB worker id");
    // Out-of-range tile counts are clamped (1..64); whatever is leased goes straight back.
    const std::string workerId = h.registerWorker("clamped");
    auto giveBack = [&](const v1::LeaseReply& leased) {
        v1::ReleaseRequest release;
        release.set_worker_id(workerId);
        for (const auto& l : leased.leases()) release.add_lease_ids(l.lease_id());
        grpc::ClientContext context;
        prepare(context);
        v1::ReleaseReply released;
        EXPECT_TRUE(h.gateway().ReleaseLeases(&context, release, &released).ok());
    };
    for (const uint32_t maxTiles : {0u, ~0u}) {
        v1::LeaseReply leased;
        EXPECT_TRUE(lease(workerId, maxTiles, &leased).ok()) << "max_tiles " << maxTiles;
        EXPECT_LE(leased.leases_size(), maxTiles == 0 ? 1 : 64) << "max_tiles " << maxTiles;
        giveBack(leased);
    }
    // ReleaseLeases: no id is refused; unknown leases and leases of other workers are ignored.
    {
        v1::ReleaseRequest release;
        release.add_lease_ids("x");
        grpc::ClientContext context;
        prepare(context);
        v1::ReleaseReply released;
        expectStatus(h.gateway().ReleaseLeases(&context, release, &released), StatusCode::INVALID_ARGUMENT,
                     "worker_id is required", "ReleaseLeases without a worker id");
    }
    {
        v1::ReleaseRequest release;
        release.set_worker_id(workerId);
        release.add_lease_ids("no-such-lease");
        release.add_lease_ids(std::string(100000, 'l'));
        release.set_failure(std::string(100000, 'f'));
        grpc::ClientContext context;
        prepare(context);
        v1::ReleaseReply released;
        EXPECT_TRUE(h.gateway().ReleaseLeases(&context, release, &released).ok());
    }
    // FetchAsset.
    auto fetch = [&](const std::string& sha256, uint64_t offset) {
        v1::FetchAssetRequest request;
        request.set_sha256(sha256);
        request.set_offset(offset);
        grpc::ClientContext context;
        prepare(context);
        auto reader = h.gateway().FetchAsset(&context, request);
        v1::DataChunk chunk;
        while (reader->Read(&chunk)) {
        }
        return reader->Finish();
    };
    expectStatus(fetch("", 0), StatusCode::INVALID_ARGUMENT, "sha256 is required", "FetchAsset without a hash");
    expectStatus(fetch("../../etc/passwd", 0), StatusCode::INVALID_ARGUMENT, "is not a SHA-256", "FetchAsset of a path");
    expectStatus(fetch(std::string(100000, 'a'), 0), StatusCode::INVALID_ARGUMENT, "is not a SHA-256",
                 "FetchAsset of a 100 kB hash");
    expectStatus(fetch(std::string(64, '0'), 0), StatusCode::NOT_FOUND, "no live job uses asset",
                 "FetchAsset of an unknown asset");
    if (!liveAsset.empty()) {
        expectStatus(fetch(liveAsset, ~uint64_t(0)), StatusCode::OUT_OF_RANGE, "offset beyond the end",
                     "FetchAsset from offset 2^64-1");
        EXPECT_TRUE(fetch(liveAsset, 0).ok());
    }
}

// ------------------------------------------------------------------ tile results

// `count` leases of `jobId`'s tiles for `workerId` (the job must have the highest priority).
std::vector<v1::TileLease> leaseTiles(Harness& h, const std::string& workerId, const std::string& jobId, int count) {
    v1::LeaseRequest ask;
    ask.set_worker_id(workerId);
    ask.set_max_tiles(uint32_t(count));
    grpc::ClientContext context;
    prepare(context);
    v1::LeaseReply reply;
    const grpc::Status status = h.gateway().LeaseTiles(&context, ask, &reply);
    EXPECT_TRUE(status.ok()) << rpc::describe(status);
    std::vector<v1::TileLease> leases(reply.leases().begin(), reply.leases().end());
    EXPECT_EQ(int(leases.size()), count);
    for (const auto& l : leases) EXPECT_EQ(l.job_id(), jobId);
    return leases;
}

// Every kind of malformed TileResult for a `path` job (one layer) whose tiles
// `leases` hold (at least 20; each refused result sends its tile back to the
// queue once, far from the job's rejection limit). Unused leases are given back.
void tileResultCases(Harness& h, const std::string& workerId, const std::vector<v1::TileLease>& leases) {
    ASSERT_GE(leases.size(), 20u);
    size_t next = 0;
    auto resultFor = [&](const v1::TileLease& lease) {
        v1::TileResult result;
        result.set_worker_id(workerId);
        result.set_lease_id(lease.lease_id());
        result.set_job_id(lease.job_id());
        *result.mutable_tile() = lease.tile();
        result.set_first_pass(lease.first_pass());  // the lease's sample passes
        result.set_pass_count(lease.pass_count());
        const auto& t = lease.tile();
        const std::vector<float> pixels(size_t(t.x1() - t.x0()) * (t.y1() - t.y0()) * 3, 0.25f);
        result.add_layers()->set_rgb(pixels.data(), pixels.size() * sizeof(float));
        result.set_seconds(0.01);
        return result;
    };
    auto submit = [&](const v1::TileResult& result, v1::SubmitTileReply* reply) {
        grpc::ClientContext context;
        prepare(context);
        return h.gateway().SubmitTile(&context, result, reply);
    };
    v1::SubmitTileReply reply;
    // Refused before the result is looked at: the lease stays.
    struct Case {
        std::string what;
        std::function<void(v1::TileResult&)> mutate;
        StatusCode code;
        std::string fragment;
    };
    using R = v1::TileResult;
    const std::vector<Case> before = {
        {"no job id", [](R& r) { r.clear_job_id(); }, StatusCode::INVALID_ARGUMENT, "job_id is required"},
        {"unknown job", [](R& r) { r.set_job_id("job-ffffffffffff"); }, StatusCode::NOT_FOUND, "no job 'job-ffffffffffff'"},
        {"100 kB job id", [](R& r) { r.set_job_id(std::string(100000, 'j')); }, StatusCode::NOT_FOUND, "no job"},
        {"no worker id", [](R& r) { r.clear_worker_id(); }, StatusCode::INVALID_ARGUMENT, "worker_id is required"},
        {"unknown worker", [](R& r) { r.set_worker_id("w0-000000"); }, StatusCode::FAILED_PRECONDITION, "register again"},
        {"100 kB worker id", [](R& r) { r.set_worker_id(std::string(100000, 'w')); }, StatusCode::FAILED_PRECONDITION,
         "register again"},
        // Not leased: no lease, a made-up lease, another tile's lease (none of them counts against the tile).
        {"no lease id", [](R& r) { r.clear_lease_id(); }, StatusCode::INVALID_ARGUMENT, "lease_id is required"},
        {"made-up lease", [](R& r) { r.set_lease_id("lease-1"); }, StatusCode::INVALID_ARGUMENT, "was never issued"},
        {"100 kB lease id", [](R& r) { r.set_lease_id(std::string(100000, 'l')); }, StatusCode::INVALID_ARGUMENT,
         "was never issued"},
        {"lease number never issued", [](R& r) { r.set_lease_id(r.lease_id() + "999999999"); },
         StatusCode::INVALID_ARGUMENT, "was never issued"},
        {"lease number over 2^64", [](R& r) { r.set_lease_id(r.lease_id() + std::string(25, '9')); },
         StatusCode::INVALID_ARGUMENT, "was never issued"},
        {"another tile's lease", [&](R& r) { r.set_lease_id(leases[1].lease_id()); }, StatusCode::INVALID_ARGUMENT,
         "was never issued"},
    };
    for (const auto& c : before) {
        R result = resultFor(leases[0]);
        c.mutate(result);
        expectStatus(submit(result, &reply), c.code, c.fragment, "SubmitTile: " + c.what);
    }
    // Refused on their content: each takes a lease, whose tile goes back to the queue.
    const size_t floatBytes = 8 * 8 * 3 * sizeof(float);
    auto setFloat = [](R& r, size_t index, float value) {
        std::string rgb = r.layers(0).rgb();
        std::memcpy(rgb.data() + index * sizeof(float), &value, sizeof value);
        r.mutable_layers(0)->set_rgb(rgb);
    };
    const std::vector<Case> content = {
        {"no layers", [](R& r) { r.clear_layers(); }, StatusCode::INVALID_ARGUMENT, "wrong number of layers: 0, expected 1"},
        {"passes the tile does not need", [](R& r) { r.set_first_pass(r.first_pass() + 1); },
         StatusCode::INVALID_ARGUMENT, "are not what tile"},
        {"no passes", [](R& r) { r.set_pass_count(0); }, StatusCode::INVALID_ARGUMENT, "are not what tile"},
        {"2^32-1 passes", [](R& r) { r.set_pass_count(~0u); }, StatusCode::INVALID_ARGUMENT, "are not what tile"},
        {"an extra layer", [](R& r) { *r.add_layers() = r.layers(0); }, StatusCode::INVALID_ARGUMENT,
         "wrong number of layers: 2, expected 1"},
        {"4 bytes short", [&](R& r) { r.mutable_layers(0)->mutable_rgb()->resize(floatBytes - 4); },
         StatusCode::INVALID_ARGUMENT, "wrong size: " + std::to_string(floatBytes - 4) + " bytes, expected " +
                                           std::to_string(floatBytes)},
        {"12 bytes long", [&](R& r) { r.mutable_layers(0)->mutable_rgb()->resize(floatBytes + 12); },
         StatusCode::INVALID_ARGUMENT, "wrong size"},
        {"no pixels", [](R& r) { r.mutable_layers(0)->clear_rgb(); }, StatusCode::INVALID_ARGUMENT, "wrong size: 0 bytes"},
        {"a NaN", [&](R& r) { setFloat(r, 17, std::numeric_limits<float>::quiet_NaN()); }, StatusCode::INVALID_ARGUMENT,
         "non-finite"},
        {"an infinity", [&](R& r) { setFloat(r, 0, std::numeric_limits<float>::infinity()); },
         StatusCode::INVALID_ARGUMENT, "non-finite"},
        {"a layer named wrongly", [](R& r) { r.mutable_layers(0)->set_name(std::string(100000, 'n')); },
         StatusCode::INVALID_ARGUMENT, "layer 0 is"},
        {"zero-size tile", [](R& r) { r.mutable_tile()->set_x1(r.tile().x0()); }, StatusCode::INVALID_ARGUMENT,
         "differ from the job's tiling"},
        {"inverted tile",
         [](R& r) {
             r.mutable_tile()->set_x1(r.tile().x0() > 0 ? r.tile().x0() - 1 : 0);
             r.mutable_tile()->set_y1(0);
         },
         StatusCode::INVALID_ARGUMENT, "differ from the job's tiling"},
        {"seconds NaN", [](R& r) { r.set_seconds(std::numeric_limits<double>::quiet_NaN()); },
         StatusCode::INVALID_ARGUMENT, "seconds must be finite"},
        {"seconds -1", [](R& r) { r.set_seconds(-1.0); }, StatusCode::INVALID_ARGUMENT, "seconds must be finite"},
        {"tile outside the image",
         [](R& r) {
             r.mutable_tile()->set_x0(1000000000);
             r.mutable_tile()->set_x1(1000000008);
         },
         StatusCode::INVALID_ARGUMENT, "(1000000000, "},
        {"tile at 2^32-1",
         [](R& r) {
             r.mutable_tile()->set_x0(~0u);
             r.mutable_tile()->set_y0(~0u);
         },
         StatusCode::INVALID_ARGUMENT, "is not a tile of this job"},
    };
    next = 1;
    for (const auto& c : content) {
        if (next >= leases.size() - 1) break;
        R result = resultFor(leases[next++]);
        c.mutate(result);
        expectStatus(submit(result, &reply), c.code, c.fragment, "SubmitTile: " + c.what);
    }
    EXPECT_LT(next, leases.size() - 1) << "too few leases for the cases";
    // A good result is taken once; the same again is a duplicate (OK, not taken).
    const R good = resultFor(leases[next++]);
    ASSERT_TRUE(submit(good, &reply).ok());
    EXPECT_TRUE(reply.accepted()) << reply.reason();
    ASSERT_TRUE(submit(good, &reply).ok());
    EXPECT_FALSE(reply.accepted());
    EXPECT_NE(reply.reason().find("duplicate"), std::string::npos) << reply.reason();
    // What was not used goes back.
    v1::ReleaseRequest release;
    release.set_worker_id(workerId);
    for (const auto& l : leases) release.add_lease_ids(l.lease_id());
    grpc::ClientContext context;
    prepare(context);
    v1::ReleaseReply released;
    EXPECT_TRUE(h.gateway().ReleaseLeases(&context, release, &released).ok());
}

// Jobs whose defines break the scene: accepted (the coordinator does not parse
// scenes on submission), then failed at preparation with a message naming the
// problem. Returns (job id, what the message must name).
std::vector<std::pair<std::string, std::string>> submitBrokenScenes(Harness& h) {
    std::vector<std::pair<std::string, std::string>> ids;
    struct Broken {
        std::string name, value, fragment;
    };
    for (const auto& [name, value, fragment] : std::vector<Broken>{
             {"sigmaS", "nan", "<rgb name=\"sigmaS\">: 'value' must be finite"},
             {"width", "100000", "film width must be in [1, 16384], got 100000"},
             {"width", "99999999999999999999999", "cannot parse 'width'"},
             {"spp", "2147483647", "sampleCount must be in [1, 1048576], got 2147483647"},
             {"lightIntensity", std::string(4000, '9'), "<spectrum name=\"intensity\">"}}) {
        v1::JobSpec spec = makeSpec("vrl-lightcuts", 0, 0, 0, 8);
        spec.mutable_parameters()->set_width(0);
        spec.mutable_parameters()->set_height(0);
        (*spec.mutable_defines())[name] = value;
        (*spec.mutable_defines())["width"] = name == "width" ? value : "16";
        (*spec.mutable_defines())["height"] = "12";
        if (name != "spp") (*spec.mutable_defines())["spp"] = "1";
        spec.set_name("broken-" + name);
        ids.emplace_back(h.submit(spec), fragment);
    }
    return ids;
}

void expectImage(Harness& h, const std::string& id, int width, int height) {
    const v1::JobProgress last = h.waitForEnd(id);
    ASSERT_EQ(last.state(), v1::JOB_STATE_DONE) << id << ": " << last.message();
    const ImageSet image = h.fetchImage(id);
    ASSERT_EQ(image.image.width(), width);
    ASSERT_EQ(image.image.height(), height);
    double sum = 0.0;
    for (const Rgb& p : image.image.pixels()) {
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
        sum += p.x + p.y + p.z;
    }
    EXPECT_GT(sum, 0.0) << id << ": a black image";
}

// ------------------------------------------------------------------ the tests

TEST(MalformedRequests, SubmitJobRefusesEveryBadSpecNamingTheProblem) {
    Harness h;
    submitJobCases(h);
    h.expectServing();
}

TEST(MalformedRequests, JobReferencesAndBundleHashesAreChecked) {
    Harness h;
    const std::string waiting = h.submit(makeSpec("path", 1, 16, 12, 8));  // no worker: never done
    jobRefCases(h, waiting);
    h.expectServing();
}

TEST(MalformedRequests, BadUploadsAreRefusedAndAStalledOneBlocksNothing) {
    Harness h;
    uploadCases(h);
    h.expectServing();
}

TEST(MalformedRequests, BadWorkerCallsAreRefusedAndForeignLeasesStay) {
    Harness h;
    const std::string id = h.submit(makeSpec("path", 1, 32, 32, 8));
    h.waitFor(id, [](v1::JobState s) { return s == v1::JOB_STATE_RENDERING; });
    const std::string owner = h.registerWorker("owner");
    const auto held = leaseTiles(h, owner, id, 2);
    workerCases(h, h.bundle());
    // Another worker cannot give back the owner's leases.
    const std::string other = h.registerWorker("other");
    v1::ReleaseRequest release;
    release.set_worker_id(other);
    for (const auto& l : held) release.add_lease_ids(l.lease_id());
    release.set_failure("not mine");
    grpc::ClientContext context;
    prepare(context);
    v1::ReleaseReply released;
    EXPECT_TRUE(h.gateway().ReleaseLeases(&context, release, &released).ok());
    EXPECT_EQ(h.coordinator().activeLeases(), 2u);
    EXPECT_EQ(h.coordinator().jobProgress(id).state(), v1::JOB_STATE_RENDERING);
    h.expectServing();
}

TEST(MalformedRequests, AWorkersHugeFailureReasonFailsOnlyItsJobWithAShortMessage) {
    Harness h;
    v1::JobSpec spec = makeSpec("path", 1, 8, 8, 8);  // one tile
    const std::string id = h.submit(spec);
    h.waitFor(id, [](v1::JobState s) { return s == v1::JOB_STATE_RENDERING; });
    const std::string workerId = h.registerWorker("clumsy");
    for (int attempt = 0; attempt < 3; ++attempt) {
        const auto leases = leaseTiles(h, workerId, id, 1);
        ASSERT_EQ(leases.size(), 1u);
        v1::ReleaseRequest release;
        release.set_worker_id(workerId);
        release.add_lease_ids(leases[0].lease_id());
        release.set_failure(std::string(1 << 20, 'f'));  // 1 MiB of reason
        grpc::ClientContext context;
        prepare(context);
        v1::ReleaseReply released;
        ASSERT_TRUE(h.gateway().ReleaseLeases(&context, release, &released).ok());
    }
    const v1::JobProgress failed = h.coordinator().jobProgress(id);
    EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
    EXPECT_NE(failed.message().find("could not shade it: fff"), std::string::npos) << failed.message().substr(0, 200);
    EXPECT_LE(failed.message().size(), 4200u);
    h.expectServing();
    // The coordinator still renders.
    h.startWorker("good");
    expectImage(h, h.submit(makeSpec("path", 1, 16, 12, 8)), 16, 12);
}

TEST(MalformedRequests, BadTileResultsAreRefusedAndTheJobStillFinishes) {
    Harness h;
    const std::string id = h.submit(makeSpec("path", 2, 64, 64, 8));  // 64 tiles
    h.waitFor(id, [](v1::JobState s) { return s == v1::JOB_STATE_RENDERING; });
    const std::string workerId = h.registerWorker("forger");
    tileResultCases(h, workerId, leaseTiles(h, workerId, id, 24));
    EXPECT_EQ(h.coordinator().jobProgress(id).state(), v1::JOB_STATE_RENDERING);
    EXPECT_EQ(h.coordinator().jobProgress(id).tiles_done(), 1u);  // the one good result
    h.expectServing();
    h.startWorker("good");
    expectImage(h, id, 64, 64);
}

TEST(MalformedRequests, ScenesBrokenByDefinesFailOnlyTheirOwnJobs) {
    Harness h;
    h.startWorker("good");
    const auto broken = submitBrokenScenes(h);
    const std::string good = h.submit(makeSpec("vpl-lightcuts", 1, 16, 12, 8));
    for (const auto& [id, fragment] : broken) {
        const v1::JobProgress last = h.waitForEnd(id);
        EXPECT_EQ(last.state(), v1::JOB_STATE_FAILED) << last.name();
        EXPECT_NE(last.message().find(fragment), std::string::npos) << last.name() << ": " << last.message().substr(0, 300);
        EXPECT_LE(last.message().size(), 4200u) << last.name();
    }
    expectImage(h, good, 16, 12);
    h.expectServing();
}

// Everything at once, from several threads, while valid vrl-lightcuts and
// vpl-lightcuts jobs render: the coordinator answers throughout, and the valid
// jobs (and the job whose tiles were forged) finish with their images.
TEST(MalformedRequests, ABarrageLeavesTheCoordinatorServingAndValidJobsComplete) {
    const auto start = std::chrono::steady_clock::now();
    Harness h;
    v1::JobSpec victimSpec = makeSpec("path", 2, 64, 64, 8);  // 64 tiles, leased first
    victimSpec.set_priority(10);
    const std::string victim = h.submit(victimSpec);
    const std::string lightcuts = h.submit(makeSpec("vrl-lightcuts", 1, 16, 12, 8));
    const std::string vplLightcuts = h.submit(makeSpec("vpl-lightcuts", 1, 16, 12, 8));
    h.waitFor(victim, [](v1::JobState s) { return s == v1::JOB_STATE_RENDERING; });
    const std::string forger = h.registerWorker("forger");
    const auto leases = leaseTiles(h, forger, victim, 24);
    h.startWorker("good");
    const auto broken = submitBrokenScenes(h);

    std::vector<std::future<void>> barrage;
    auto launch = [&](std::function<void()> body) { barrage.push_back(std::async(std::launch::async, std::move(body))); };
    launch([&] { tileResultCases(h, forger, leases); });
    for (int round = 0; round < 2; ++round) {
        launch([&] { submitJobCases(h); });
        launch([&] { jobRefCases(h, ""); });
        launch([&] { uploadCases(h); });
        launch([&] { workerCases(h, ""); });
        launch([&] { h.expectServing(); });
    }
    for (auto& f : barrage) f.get();
    h.expectServing();

    expectImage(h, lightcuts, 16, 12);
    expectImage(h, vplLightcuts, 16, 12);
    expectImage(h, victim, 64, 64);
    for (const auto& [id, fragment] : broken) {
        const v1::JobProgress last = h.waitForEnd(id);
        EXPECT_EQ(last.state(), v1::JOB_STATE_FAILED) << last.name();
        EXPECT_NE(last.message().find(fragment), std::string::npos) << last.name() << ": " << last.message().substr(0, 300);
    }
    h.expectServing();
    std::cout << "barrage and jobs: " << std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
              << " s\n";
}

}  // namespace
}  // namespace vrl
