// The coordinator's state does not grow for ever: PurgeJobs and --retention
// delete finished jobs (records, EXRs) and the scene bundles no remaining job
// uses, keep running jobs and bundles still in use, and do so at start from the
// finish times persisted with each job. Also GetServiceInfo, which clients ask
// before uploading, and the partial image of a job still rendering.
#include "client/job_client.h"
#include "render/image/exr_io.h"
#include "server/coordinator_service.h"
#include "service/common/rpc_common.h"
#include "service/job/job_scene.h"
#include "tests/support/temp_dir.h"
#include "worker/worker.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <thread>

namespace vrl {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using client::JobClient;
using client::JobClientError;
using client::collectSceneBundle;

const fs::path kScene = fs::path(VRL_TEST_DATA_DIR) / ".." / "scenes" / "smoke-room.xml";

v1::JobSpec smallJob(int width, int height, int spp) {
    v1::JobSpec spec;
    *spec.mutable_parameters() = rpc::defaultRenderParameters(parseRenderMethod("path"));
    spec.mutable_parameters()->set_samples_per_pixel(spp);
    spec.mutable_parameters()->set_width(uint32_t(width));
    spec.mutable_parameters()->set_height(uint32_t(height));
    spec.set_tile_size(8);
    spec.set_name("smoke-room.xml");
    return spec;
}

// A coordinator (no token) on loopback over `stateDir`, with in-process workers on demand.
class Coordinator {
public:
    Coordinator(const fs::path& stateDir, std::chrono::milliseconds retention) {
        server::CoordinatorOptions options;
        options.stateDir = stateDir;
        options.retention = retention;
        options.leaseTimeout = 1500ms;
        options.heartbeatInterval = 100ms;
        options.heartbeatTimeout = 600ms;
        coordinator_ = std::make_unique<server::Coordinator>(options);
        server::ServerOptions serverOptions;
        serverOptions.listen = "127.0.0.1:0";
        server_ = std::make_unique<server::CoordinatorServer>(*coordinator_, serverOptions);
        address_ = "127.0.0.1:" + std::to_string(server_->port());
    }
    ~Coordinator() {
        stopWorker();
        server_.reset();
        coordinator_.reset();
    }
    JobClient client() const { return JobClient(address_, {}, ""); }
    std::string submit(const fs::path& scene, v1::JobSpec spec) {
        JobClient c = client();
        spec.set_bundle_sha256(c.uploadBundle(collectSceneBundle(scene, {})));
        return c.submit(spec);
    }
    void startWorker() {
        worker::WorkerOptions o;
        o.coordinator = address_;
        o.threads = 1;
        o.name = "w";
        worker_ = std::make_unique<worker::Worker>(o);
        thread_ = std::thread([this] { worker_->run(); });
    }
    void stopWorker() {
        if (!worker_) return;
        worker_->stop();
        thread_.join();
        worker_.reset();
    }
    server::Coordinator& coordinator() { return *coordinator_; }

private:
    std::unique_ptr<server::Coordinator> coordinator_;
    std::unique_ptr<server::CoordinatorServer> server_;
    std::string address_;
    std::unique_ptr<worker::Worker> worker_;
    std::thread thread_;
};

void waitUntil(const std::function<bool()>& condition, std::chrono::milliseconds timeout = 60s) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (!condition()) {
        ASSERT_LT(std::chrono::steady_clock::now(), until) << "timed out";
        std::this_thread::sleep_for(10ms);
    }
}

// The smoke room copied with a comment appended: the same scene in another bundle.
fs::path copyOfTheScene(const fs::path& dir) {
    fs::copy(kScene.parent_path() / "meshes", dir / "meshes", fs::copy_options::recursive);
    fs::copy_file(kScene, dir / "copy.xml");
    std::ofstream(dir / "copy.xml", std::ios::app) << "<!-- another bundle -->\n";
    return dir / "copy.xml";
}

std::vector<std::string> ids(const std::vector<v1::JobProgress>& jobs) {
    std::vector<std::string> out;
    for (const auto& j : jobs) out.push_back(j.job_id());
    return out;
}

TEST(Retention, PurgeRemovesFinishedJobsTheirImagesAndUnusedBundlesButKeepsRunningJobsAndBundlesInUse) {
    test::TempDir state("vrl-retention-test"), scenes("vrl-retention-scenes");
    const fs::path otherScene = copyOfTheScene(scenes.path());
    Coordinator c(state.path(), 0ms);
    JobClient client = c.client();
    // Job A (bundle A) is rendered to the end; B and C share bundle B; B is cancelled, C keeps running.
    c.startWorker();
    const std::string a = c.submit(kScene, smallJob(16, 12, 1));
    ASSERT_EQ(client.watch(a, {}).state(), v1::JOB_STATE_DONE);
    c.stopWorker();
    const std::string b = c.submit(otherScene, smallJob(16, 12, 1));
    EXPECT_EQ(client.cancel(b), v1::JOB_STATE_CANCELLED);
    const std::string running = c.submit(otherScene, smallJob(64, 48, 4));
    // Jobs are prepared one at a time in order: once `running` renders, B (cancelled, perhaps while being
    // prepared, when it may not be purged yet) is no longer in the preparation thread's hands.
    waitUntil([&] { return c.coordinator().jobProgress(running).state() == v1::JOB_STATE_RENDERING; });
    const fs::path imageA = state.path() / "jobs" / a / "image.exr";
    ASSERT_TRUE(fs::exists(imageA));
    size_t bundlesBefore = 0;
    for (const auto& entry : fs::directory_iterator(state.path() / "bundles"))
        bundlesBefore += entry.path().extension() == ".bundle";
    ASSERT_EQ(bundlesBefore, 2u);

    const v1::PurgeJobsReply reply = client.purge(0ms);
    std::vector<std::string> purged = ids({reply.purged().begin(), reply.purged().end()});
    std::sort(purged.begin(), purged.end());
    std::vector<std::string> expected{a, b};
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(purged, expected);
    EXPECT_EQ(reply.bundles_removed(), 1u);  // bundle A; bundle B is still used by the running job
    EXPECT_GT(reply.bytes_freed(), 0u);
    EXPECT_FALSE(fs::exists(imageA));
    EXPECT_FALSE(fs::exists(state.path() / "jobs" / a));
    EXPECT_FALSE(fs::exists(state.path() / "jobs" / b));
    EXPECT_TRUE(fs::exists(state.path() / "jobs" / running / "spec.pb"));
    size_t bundlesAfter = 0, bundleDirs = 0;
    for (const auto& entry : fs::directory_iterator(state.path() / "bundles")) {
        bundlesAfter += entry.path().extension() == ".bundle";
        bundleDirs += entry.is_directory();
    }
    EXPECT_EQ(bundlesAfter, 1u);
    EXPECT_EQ(bundleDirs, 1u);
    EXPECT_EQ(ids(client.list()), std::vector<std::string>{running});
    try {
        client.fetchImage(a, scenes.path() / "gone.exr");
        FAIL() << "a purged job served an image";
    } catch (const JobClientError& e) {
        EXPECT_EQ(e.code, grpc::StatusCode::NOT_FOUND) << e.what();
    }
    // The running job is not purged and still renders to the end from its bundle.
    c.startWorker();
    EXPECT_EQ(client.watch(running, {}).state(), v1::JOB_STATE_DONE);
}

TEST(Retention, AtStartAFinishedJobOlderThanTheRetentionIsPurgedAndTimesSurviveARestart) {
    test::TempDir state("vrl-retention-test");
    std::string old, recent;
    int64_t recentSubmitted = 0, recentFinished = 0;
    {
        Coordinator c(state.path(), 7 * 24h);
        JobClient client = c.client();
        old = c.submit(kScene, smallJob(16, 12, 1));
        recent = c.submit(kScene, smallJob(16, 12, 1));
        client.cancel(old);
        client.cancel(recent);
        for (const auto& j : client.list()) {
            EXPECT_GT(j.submitted_unix_ms(), 1'600'000'000'000) << j.job_id();
            EXPECT_GE(j.finished_unix_ms(), j.submitted_unix_ms()) << j.job_id();
            if (j.job_id() == recent) {
                recentSubmitted = j.submitted_unix_ms();
                recentFinished = j.finished_unix_ms();
            }
        }
    }
    // Make `old` look finished 8 days ago in its persisted record.
    const fs::path recordFile = state.path() / "jobs" / old / "record.pb";
    v1::JobProgress record;
    ASSERT_TRUE(record.ParseFromString(rpc::readFileText(recordFile.string())));
    record.set_finished_unix_ms(record.finished_unix_ms() - int64_t(8) * 24 * 3600 * 1000);
    std::ofstream(recordFile, std::ios::binary | std::ios::trunc) << record.SerializeAsString();

    Coordinator c(state.path(), 7 * 24h);
    const auto jobs = c.client().list();
    ASSERT_EQ(ids(jobs), std::vector<std::string>{recent});
    EXPECT_EQ(jobs[0].submitted_unix_ms(), recentSubmitted);
    EXPECT_EQ(jobs[0].finished_unix_ms(), recentFinished);
    EXPECT_FALSE(fs::exists(state.path() / "jobs" / old));
    EXPECT_EQ(c.client().purge(24h).purged_size(), 0);  // --older-than 1d: the recent job stays
}

TEST(Retention, ATinyRetentionPurgesPeriodicallyAndAWatcherOfAPurgedJobIsToldItIsGone) {
    test::TempDir state("vrl-retention-test");
    Coordinator c(state.path(), 300ms);
    JobClient client = c.client();
    const std::string id = c.submit(kScene, smallJob(16, 12, 1));
    client.cancel(id);
    waitUntil([&] { return client.list().empty(); }, 10s);
    EXPECT_FALSE(fs::exists(state.path() / "jobs" / id));
    try {
        client.watch(id, {});
        FAIL() << "watching a purged job succeeded";
    } catch (const JobClientError& e) {
        EXPECT_EQ(e.code, grpc::StatusCode::NOT_FOUND) << e.what();
    }
}

TEST(ServiceInfo, GivesVersionsLimitsWorkersAndRetention) {
    test::TempDir state("vrl-retention-test");
    Coordinator c(state.path(), 12h);
    JobClient client = c.client();
    v1::ServiceInfo info = client.serviceInfo();
    EXPECT_EQ(info.program_version(), VRL_VERSION);
    EXPECT_EQ(info.protocol_version(), rpc::kProtocolVersion);
    EXPECT_EQ(info.limits().max_bundle_bytes(), rpc::ServiceLimits{}.maxBundleBytes);
    EXPECT_EQ(info.limits().max_vrls(), rpc::ServiceLimits{}.maxVrls);
    EXPECT_EQ(info.retention_ms(), 12 * 3600 * 1000);
    EXPECT_FALSE(info.token_required());
    EXPECT_EQ(info.workers_connected(), 0u);
    c.startWorker();
    waitUntil([&] { return client.serviceInfo().workers_connected() == 1; }, 20s);
}

TEST(PartialImage, AJobStillRenderingServesItsFinishedTilesMarkedPartial) {
    test::TempDir state("vrl-retention-test");
    Coordinator c(state.path(), 0ms);
    JobClient client = c.client();
    const std::string id = c.submit(kScene, smallJob(64, 48, 512));
    c.startWorker();
    waitUntil([&] { return c.coordinator().jobProgress(id).tiles_done() >= 2; });
    const fs::path file = state.path() / "partial.exr";
    client.fetchImage(id, file, true);
    client.cancel(id);
    try {
        client.fetchImage(id, state.path() / "none.exr", true);  // cancelled: its tiles are gone
        FAIL() << "a cancelled job served a partial image";
    } catch (const JobClientError& e) {
        EXPECT_EQ(e.code, grpc::StatusCode::FAILED_PRECONDITION) << e.what();
    }
    const ImageSet images = readExr(file);
    EXPECT_EQ(images.image.width(), 64);
    EXPECT_EQ(images.image.height(), 48);
    ASSERT_TRUE(images.metadata.count("vrl.partial"));
    ASSERT_TRUE(images.metadata.count("vrl.tilesTotal"));
    EXPECT_GE(metadataNumber(images.metadata.at("vrl.partial")), 2.0);
    EXPECT_EQ(metadataNumber(images.metadata.at("vrl.tilesTotal")), 48.0);  // 8x6 tiles of 8x8
}

}  // namespace
}  // namespace vrl
