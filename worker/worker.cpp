#include "worker/worker.h"

#include "service/job/job_lights_blob.h"
#include "service/job/job_scene.h"
#include "service/job/scene_bundle.h"
#include "util/atomic_file.h"
#include "util/random_id.h"
#include "vrl/v1/vrl.grpc.pb.h"

#include <spdlog/spdlog.h>
#include <tbb/info.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <random>
#include <span>
#include <vector>

namespace vrl::worker {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

struct Worker::JobContext {
    v1::JobAssets assets;
    rpc::JobScene scene;
    RenderLights lights;
    std::unique_ptr<TileShader> shader;
};

namespace {

std::string defaultName() {
    char host[256] = {};
    gethostname(host, sizeof host - 1);
    return std::string(host) + ":" + std::to_string(getpid());
}

bool retryable(const grpc::Status& status) {
    return status.error_code() == grpc::StatusCode::UNAVAILABLE ||
           status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED;
}

}  // namespace

Worker::Worker(WorkerOptions options) : options_(std::move(options)) {
    if (options_.threads <= 0) options_.threads = tbb::info::default_concurrency();
    if (options_.name.empty()) options_.name = defaultName();
    channel_ = rpc::makeChannel(options_.coordinator, options_.tls);
    fetcher_ = std::make_unique<AssetFetcher>(channel_, options_.token);
    if (options_.cacheDir.empty()) {
        cacheDir_ = fs::temp_directory_path() / ("vrl-worker-" + std::to_string(getpid()) + "-" + util::randomHex(8));
        ownsCacheDir_ = true;
    } else {
        cacheDir_ = options_.cacheDir;
    }
    fs::create_directories(cacheDir_);
    if (!options_.healthListen.empty()) {
        grpc::ServerBuilder builder;
        builder.RegisterService(&health_);
        int port = 0;
        builder.AddListeningPort(options_.healthListen, grpc::InsecureServerCredentials(), &port);
        healthServer_ = builder.BuildAndStart();
        if (!healthServer_ || port == 0)
            throw std::runtime_error("cannot serve health checks on '" + options_.healthListen + "'");
        health_.setServing(false);  // SERVING once registered
    }
}

Worker::~Worker() {
    stop();
    if (healthServer_) {
        health_.shutdown();
        healthServer_->Shutdown(std::chrono::system_clock::now() + 1s);
    }
    if (ownsCacheDir_) {
        std::error_code error;
        fs::remove_all(cacheDir_, error);
    }
}

void Worker::stop() {
    health_.setServing(false);  // draining: take no new work
    {
        std::lock_guard lock(mutex_);  // so a sleeper cannot miss the wake-up
        stopping_ = true;
    }
    wake_.notify_all();
}

void Worker::kill() {
    killed_ = true;
    stop();
}

bool Worker::sleepUnlessStopping(std::chrono::milliseconds duration) {
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, duration, [&] { return stopping_.load(); });
    return !stopping_;
}

WorkerStatistics Worker::statistics() const {
    std::lock_guard lock(mutex_);
    WorkerStatistics s = statistics_;
    s.assets = fetcher_->statistics();
    return s;
}

void Worker::registerWorker() {
    std::lock_guard guard(registerMutex_);
    if (!workerId_.empty() && !reregister_) return;
    auto stub = v1::WorkerGateway::NewStub(channel_);
    const auto start = std::chrono::steady_clock::now();
    bool warned = false;
    while (!stopping_) {
        grpc::ClientContext context;
        rpc::prepareContext(context, options_.token, 10s);
        context.set_wait_for_ready(true);
        v1::RegisterRequest request;
        request.set_protocol_version(options_.protocolVersion);
        request.set_program_version(options_.programVersion);
        request.set_threads(uint32_t(options_.threads));
        request.set_name(options_.name);
        v1::RegisterReply reply;
        const grpc::Status status = stub->Register(&context, request, &reply);
        if (status.ok()) {
            workerId_ = reply.worker_id();
            heartbeatIntervalMs_ = std::max<uint32_t>(10, reply.heartbeat_interval_ms());
            reregister_ = false;
            spdlog::info("registered with {} as {} ({} threads)", options_.coordinator, workerId_, options_.threads);
            health_.setServing(true);
            return;
        }
        if (!retryable(status))
            throw WorkerRefused("the coordinator at " + options_.coordinator + " refused this worker: " +
                                rpc::describe(status));
        if (!warned) {
            spdlog::warn("coordinator {} not reachable yet ({}); retrying", options_.coordinator, rpc::describe(status));
            warned = true;
        }
        if (workerId_.empty() && std::chrono::steady_clock::now() - start > 5min)
            throw std::runtime_error("the coordinator at " + options_.coordinator + " stayed unreachable for 5 minutes");
        sleepUnlessStopping(500ms);
    }
}

void Worker::run() {
    registerWorker();
    std::thread heartbeat([this] { heartbeatLoop(); });
    std::vector<std::thread> loops;
    std::exception_ptr failure;
    std::mutex failureMutex;
    for (int t = 0; t < options_.threads; ++t)
        loops.emplace_back([&] {
            try {
                leaseLoop();
            } catch (...) {
                std::lock_guard lock(failureMutex);
                if (!failure) failure = std::current_exception();
                stop();
            }
        });
    for (auto& loop : loops) loop.join();
    stop();
    heartbeat.join();
    health_.setServing(false);
    spdlog::info("worker {} stopped ({} tiles returned)", workerId_, statistics().tilesAccepted);
    if (failure) std::rethrow_exception(failure);
}

void Worker::heartbeatLoop() {
    auto stub = v1::WorkerGateway::NewStub(channel_);
    while (sleepUnlessStopping(std::chrono::milliseconds(heartbeatIntervalMs_.load()))) {
        if (killed_) return;
        grpc::ClientContext context;
        rpc::prepareContext(context, options_.token, std::chrono::milliseconds(std::max<int64_t>(heartbeatIntervalMs_ * 2, 1000)));
        v1::HeartbeatRequest request;
        {
            std::lock_guard guard(registerMutex_);
            request.set_worker_id(workerId_);
        }
        v1::HeartbeatReply reply;
        const grpc::Status status = stub->Heartbeat(&context, request, &reply);
        if (status.ok() && !reply.known()) {
            spdlog::warn("the coordinator forgot this worker (it restarted, or heartbeats were late); registering again");
            reregister_ = true;
            health_.setServing(false);  // until registered again
        } else if (!status.ok()) {
            spdlog::warn("heartbeat failed: {}", rpc::describe(status));
        }
    }
}

std::shared_ptr<const Worker::JobContext> Worker::loadJob(const std::string& jobId, const std::string& assetsBytes) {
    std::promise<std::shared_ptr<const JobContext>> promise;
    std::shared_future<std::shared_ptr<const JobContext>> future;
    bool mine = false;
    {
        std::lock_guard lock(mutex_);
        const auto it = jobs_.find(jobId);
        if (it != jobs_.end()) {
            future = it->second;
        } else {
            future = promise.get_future().share();
            jobs_[jobId] = future;
            jobOrder_.push_back(jobId);
            while (jobOrder_.size() > options_.maxCachedJobs) {  // a loaded job in use stays alive via its shared_ptr
                jobs_.erase(jobOrder_.front());
                jobOrder_.erase(jobOrder_.begin());
            }
            mine = true;
        }
    }
    if (!mine) return future.get();
    try {
        auto context = std::make_shared<JobContext>();
        if (!context->assets.ParseFromString(assetsBytes)) throw std::runtime_error("corrupt job description");
        const auto& assets = context->assets;
        const std::string& bundleSha = assets.spec().bundle_sha256();
        if (bundleSha.size() != 64 || bundleSha.find_first_not_of("0123456789abcdef") != std::string::npos)
            throw std::runtime_error("the coordinator named a malformed bundle hash");
        if (assets.bundle_size() > options_.limits.maxBundleBytes)
            throw std::runtime_error("the job's bundle exceeds this worker's bundle size limit");
        const fs::path bundleDir = cacheDir_ / "bundles" / bundleSha;
        const fs::path marker = cacheDir_ / "bundles" / (bundleSha + ".scene");  // written once the bundle is whole
        fs::path sceneFile;
        if (fs::exists(marker)) {
            sceneFile = bundleDir / rpc::readFileText(marker.string());
        } else {
            const std::string blob = fetcher_->fetch(bundleSha, assets.bundle_size());
            const v1::SceneBundle bundle = rpc::parseBundleBlob(blob, options_.limits);
            fs::create_directories(bundleDir.parent_path());
            std::error_code error;
            fs::remove_all(bundleDir, error);  // a half-written copy from a crash
            sceneFile = rpc::extractBundle(bundle, bundleDir);
            util::writeFileAtomically(marker, bundle.scene_path());
        }
        context->scene = rpc::loadJobScene(bundleDir, sceneFile, assets.spec(), options_.limits);
        if (context->scene.width != int(assets.width()) || context->scene.height != int(assets.height()) ||
            context->scene.settings.samplesPerPixel != assets.samples_per_pixel())
            throw std::runtime_error("this worker resolves the job's scene differently from the coordinator "
                                     "(resolution or samples); are both the same release?");
        if (!assets.lights_sha256().empty()) {
            const std::string blob = fetcher_->fetch(assets.lights_sha256(), assets.lights_size());
            context->lights = rpc::decodeJobLights(
                std::span(reinterpret_cast<const uint8_t*>(blob.data()), blob.size()), context->scene.settings);
        }
        context->shader = std::make_unique<TileShader>(*context->scene.scene, context->scene.settings, context->lights);
        if (context->shader->layerNames() != std::vector<std::string>(assets.layer_names().begin(), assets.layer_names().end()))
            throw std::runtime_error("this worker's layers differ from the coordinator's");
        {
            std::lock_guard lock(mutex_);
            ++statistics_.jobsLoaded;
        }
        spdlog::info("job {}: assets verified and scene built", jobId);
        promise.set_value(context);
    } catch (...) {
        {
            std::lock_guard lock(mutex_);
            jobs_.erase(jobId);  // a later lease tries again
            std::erase(jobOrder_, jobId);
        }
        promise.set_exception(std::current_exception());
    }
    return future.get();
}

void Worker::leaseLoop() {
    auto stub = v1::WorkerGateway::NewStub(channel_);
    while (!stopping_) {
        if (reregister_) registerWorker();
        v1::LeaseRequest request;
        {
            std::lock_guard guard(registerMutex_);
            request.set_worker_id(workerId_);
        }
        request.set_max_tiles(1);
        v1::LeaseReply reply;
        grpc::ClientContext context;
        rpc::prepareContext(context, options_.token, 10s);
        const grpc::Status status = stub->LeaseTiles(&context, request, &reply);
        if (!status.ok()) {
            if (status.error_code() == grpc::StatusCode::FAILED_PRECONDITION) {
                reregister_ = true;  // the coordinator forgot us
                health_.setServing(false);
                continue;
            }
            if (status.error_code() == grpc::StatusCode::UNAUTHENTICATED)
                throw WorkerRefused("the coordinator refused a lease: " + rpc::describe(status));
            spdlog::warn("lease failed: {}; retrying", rpc::describe(status));
            sleepUnlessStopping(500ms);
            continue;
        }
        if (reply.leases_size() == 0) {
            sleepUnlessStopping(std::chrono::milliseconds(std::max<uint32_t>(reply.retry_after_ms(), 20)));
            continue;
        }
        std::vector<std::string> unfinished;
        std::string failure;  // why leases are given back, if not for stopping
        for (const auto& lease : reply.leases()) {
            if (stopping_ || killed_) {
                unfinished.push_back(lease.lease_id());
                continue;
            }
            std::string assetsBytes;
            for (const auto& job : reply.jobs())
                if (job.job_id() == lease.job_id()) job.SerializeToString(&assetsBytes);
            std::shared_ptr<const JobContext> job;
            try {
                job = loadJob(lease.job_id(), assetsBytes);
            } catch (const std::exception& e) {
                spdlog::error("job {}: cannot load: {}", lease.job_id(), e.what());
                failure = std::string("cannot load the job: ") + e.what();
                unfinished.push_back(lease.lease_id());
                sleepUnlessStopping(1s);
                continue;
            }
            const TileRect tile{int(lease.tile().x0()), int(lease.tile().y0()), int(lease.tile().x1()),
                                int(lease.tile().y1())};
            const auto start = std::chrono::steady_clock::now();
            TileSums shaded;
            try {
                // The lease's sample passes: all of them at once, or one pass of a time-limited job.
                shaded = job->shader->shadeTile(tile, int(std::min<uint32_t>(lease.first_pass(), kMaxPasses)),
                                                int(std::min<uint32_t>(lease.pass_count(), kMaxPasses)));
            } catch (const std::exception& e) {
                spdlog::error("job {}: shading a tile failed: {}", lease.job_id(), e.what());
                failure = e.what();
                unfinished.push_back(lease.lease_id());
                continue;
            }
            v1::TileResult result;
            result.set_worker_id(request.worker_id());
            result.set_lease_id(lease.lease_id());
            result.set_job_id(lease.job_id());
            *result.mutable_tile() = lease.tile();
            result.set_first_pass(lease.first_pass());
            result.set_pass_count(lease.pass_count());
            for (size_t l = 0; l < shaded.sums.layers.size(); ++l) {  // sample sums, resolved by the coordinator
                auto* layer = result.add_layers();
                layer->set_name(l == 0 ? "" : job->shader->layerNames()[l - 1]);
                layer->set_per_pixel(shaded.sums.perPixel[l] != 0);
                const auto& pixels = shaded.sums.layers[l].pixels();
                layer->set_rgb(reinterpret_cast<const char*>(pixels.data()), pixels.size() * sizeof(Rgb));
            }
            result.set_bound_exceeded(shaded.sums.boundExceeded);
            result.set_bounded_estimates(shaded.sums.boundedEstimates);
            result.set_seconds(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
            for (int attempt = 0; attempt < 5 && !killed_; ++attempt) {
                grpc::ClientContext submitContext;
                rpc::prepareContext(submitContext, options_.token, 60s);
                v1::SubmitTileReply submitted;
                const grpc::Status s = stub->SubmitTile(&submitContext, result, &submitted);
                if (s.ok()) {
                    std::lock_guard lock(mutex_);
                    ++statistics_.tilesSubmitted;
                    if (submitted.accepted()) ++statistics_.tilesAccepted;
                    else spdlog::debug("tile not taken: {}", submitted.reason());
                    break;
                }
                spdlog::warn("submitting a tile failed: {}", rpc::describe(s));
                if (!retryable(s)) break;
                std::this_thread::sleep_for(200ms);
            }
        }
        if (!unfinished.empty() && !killed_) {
            grpc::ClientContext releaseContext;
            rpc::prepareContext(releaseContext, options_.token, 5s);
            v1::ReleaseRequest release;
            release.set_worker_id(request.worker_id());
            release.set_failure(failure);
            for (const auto& id : unfinished) release.add_lease_ids(id);
            v1::ReleaseReply released;
            (void)stub->ReleaseLeases(&releaseContext, release, &released);
        }
    }
}

}  // namespace vrl::worker
