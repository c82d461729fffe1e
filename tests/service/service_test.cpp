// The distributed service end to end, inside this process: a real coordinator
// gRPC server on loopback, in-process workers on threads, the JobService
// client. Every image is compared bit for bit with the embedded render.
#include "client/job_client.h"
#include "render/image/exr_io.h"
#include "server/coordinator_service.h"
#include "service/job/job_scene.h"
#include "service/job/scene_bundle.h"
#include "tests/support/temp_dir.h"
#include "util/hash.h"
#include "worker/worker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <random>
#include <thread>

namespace vrl {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using client::JobClient;
using client::JobClientError;
using client::collectSceneBundle;

const fs::path kScene = fs::path(VRL_TEST_DATA_DIR) / ".." / "scenes" / "smoke-room.xml";
constexpr const char* kToken = "test-token-0123456789";

using test::freshDirectory;

v1::JobSpec makeSpec(const std::string& method, int spp, uint64_t seed, int width, int height, uint32_t tile) {
    v1::JobSpec spec;
    auto& p = *spec.mutable_parameters();
    p = rpc::defaultRenderParameters(parseRenderMethod(method));
    p.set_samples_per_pixel(spp);
    p.set_seed(seed);
    p.set_width(uint32_t(width));
    p.set_height(uint32_t(height));
    p.set_vrl_count(3000);
    spec.set_tile_size(tile);
    spec.set_name("smoke-room.xml");
    return spec;
}

// The embedded render of `spec` (same scene, same settings translation).
ImageSet embeddedRender(const v1::JobSpec& spec) {
    const fs::path directory = kScene.parent_path();
    rpc::JobScene job = rpc::loadJobScene(directory, kScene, spec, rpc::ServiceLimits{});
    return render(*job.scene, job.settings);
}

void expectBitIdentical(const ImageSet& expected, const ImageSet& actual) {
    ASSERT_EQ(expected.image.width(), actual.image.width());
    ASSERT_EQ(expected.image.height(), actual.image.height());
    ASSERT_EQ(expected.layers.size(), actual.layers.size());
    auto same = [](const Image& a, const Image& b) {
        return a.pixelCount() == b.pixelCount() &&
               std::memcmp(a.pixels().data(), b.pixels().data(), a.pixelCount() * sizeof(Rgb)) == 0;
    };
    EXPECT_TRUE(same(expected.image, actual.image)) << "image differs";
    for (const auto& [name, layer] : expected.layers) {  // an EXR file lists its layers by name
        const auto found = std::find_if(actual.layers.begin(), actual.layers.end(),
                                        [&layerName = name](const auto& entry) { return entry.first == layerName; });
        ASSERT_NE(found, actual.layers.end()) << "layer " << name << " missing";
        EXPECT_TRUE(same(layer, found->second)) << "layer " << name;
    }
}

// `image` has a layer `name` that is not all zero (so its lights reached the workers).
void expectLayer(const ImageSet& image, std::string_view name) {
    const auto found = std::find_if(image.layers.begin(), image.layers.end(),
                                    [&](const auto& entry) { return entry.first == name; });
    ASSERT_NE(found, image.layers.end()) << "no layer " << name;
    const auto& pixels = found->second.pixels();
    EXPECT_TRUE(std::any_of(pixels.begin(), pixels.end(), [](const Rgb& p) { return p != Rgb(0.0f); }))
        << "layer " << name << " is all zero";
}

// A coordinator on 127.0.0.1:<free port> with a temporary state directory.
class Cluster {
public:
    explicit Cluster(server::CoordinatorOptions options = fastOptions(), fs::path stateDir = {},
                     rpc::TlsOptions tls = {})
        : stateDir_(stateDir.empty() ? freshDirectory("vrl-service-test") : stateDir) {
        options.stateDir = stateDir_;
        coordinator_ = std::make_unique<server::Coordinator>(options);
        server::ServerOptions serverOptions;
        serverOptions.listen = "127.0.0.1:0";
        serverOptions.token = kToken;
        serverOptions.tls = tls;
        server_ = std::make_unique<server::CoordinatorServer>(*coordinator_, serverOptions);
        address_ = "127.0.0.1:" + std::to_string(server_->port());
    }
    ~Cluster() {
        for (auto& w : workers_) w.first->stop();
        for (auto& w : workers_) w.second.join();
        server_.reset();
        coordinator_.reset();
        if (ownsState_) {
            std::error_code error;
            fs::remove_all(stateDir_, error);
        }
    }
    static server::CoordinatorOptions fastOptions() {
        server::CoordinatorOptions o;
        o.leaseTimeout = 1500ms;
        o.heartbeatInterval = 100ms;
        o.heartbeatTimeout = 600ms;
        return o;
    }
    worker::WorkerOptions workerOptions(const std::string& name, const std::string& token = kToken) const {
        worker::WorkerOptions o;
        o.coordinator = address_;
        o.token = token;
        o.threads = 1;
        o.name = name;
        return o;
    }
    worker::Worker& startWorker(const std::string& name) { return startWorker(workerOptions(name)); }
    worker::Worker& startWorker(const worker::WorkerOptions& options) {
        auto worker = std::make_unique<worker::Worker>(options);
        worker::Worker* raw = worker.get();
        workers_.emplace_back(std::move(worker), std::thread([raw] { raw->run(); }));
        return *raw;
    }
    JobClient client(const std::string& token = kToken) const { return JobClient(address_, clientTls_, token); }
    void setClientTls(const rpc::TlsOptions& tls) { clientTls_ = tls; }
    // Uploads the default scene's bundle and submits `spec`.
    std::string submit(v1::JobSpec spec) {
        JobClient c = client();
        spec.set_bundle_sha256(c.uploadBundle(collectSceneBundle(kScene, {})));
        return c.submit(spec);
    }
    ImageSet waitForImage(const std::string& jobId) {
        JobClient c = client();
        const v1::JobProgress last = c.watch(jobId, {});
        EXPECT_EQ(last.state(), v1::JOB_STATE_DONE) << last.message();
        const fs::path file = stateDir_ / ("fetched-" + jobId + ".exr");
        c.fetchImage(jobId, file);
        return readExr(file);
    }
    server::Coordinator& coordinator() { return *coordinator_; }
    const std::string& address() const { return address_; }
    const fs::path& stateDir() const { return stateDir_; }
    void keepState() { ownsState_ = false; }

private:
    fs::path stateDir_;
    bool ownsState_ = true;
    std::unique_ptr<server::Coordinator> coordinator_;
    std::unique_ptr<server::CoordinatorServer> server_;
    std::string address_;
    rpc::TlsOptions clientTls_;
    std::vector<std::pair<std::unique_ptr<worker::Worker>, std::thread>> workers_;
};

void waitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = 60s) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
        ASSERT_LT(std::chrono::steady_clock::now(), until) << "timed out";
        std::this_thread::sleep_for(5ms);
    }
}

TEST(Service, PathImageIsBitIdenticalToTheEmbeddedRender) {
    Cluster cluster;
    cluster.startWorker("a");
    cluster.startWorker("b");
    const v1::JobSpec spec = makeSpec("path", 2, 7, 40, 30, 8);
    const ImageSet image = cluster.waitForImage(cluster.submit(spec));
    expectBitIdentical(embeddedRender(spec), image);
    EXPECT_EQ(std::get<std::string>(image.metadata.at("vrl.method")), "path");
}

TEST(Service, LightcutsImageAndLayersAreBitIdenticalToTheEmbeddedRender) {
    Cluster cluster;
    cluster.startWorker("a");
    cluster.startWorker("b");
    cluster.startWorker("c");
    const v1::JobSpec spec = makeSpec("vrl-lightcuts", 1, 3, 32, 24, 8);
    const std::string id = cluster.submit(spec);
    const ImageSet image = cluster.waitForImage(id);
    expectBitIdentical(embeddedRender(spec), image);
    expectLayer(image, kSurfaceVplLayerName);  // part (b)'s surface VPLs and their tree, shipped with the VRLs
    // Every preparation phase is listed once over, in order, however short it was: a client
    // whose polls fell between them still shows each (client/remote_render.cpp).
    const v1::JobProgress progress = cluster.coordinator().jobProgress(id);
    ASSERT_EQ(progress.preparing_phases_done_size(), 2) << progress.ShortDebugString();
    EXPECT_EQ(progress.preparing_phases_done(0), "light tracing");
    EXPECT_EQ(progress.preparing_phases_done(1), "building the light tree");
}

TEST(Service, PlainVrlImageIsBitIdenticalToTheEmbeddedRender) {
    Cluster cluster;
    cluster.startWorker("a");
    v1::JobSpec spec = makeSpec("vrl", 1, 5, 16, 12, 8);
    spec.mutable_parameters()->set_vrl_count(500);
    const ImageSet image = cluster.waitForImage(cluster.submit(spec));
    expectBitIdentical(embeddedRender(spec), image);
    expectLayer(image, kSurfaceVplLayerName);  // part (b)'s surface VPLs, shipped with the VRLs
}

// Part (b) alone keeps no VRLs, only surface VPLs: they are shipped all the same
// (a "VRLLIGHT" blob with no VRL part), for the plain and the cut shading.
TEST(Service, SurfaceVplsAloneAreShippedAndShadeBitIdentically) {
    Cluster cluster;
    cluster.startWorker("a");
    cluster.startWorker("b");
    for (const char* method : {"vrl", "vrl-lightcuts"}) {
        SCOPED_TRACE(method);
        v1::JobSpec spec = makeSpec(method, 1, 9, 16, 12, 8);
        spec.mutable_parameters()->set_transport("single");
        spec.mutable_parameters()->set_vrl_count(800);
        const ImageSet image = cluster.waitForImage(cluster.submit(spec));
        expectBitIdentical(embeddedRender(spec), image);
        expectLayer(image, kSurfaceVplLayerName);
    }
}

// The job's surface VPL limit reaches the coordinator, which traces them: -1 ships
// none and the workers path-sample part (b)'s surface light (no single-vpl layer);
// a small limit ships the first paths' VPLs (here one chunk's: 64 paths). Both shade bit-identically to the
// embedded render and record the limit in the EXR.
TEST(Service, SurfaceVplLimitReachesTheCoordinatorAndTheWorkers) {
    Cluster cluster;
    cluster.startWorker("a");
    for (const int64_t limit : {int64_t(-1), int64_t(100)}) {
        SCOPED_TRACE(limit);
        v1::JobSpec spec = makeSpec("vrl-lightcuts", 1, 9, 16, 12, 8);
        spec.mutable_parameters()->set_vrl_count(800);
        spec.mutable_parameters()->set_surface_vpls(limit);
        const ImageSet image = cluster.waitForImage(cluster.submit(spec));
        expectBitIdentical(embeddedRender(spec), image);
        const bool hasLayer = std::any_of(image.layers.begin(), image.layers.end(),
                                          [](const auto& entry) { return entry.first == kSurfaceVplLayerName; });
        EXPECT_EQ(hasLayer, limit > 0);
        EXPECT_EQ(std::get<double>(image.metadata.at("vrl.surfaceVplLimit")), limit > 0 ? double(limit) : 0.0);
        if (limit > 0) {
            expectLayer(image, kSurfaceVplLayerName);
            EXPECT_LT(std::get<double>(image.metadata.at("vrl.surfaceVplPaths")),
                      std::get<double>(image.metadata.at("vrl.lightPaths")));
        }
    }
}

// A time-limited job leases (tile, pass): with --spp 6 as its cap it runs 3
// passes whatever the clock, and its image equals the embedded fixed render of
// 6 samples bit for bit, every (tile, pass) taken exactly once, even when a
// worker dies midway (its lease expires and the pass is leased again).
TEST(Service, ProgressiveJobEqualsTheFixedRenderOfItsPasses) {
    Cluster cluster;
    v1::JobSpec spec = makeSpec("vrl-lightcuts", 6, 13, 32, 24, 8);  // 12 tiles
    spec.mutable_parameters()->set_time_limit_seconds(600.0);
    const std::string id = cluster.submit(spec);
    worker::Worker& doomed = cluster.startWorker("doomed");
    waitUntil([&] { return cluster.coordinator().jobProgress(id).tiles_done() >= 2; });
    doomed.kill();
    cluster.startWorker("a");
    cluster.startWorker("b");
    const ImageSet image = cluster.waitForImage(id);
    v1::JobSpec fixed = spec;
    fixed.mutable_parameters()->set_time_limit_seconds(0.0);
    expectBitIdentical(embeddedRender(fixed), image);
    EXPECT_EQ(metadataNumber(image.metadata.at("vrl.progressive.passes")), 3.0);
    EXPECT_EQ(metadataNumber(image.metadata.at("vrl.spp")), 6.0);
    EXPECT_EQ(image.metadata.count("vrl.partial"), 0u);
    const v1::JobProgress progress = cluster.coordinator().jobProgress(id);
    EXPECT_EQ(progress.passes_done(), 3u);
    EXPECT_EQ(progress.passes_total(), 3u);
    EXPECT_EQ(progress.samples_per_pixel(), 6);
    EXPECT_EQ(cluster.coordinator().statistics().tilesAccepted, 12u * 3u);
}

// The time limit ends the job with its completed passes: nothing here depends
// on how many there are (the machine's speed), only that they are whole
// passes equal to the fixed render of their samples, or, if the limit ran out
// in the first pass, a partial image.
TEST(Service, TimeLimitedJobEndsWithItsCompletedPasses) {
    Cluster cluster;
    cluster.startWorker("a");
    cluster.startWorker("b");
    v1::JobSpec spec = makeSpec("path", 0, 5, 16, 8, 8);
    spec.mutable_parameters()->set_time_limit_seconds(1.0);
    const ImageSet image = cluster.waitForImage(cluster.submit(spec));
    const int passes = int(metadataNumber(image.metadata.at("vrl.progressive.passes")));
    const int spp = int(metadataNumber(image.metadata.at("vrl.spp")));
    if (passes == 0) {
        EXPECT_EQ(image.metadata.count("vrl.partial"), 1u);
        GTEST_SKIP() << "the time limit ran out in the first pass on this machine";
    }
    EXPECT_EQ(spp, (1 << passes) - 1);
    EXPECT_LT(passes, 21) << "the limit, not the cap, should have ended it";
    v1::JobSpec fixed = spec;
    fixed.mutable_parameters()->set_time_limit_seconds(0.0);
    fixed.mutable_parameters()->set_samples_per_pixel(spp);
    expectBitIdentical(embeddedRender(fixed), image);
}

TEST(Service, AJobSurvivesAWorkerKilledMidJob) {
    Cluster cluster;
    const v1::JobSpec spec = makeSpec("path", 8, 11, 48, 32, 8);  // 24 tiles
    const std::string id = cluster.submit(spec);
    worker::Worker& doomed = cluster.startWorker("doomed");
    waitUntil([&] { return cluster.coordinator().jobProgress(id).tiles_done() >= 3; });
    doomed.kill();  // no more heartbeats, results or releases: its lease must expire
    const auto killedAt = cluster.coordinator().jobProgress(id).tiles_done();
    EXPECT_LT(killedAt, 24u) << "the job finished before the worker died; make it longer";
    cluster.startWorker("survivor");
    expectBitIdentical(embeddedRender(spec), cluster.waitForImage(id));
    const auto stats = cluster.coordinator().statistics();
    EXPECT_EQ(stats.tilesAccepted, 24u);  // every tile taken exactly once
}

TEST(Service, AWorkerOfAnotherProtocolVersionIsRefusedNamingBothVersions) {
    Cluster cluster;
    worker::WorkerOptions options = cluster.workerOptions("old");
    options.protocolVersion = 99;
    worker::Worker worker(options);
    try {
        worker.run();
        FAIL() << "a worker of protocol 99 was accepted";
    } catch (const worker::WorkerRefused& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("protocol 99"), std::string::npos) << message;
        EXPECT_NE(message.find("protocol " + std::to_string(rpc::kProtocolVersion)), std::string::npos) << message;
        EXPECT_NE(message.find(VRL_VERSION), std::string::npos) << message;
    }
    options.protocolVersion = rpc::kProtocolVersion;
    options.programVersion = "0.0.0-other";
    worker::Worker other(options);
    EXPECT_THROW(other.run(), worker::WorkerRefused);
}

TEST(Service, AWrongOrMissingTokenIsRefused) {
    Cluster cluster;
    try {
        cluster.client("not-the-token").list();
        FAIL() << "a wrong token was accepted";
    } catch (const JobClientError& e) {
        EXPECT_EQ(e.code, grpc::StatusCode::UNAUTHENTICATED);
        EXPECT_NE(std::string(e.what()).find("wrong token"), std::string::npos) << e.what();
    }
    try {
        cluster.client("").list();
        FAIL() << "a call without a token was accepted";
    } catch (const JobClientError& e) {
        EXPECT_EQ(e.code, grpc::StatusCode::UNAUTHENTICATED);
        EXPECT_NE(std::string(e.what()).find("requires a token"), std::string::npos) << e.what();
    }
    worker::Worker worker(cluster.workerOptions("intruder", "not-the-token"));
    EXPECT_THROW(worker.run(), worker::WorkerRefused);
    EXPECT_NO_THROW(cluster.client().list());
}

TEST(Service, TwoJobsRunAtOnceAndTheHigherPriorityGoesFirst) {
    Cluster cluster;
    v1::JobSpec low = makeSpec("path", 2, 1, 32, 24, 8);
    v1::JobSpec high = makeSpec("vrl-lightcuts", 1, 2, 32, 24, 8);
    low.set_priority(0);
    high.set_priority(5);
    const std::string lowId = cluster.submit(low);
    const std::string highId = cluster.submit(high);
    waitUntil([&] {
        return cluster.coordinator().jobProgress(lowId).state() == v1::JOB_STATE_RENDERING &&
               cluster.coordinator().jobProgress(highId).state() == v1::JOB_STATE_RENDERING;
    });
    cluster.startWorker("only");  // one thread: tiles are leased strictly by priority
    waitUntil([&] {
        return cluster.coordinator().jobProgress(lowId).state() == v1::JOB_STATE_DONE ||
               cluster.coordinator().jobProgress(highId).state() == v1::JOB_STATE_DONE;
    });
    EXPECT_EQ(cluster.coordinator().jobProgress(highId).state(), v1::JOB_STATE_DONE);
    EXPECT_NE(cluster.coordinator().jobProgress(lowId).state(), v1::JOB_STATE_DONE);
    cluster.startWorker("second");
    expectBitIdentical(embeddedRender(high), cluster.waitForImage(highId));
    expectBitIdentical(embeddedRender(low), cluster.waitForImage(lowId));
    const auto jobs = cluster.client().list();
    EXPECT_EQ(jobs.size(), 2u);
}

TEST(Service, CancelStopsAJobAndItsImageIsNeverServed) {
    Cluster cluster;
    const std::string id = cluster.submit(makeSpec("path", 64, 1, 64, 48, 8));
    cluster.startWorker("a");
    waitUntil([&] { return cluster.coordinator().jobProgress(id).tiles_done() >= 1; });
    JobClient client = cluster.client();
    EXPECT_EQ(client.cancel(id), v1::JOB_STATE_CANCELLED);
    const v1::JobProgress last = client.watch(id, {});
    EXPECT_EQ(last.state(), v1::JOB_STATE_CANCELLED);
    EXPECT_LT(last.tiles_done(), last.tiles_total());
    try {
        client.fetchImage(id, cluster.stateDir() / "never.exr");
        FAIL() << "a cancelled job served an image";
    } catch (const JobClientError& e) {
        EXPECT_EQ(e.code, grpc::StatusCode::FAILED_PRECONDITION);
    }
    // The worker keeps serving: a later job still completes.
    const v1::JobSpec spec = makeSpec("path", 1, 2, 16, 16, 8);
    expectBitIdentical(embeddedRender(spec), cluster.waitForImage(cluster.submit(spec)));
}

// Uploads a hand-made bundle; returns the status code of the upload.
grpc::StatusCode uploadRaw(JobClient& client, const v1::SceneBundle& bundle, std::string* message) {
    std::string blob;
    bundle.SerializeToString(&blob);
    try {
        client.uploadBundle(blob);
        return grpc::StatusCode::OK;
    } catch (const JobClientError& e) {
        *message = e.what();
        return e.code;
    }
}

TEST(Service, HostileBundlesAreRefused) {
    server::CoordinatorOptions options = Cluster::fastOptions();
    options.limits.maxBundleBytes = 64 << 10;
    Cluster cluster(options);
    JobClient client = cluster.client();
    const std::string scene = "<scene version=\"0.5.0\"><sensor type=\"perspective\"/></scene>";
    struct Case {
        std::string path;
        v1::BundleEntry::Kind kind;
        std::string expected;
    };
    const std::vector<Case> cases = {{"../evil.xml", v1::BundleEntry::KIND_FILE, "'..'"},
                                     {"a/../../evil.xml", v1::BundleEntry::KIND_FILE, "'..'"},
                                     {"/etc/passwd", v1::BundleEntry::KIND_FILE, "absolute"},
                                     {"link.obj", v1::BundleEntry::KIND_SYMLINK, "link"}};
    for (const auto& c : cases) {
        v1::SceneBundle bundle;
        bundle.set_scene_path("scene.xml");
        auto* main = bundle.add_entries();
        main->set_path("scene.xml");
        main->set_data(scene);
        auto* hostile = bundle.add_entries();
        hostile->set_path(c.path);
        hostile->set_kind(c.kind);
        hostile->set_data("x");
        std::string message;
        EXPECT_EQ(uploadRaw(client, bundle, &message), grpc::StatusCode::INVALID_ARGUMENT) << c.path;
        EXPECT_NE(message.find(c.expected), std::string::npos) << message;
    }
    v1::SceneBundle big;
    big.set_scene_path("scene.xml");
    big.add_entries()->set_path("scene.xml");
    big.add_entries()->set_path("padding.bin");
    big.mutable_entries(1)->set_data(std::string(100 << 10, 'x'));
    std::string message;
    EXPECT_EQ(uploadRaw(client, big, &message), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_NE(message.find("exceeds the limit"), std::string::npos) << message;

    // A scene that includes a file outside its bundle fails, naming the problem.
    v1::SceneBundle escaping;
    escaping.set_scene_path("scene.xml");
    escaping.add_entries()->set_path("scene.xml");
    escaping.mutable_entries(0)->set_data(
        "<scene version=\"0.5.0\"><include filename=\"../../../../../../etc/hostname\"/></scene>");
    std::string blob;
    escaping.SerializeToString(&blob);
    v1::JobSpec spec = makeSpec("path", 1, 0, 8, 8, 8);
    spec.set_bundle_sha256(client.uploadBundle(blob));
    const std::string id = client.submit(spec);
    const v1::JobProgress last = client.watch(id, {});
    EXPECT_EQ(last.state(), v1::JOB_STATE_FAILED);
    EXPECT_NE(last.message().find("outside the scene bundle"), std::string::npos) << last.message();
}

TEST(Service, ABundleIsUploadedOnceAndAWorkerDownloadsAJobsAssetsOnce) {
    Cluster cluster;
    JobClient client = cluster.client();
    const std::string blob = collectSceneBundle(kScene, {});
    bool uploaded = false;
    client.uploadBundle(blob, &uploaded);
    EXPECT_TRUE(uploaded);
    client.uploadBundle(blob, &uploaded);
    EXPECT_FALSE(uploaded);
    worker::Worker& worker = cluster.startWorker("a");
    const v1::JobSpec spec = makeSpec("vrl-lightcuts", 1, 1, 32, 32, 8);  // 16 tiles
    (void)cluster.waitForImage(cluster.submit(spec));
    const auto stats = worker.statistics();
    EXPECT_EQ(stats.assets.blobs, 2u);  // the bundle and the light tree, once each for 16 tiles
    EXPECT_EQ(stats.jobsLoaded, 1u);
}

// The Coordinator core without gRPC, holding the default scene's bundle; leases
// and workers never time out, so a test drives every step itself.
struct CoreCoordinator {
    CoreCoordinator() {
        options = Cluster::fastOptions();
        options.stateDir = freshDirectory("vrl-coordinator-core");
        options.leaseTimeout = 60s;
        options.heartbeatTimeout = 60s;
        coordinator = std::make_unique<server::Coordinator>(options);
        const std::string blob = collectSceneBundle(kScene, {});
        sha = util::sha256Hex(blob);
        coordinator->storeBundle(sha, blob);
    }
    ~CoreCoordinator() {
        coordinator.reset();
        std::error_code error;
        fs::remove_all(options.stateDir, error);
    }
    server::CoordinatorOptions options;
    std::unique_ptr<server::Coordinator> coordinator;
    std::string sha;
};

std::string registerTestWorker(server::Coordinator& coordinator) {
    v1::RegisterRequest hello;
    hello.set_protocol_version(rpc::kProtocolVersion);
    hello.set_program_version(VRL_VERSION);
    hello.set_threads(1);
    return coordinator.registerWorker(hello).worker_id();
}

TEST(Service, TileResultsAreTakenOnceAndCheckedBeforeMerging) {
    {
        CoreCoordinator core;
        server::Coordinator& coordinator = *core.coordinator;
        const std::string sha = core.sha;
        v1::JobSpec spec = makeSpec("path", 1, 0, 16, 8, 8);  // two tiles
        spec.set_bundle_sha256(sha);
        const std::string id = coordinator.submitJob(spec);
        const std::string workerId = registerTestWorker(coordinator);
        v1::LeaseRequest ask;
        ask.set_worker_id(workerId);
        ask.set_max_tiles(4);
        v1::LeaseReply lease;
        waitUntil([&] {
            lease = coordinator.leaseTiles(ask);
            return lease.leases_size() > 0;
        });
        ASSERT_EQ(lease.leases_size(), 2);
        const v1::TileLease second = lease.leases(1);
        auto resultFor = [&](const v1::TileLease& l, const std::vector<float>& pixels, size_t bytes) {
            v1::TileResult result;
            result.set_worker_id(workerId);
            result.set_lease_id(l.lease_id());
            result.set_job_id(id);
            *result.mutable_tile() = l.tile();
            result.set_first_pass(l.first_pass());
            result.set_pass_count(l.pass_count());
            result.add_layers()->set_rgb(pixels.data(), bytes);
            return result;
        };
        std::vector<float> pixels(8 * 8 * 3, 0.25f);
        const size_t bytes = pixels.size() * sizeof(float);
        pixels[17] = std::numeric_limits<float>::quiet_NaN();
        v1::SubmitTileReply reply = coordinator.submitTile(resultFor(lease.leases(0), pixels, bytes));
        EXPECT_FALSE(reply.accepted());
        EXPECT_NE(reply.reason().find("non-finite"), std::string::npos) << reply.reason();
        reply = coordinator.submitTile(resultFor(lease.leases(0), pixels, 10));  // truncated
        EXPECT_FALSE(reply.accepted());
        EXPECT_NE(reply.reason().find("wrong size"), std::string::npos) << reply.reason();
        // The refused tile went back to the queue; a good result is taken, a duplicate dropped.
        waitUntil([&] {
            lease = coordinator.leaseTiles(ask);
            return lease.leases_size() > 0;
        });
        ASSERT_EQ(lease.leases_size(), 1);
        pixels[17] = 0.5f;
        EXPECT_TRUE(coordinator.submitTile(resultFor(lease.leases(0), pixels, bytes)).accepted());
        reply = coordinator.submitTile(resultFor(lease.leases(0), pixels, bytes));
        EXPECT_FALSE(reply.accepted());
        EXPECT_NE(reply.reason().find("duplicate"), std::string::npos) << reply.reason();
        EXPECT_EQ(coordinator.statistics().duplicatesDropped, 1u);
        EXPECT_EQ(coordinator.jobProgress(id).tiles_done(), 1u);
        std::vector<float> other(8 * 8 * 3, 1.0f);
        EXPECT_TRUE(coordinator.submitTile(resultFor(second, other, bytes)).accepted());
        EXPECT_EQ(coordinator.jobProgress(id).state(), v1::JOB_STATE_DONE);
        const ImageSet image = readExr(coordinator.imageFile(id));
        EXPECT_EQ(image.image.at(5, 0).z, 0.5f);
        EXPECT_EQ(image.image.at(0, 0).x, 0.25f);
        EXPECT_EQ(image.image.at(12, 3).y, 1.0f);
    }
}

TEST(Service, AJobNoWorkerCanShadeFailsWithTheWorkersReasonAndForeignLeasesAreIgnored) {
    {
        CoreCoordinator core;
        server::Coordinator& coordinator = *core.coordinator;
        const server::CoordinatorOptions& options = core.options;
        const std::string sha = core.sha;
        v1::JobSpec big = makeSpec("path", 1, 0, 64, 64, 8);  // 64 tiles
        big.set_bundle_sha256(sha);
        v1::JobSpec small = makeSpec("path", 1, 0, 8, 8, 8);  // 1 tile, higher priority: leased first
        small.set_bundle_sha256(sha);
        small.set_priority(1);
        const std::string bigId = coordinator.submitJob(big);
        const std::string smallId = coordinator.submitJob(small);
        const std::string workerId = registerTestWorker(coordinator);
        v1::LeaseRequest ask;
        ask.set_worker_id(workerId);
        ask.set_max_tiles(1);
        waitUntil([&] { return coordinator.jobProgress(bigId).state() == v1::JOB_STATE_RENDERING &&
                               coordinator.jobProgress(smallId).state() == v1::JOB_STATE_RENDERING; });
        // A result for the small job carrying a lease of the big one is refused without touching the big job.
        ask.set_max_tiles(2);
        const v1::LeaseReply two = coordinator.leaseTiles(ask);
        ASSERT_EQ(two.leases_size(), 2);
        ASSERT_EQ(two.leases(0).job_id(), smallId);
        ASSERT_EQ(two.leases(1).job_id(), bigId);
        v1::TileResult forged;
        forged.set_worker_id(workerId);
        forged.set_job_id(smallId);
        forged.set_lease_id(two.leases(1).lease_id());
        *forged.mutable_tile() = two.leases(1).tile();
        EXPECT_FALSE(coordinator.submitTile(forged).accepted());
        EXPECT_EQ(coordinator.activeLeases(), 2u);  // the big job's lease is untouched
        // A worker that cannot shade the small job gives its lease back with a reason, three times.
        std::string lastLease = two.leases(0).lease_id();
        for (int attempt = 0; attempt < options.maxTileRejections; ++attempt) {
            v1::ReleaseRequest release;
            release.set_worker_id(workerId);
            release.set_failure("cannot load the job: test");
            release.add_lease_ids(lastLease);
            coordinator.releaseLeases(release);
            if (attempt + 1 < options.maxTileRejections) {
                ask.set_max_tiles(1);
                const v1::LeaseReply again = coordinator.leaseTiles(ask);
                ASSERT_EQ(again.leases_size(), 1);
                ASSERT_EQ(again.leases(0).job_id(), smallId);
                lastLease = again.leases(0).lease_id();
            }
        }
        const v1::JobProgress failed = coordinator.jobProgress(smallId);
        EXPECT_EQ(failed.state(), v1::JOB_STATE_FAILED);
        EXPECT_NE(failed.message().find("could not shade it: cannot load the job: test"), std::string::npos)
            << failed.message();
        EXPECT_EQ(coordinator.jobProgress(bigId).state(), v1::JOB_STATE_RENDERING);
    }
}

TEST(Service, UnfinishedJobsResumeAfterACoordinatorRestartAndFinishedOnesStayFetchable) {
    const fs::path state = freshDirectory("vrl-restart");
    const v1::JobSpec spec = makeSpec("path", 8, 4, 48, 32, 8);  // 24 tiles
    std::string id;
    {
        Cluster first(Cluster::fastOptions(), state);
        first.keepState();
        id = first.submit(spec);
        first.startWorker("a");
        waitUntil([&] { return first.coordinator().jobProgress(id).tiles_done() >= 4; });
    }  // the coordinator stops mid-job
    Cluster second(Cluster::fastOptions(), state);
    waitUntil([&] { return second.coordinator().jobProgress(id).state() == v1::JOB_STATE_RENDERING; });
    const auto restored = second.coordinator().jobProgress(id).tiles_done();
    EXPECT_GE(restored, 4u) << "the checkpointed tiles were not restored";
    second.startWorker("b");
    expectBitIdentical(embeddedRender(spec), second.waitForImage(id));
    EXPECT_LE(second.coordinator().statistics().tilesAccepted, 24u - restored);
    second.keepState();
    {
        Cluster third(Cluster::fastOptions(), state);  // a finished job survives a restart too
        EXPECT_EQ(third.coordinator().jobProgress(id).state(), v1::JOB_STATE_DONE);
        expectBitIdentical(embeddedRender(spec), third.waitForImage(id));
    }
    std::error_code error;
    fs::remove_all(state, error);
}

// A CA, a server certificate for 127.0.0.1 and a worker's client certificate, made with the openssl CLI.
void makeCertificates(const fs::path& dir) {
    const std::string d = dir.string();
    std::ofstream(dir / "server.ext") << "subjectAltName=IP:127.0.0.1,DNS:localhost\n";
    std::ofstream(dir / "client.ext") << "extendedKeyUsage=clientAuth\n";
    const std::string quiet = " > /dev/null 2>&1";
    const std::vector<std::string> commands = {
        "openssl req -x509 -newkey rsa:2048 -nodes -keyout " + d + "/ca.key -out " + d +
            "/ca.pem -days 2 -subj /CN=vrl-test-ca",
        "openssl req -newkey rsa:2048 -nodes -keyout " + d + "/server.key -out " + d + "/server.csr -subj /CN=localhost",
        "openssl x509 -req -in " + d + "/server.csr -CA " + d + "/ca.pem -CAkey " + d + "/ca.key -CAcreateserial -out " +
            d + "/server.pem -days 2 -extfile " + d + "/server.ext",
        "openssl req -newkey rsa:2048 -nodes -keyout " + d + "/worker.key -out " + d + "/worker.csr -subj /CN=worker",
        "openssl x509 -req -in " + d + "/worker.csr -CA " + d + "/ca.pem -CAkey " + d + "/ca.key -CAcreateserial -out " +
            d + "/worker.pem -days 2 -extfile " + d + "/client.ext"};
    for (const auto& command : commands) ASSERT_EQ(std::system((command + quiet).c_str()), 0) << command;
}

TEST(Service, TlsWithWorkerCertificatesRendersTheSameImageAndRefusesPlaintextAndCertlessWorkers) {
    const fs::path certs = freshDirectory("vrl-tls");
    makeCertificates(certs);
    rpc::TlsOptions serverTls;
    serverTls.certFile = (certs / "server.pem").string();
    serverTls.keyFile = (certs / "server.key").string();
    serverTls.clientCaFile = (certs / "ca.pem").string();
    {
        Cluster cluster(Cluster::fastOptions(), {}, serverTls);
        rpc::TlsOptions clientTls;
        clientTls.caFile = (certs / "ca.pem").string();
        // A plaintext client cannot talk to a TLS coordinator.
        EXPECT_THROW(cluster.client().list(), JobClientError);
        cluster.setClientTls(clientTls);
        EXPECT_NO_THROW(cluster.client().list());
        // A worker without a client certificate is refused; one with a certificate renders.
        worker::WorkerOptions certless = cluster.workerOptions("certless");
        certless.tls = clientTls;
        worker::Worker refused(certless);
        try {
            refused.run();
            FAIL() << "a worker without a client certificate was accepted";
        } catch (const worker::WorkerRefused& e) {
            EXPECT_NE(std::string(e.what()).find("client certificate"), std::string::npos) << e.what();
        }
        worker::WorkerOptions good = cluster.workerOptions("certified");
        good.tls = clientTls;
        good.tls.certFile = (certs / "worker.pem").string();
        good.tls.keyFile = (certs / "worker.key").string();
        cluster.startWorker(good);
        const v1::JobSpec spec = makeSpec("path", 1, 3, 16, 16, 8);
        expectBitIdentical(embeddedRender(spec), cluster.waitForImage(cluster.submit(spec)));
    }
    std::error_code error;
    fs::remove_all(certs, error);
}

}  // namespace
}  // namespace vrl
