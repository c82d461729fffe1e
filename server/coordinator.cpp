#include "server/coordinator.h"

#include "proto/job_scene.h"
#include "proto/rpc_common.h"
#include "proto/scene_bundle.h"
#include "render/exr_io.h"
#include "render/light_tree_io.h"
#include "render/scene_error.h"
#include "render/timing.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <set>

namespace vrl::server {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

bool isTerminal(v1::JobState state) {
    return state == v1::JOB_STATE_DONE || state == v1::JOB_STATE_FAILED || state == v1::JOB_STATE_CANCELLED;
}

void writeFileAtomically(const fs::path& path, const std::string& bytes) {
    const fs::path temporary = path.string() + "." + rpc::randomHex(8) + ".tmp";  // concurrent writers never share one
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out.write(bytes.data(), std::streamsize(bytes.size()));
        if (!out) throw std::runtime_error("cannot write '" + temporary.string() + "' (disk full?)");
    }
    fs::rename(temporary, path);
}

bool validHash(const std::string& sha256) {
    return sha256.size() == 64 &&
           std::all_of(sha256.begin(), sha256.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

// Refuses (InvalidArgument) a missing or malformed SHA-256 in the field `what`.
void requireHash(const std::string& sha256, const char* what) {
    if (sha256.empty())
        throw ServiceError(ErrorKind::InvalidArgument, std::string(what) + " is required (a SHA-256: 64 lowercase hex digits)");
    if (!validHash(sha256))
        throw ServiceError(ErrorKind::InvalidArgument, std::string(what) + " '" + rpc::abbreviate(sha256) +
                                                           "' is not a SHA-256 (64 lowercase hex digits)");
}

void requireWorkerId(const std::string& workerId) {
    if (workerId.empty())
        throw ServiceError(ErrorKind::InvalidArgument, "worker_id is required (the id Register returned)");
}

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

constexpr size_t kMaxMessageBytes = 4096;  // a job's failure message as stored and shown

}  // namespace

struct Coordinator::Job {
    std::string id;
    v1::JobSpec spec;
    uint64_t sequence = 0;
    fs::path dir;
    v1::JobState state = v1::JOB_STATE_QUEUED;
    std::string message;
    uint64_t version = 0;
    double preparingFraction = 0.0;
    std::vector<std::pair<std::string, double>> phases;
    // Set once prepared:
    int width = 0, height = 0;
    std::vector<TileRect> tiles;
    std::map<std::pair<int, int>, uint32_t> tileAt;  // (x0, y0) -> tile
    std::vector<std::string> layerNames;
    std::map<std::string, std::string> sceneNotes;  // EXR metadata: approximations, ignored plugins
    v1::JobAssets assets;
    std::deque<uint32_t> pending;  // may hold tiles done since they were queued: skipped when popped
    std::vector<uint8_t> queued;   // tile is in `pending`
    std::vector<uint8_t> done;
    std::vector<int> rejections;
    uint32_t doneCount = 0;
    std::vector<Image> layers;
    uint64_t boundExceeded = 0, boundedEstimates = 0;
    RenderStatistics renderStatistics;
    Clock::time_point renderStart;
    uint32_t doneAtStart = 0;  // tiles restored from the checkpoint
    struct WorkerShare {
        uint64_t tiles = 0, pixels = 0;
        double seconds = 0.0;
    };
    std::map<std::string, WorkerShare> workers;  // by worker name
    std::ofstream checkpoint;
};

Coordinator::Coordinator(CoordinatorOptions options) : options_(std::move(options)) {
    fs::create_directories(options_.stateDir / "bundles");
    fs::create_directories(options_.stateDir / "jobs");
    loadState();
    preparer_ = std::thread([this] { prepareLoop(); });
    reaper_ = std::thread([this] { reaperLoop(); });
}

Coordinator::~Coordinator() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    preparer_.join();
    reaper_.join();
}

// ------------------------------------------------------------------ state on disk

void Coordinator::loadState() {
    std::vector<std::unique_ptr<Job>> loaded;
    for (const auto& entry : fs::directory_iterator(options_.stateDir / "jobs")) {
        if (!entry.is_directory()) continue;
        auto job = std::make_unique<Job>();
        job->id = entry.path().filename().string();
        job->dir = entry.path();
        std::string bytes;
        try {
            bytes = rpc::readFileText((job->dir / "spec.pb").string());
        } catch (const std::exception&) {
            spdlog::warn("state: skipping '{}' (no spec.pb)", job->dir.string());
            continue;
        }
        if (!job->spec.ParseFromString(bytes)) {
            spdlog::warn("state: skipping '{}' (corrupt spec.pb)", job->dir.string());
            continue;
        }
        if (fs::exists(job->dir / "record.pb")) {
            v1::JobProgress record;
            if (record.ParseFromString(rpc::readFileText((job->dir / "record.pb").string()))) {
                job->state = record.state();
                job->message = record.message();
                for (const auto& phase : record.phases()) job->phases.emplace_back(phase.phase(), phase.seconds());
                job->tiles.resize(record.tiles_total());
                job->doneCount = record.tiles_done();
            }
        }
        loaded.push_back(std::move(job));
    }
    // Resume in the order of the job ids' creation time (their directory's mtime).
    std::sort(loaded.begin(), loaded.end(), [](const auto& a, const auto& b) {
        return fs::last_write_time(a->dir / "spec.pb") < fs::last_write_time(b->dir / "spec.pb");
    });
    size_t resumed = 0;
    for (auto& job : loaded) {
        job->sequence = nextSequence_++;
        if (!isTerminal(job->state)) {
            job->state = v1::JOB_STATE_QUEUED;
            ++resumed;
        }
        jobs_.emplace(job->id, std::move(job));
    }
    if (!jobs_.empty())
        spdlog::info("state: {} jobs in '{}', {} to resume", jobs_.size(), options_.stateDir.string(), resumed);
}

// ------------------------------------------------------------------ bundles and jobs

bool Coordinator::hasBundle(const std::string& sha256) const {
    requireHash(sha256, "sha256");
    return fs::exists(options_.stateDir / "bundles" / (sha256 + ".bundle"));
}

void Coordinator::storeBundle(const std::string& sha256, const std::string& blob) {
    requireHash(sha256, "the bundle's sha256");
    const std::string actual = rpc::sha256Hex(blob);
    if (actual != sha256)
        throw ServiceError(ErrorKind::InvalidArgument,
                           "the uploaded bundle's SHA-256 is " + actual + ", not the announced " + sha256);
    v1::SceneBundle bundle;
    try {
        bundle = rpc::parseBundleBlob(blob, options_.limits);
    } catch (const rpc::BundleError& e) {
        throw ServiceError(ErrorKind::InvalidArgument, std::string("refused scene bundle: ") + e.what());
    }
    const fs::path directory = options_.stateDir / "bundles" / sha256;
    if (!fs::exists(directory)) rpc::extractBundle(bundle, directory);
    writeFileAtomically(options_.stateDir / "bundles" / (sha256 + ".bundle"), blob);
    spdlog::info("bundle {}: {} files, {} bytes", sha256.substr(0, 12), bundle.entries_size(), blob.size());
}

std::string Coordinator::submitJob(const v1::JobSpec& spec) {
    try {
        rpc::validateJobSpec(spec, options_.limits);
    } catch (const rpc::JobSpecError& e) {
        throw ServiceError(ErrorKind::InvalidArgument, e.what());
    }
    requireHash(spec.bundle_sha256(), "bundle_sha256");
    if (!hasBundle(spec.bundle_sha256()))
        throw ServiceError(ErrorKind::NotFound, "no scene bundle " + spec.bundle_sha256() + " here; upload it first");
    auto job = std::make_unique<Job>();
    job->id = "job-" + rpc::randomHex(12);
    job->spec = spec;
    job->dir = options_.stateDir / "jobs" / job->id;
    if (draining()) throw ServiceError(ErrorKind::FailedPrecondition, "the coordinator is shutting down");
    fs::create_directories(job->dir);
    std::string bytes;
    spec.SerializeToString(&bytes);
    writeFileAtomically(job->dir / "spec.pb", bytes);
    const std::string id = job->id;
    {
        std::lock_guard lock(mutex_);
        job->sequence = nextSequence_++;
        jobs_.emplace(id, std::move(job));
    }
    changed_.notify_all();
    spdlog::info("{}: submitted ('{}', {}, priority {})", id, spec.name(), spec.parameters().method(), spec.priority());
    return id;
}

Coordinator::Job& Coordinator::findJob(const std::string& jobId) const {
    if (jobId.empty()) throw ServiceError(ErrorKind::InvalidArgument, "job_id is required");
    const auto it = jobs_.find(jobId);
    if (it == jobs_.end()) throw ServiceError(ErrorKind::NotFound, "no job '" + rpc::abbreviate(jobId) + "'");
    return *it->second;
}

v1::JobProgress Coordinator::progressOf(const Job& job) const {
    v1::JobProgress p;
    p.set_job_id(job.id);
    p.set_state(job.state);
    p.set_name(job.spec.name());
    p.set_priority(job.spec.priority());
    p.set_message(job.message);
    p.set_tiles_total(uint32_t(job.tiles.size()));
    p.set_tiles_done(job.doneCount);
    p.set_preparing_fraction(job.preparingFraction);
    double eta = -1.0;
    if (job.state == v1::JOB_STATE_RENDERING && job.doneCount > job.doneAtStart) {
        const double elapsed = secondsSince(job.renderStart);
        eta = elapsed / double(job.doneCount - job.doneAtStart) * double(job.tiles.size() - job.doneCount);
    } else if (job.state == v1::JOB_STATE_DONE) {
        eta = 0.0;
    }
    p.set_eta_seconds(eta);
    for (const auto& [name, share] : job.workers) {
        auto* w = p.add_workers();
        w->set_worker(name);
        w->set_tiles(share.tiles);
        w->set_pixels_per_second(share.seconds > 0.0 ? double(share.pixels) / share.seconds : 0.0);
    }
    for (const auto& [phase, seconds] : job.phases) {
        auto* t = p.add_phases();
        t->set_phase(phase);
        t->set_seconds(seconds);
    }
    return p;
}

v1::JobProgress Coordinator::jobProgress(const std::string& jobId) const {
    std::lock_guard lock(mutex_);
    return progressOf(findJob(jobId));
}

uint64_t Coordinator::waitForChange(const std::string& jobId, uint64_t seen, std::chrono::milliseconds timeout) const {
    std::unique_lock lock(mutex_);
    const Job& job = findJob(jobId);
    changed_.wait_for(lock, timeout, [&] { return job.version != seen || stopping_; });
    return job.version;
}

std::vector<v1::JobProgress> Coordinator::listJobs() const {
    std::lock_guard lock(mutex_);
    std::vector<const Job*> ordered;
    for (const auto& [id, job] : jobs_) ordered.push_back(job.get());
    std::sort(ordered.begin(), ordered.end(), [](const Job* a, const Job* b) { return a->sequence < b->sequence; });
    std::vector<v1::JobProgress> out;
    for (const Job* job : ordered) out.push_back(progressOf(*job));
    return out;
}

v1::JobState Coordinator::cancelJob(const std::string& jobId) {
    std::lock_guard lock(mutex_);
    Job& job = findJob(jobId);
    if (!isTerminal(job.state)) endJob(job, v1::JOB_STATE_CANCELLED, "cancelled by a client");
    return job.state;
}

fs::path Coordinator::imageFile(const std::string& jobId) const {
    std::lock_guard lock(mutex_);
    const Job& job = findJob(jobId);
    if (job.state != v1::JOB_STATE_DONE)
        throw ServiceError(ErrorKind::FailedPrecondition, "job '" + jobId + "' has no image yet (state " +
                                                              v1::JobState_Name(job.state) + ")");
    return job.dir / "image.exr";
}

void Coordinator::touch(Job& job) {
    ++job.version;
    changed_.notify_all();
}

void Coordinator::endJob(Job& job, v1::JobState state, const std::string& message) {
    job.state = state;
    job.message = rpc::abbreviate(message, kMaxMessageBytes);  // shown in every listing: bounded
    job.pending.clear();
    for (auto it = leases_.begin(); it != leases_.end();)
        it = it->second.jobId == job.id ? leases_.erase(it) : std::next(it);
    job.layers.clear();
    job.layers.shrink_to_fit();
    if (job.checkpoint.is_open()) job.checkpoint.close();
    std::error_code error;
    fs::remove(job.dir / "tiles.log", error);
    const v1::JobProgress record = progressOf(job);
    std::string bytes;
    record.SerializeToString(&bytes);
    try {
        writeFileAtomically(job.dir / "record.pb", bytes);
    } catch (const std::exception& e) {
        spdlog::error("{}: cannot record its end: {}", job.id, e.what());
    }
    pruneAssets();
    touch(job);
    if (state == v1::JOB_STATE_FAILED) spdlog::error("{}: failed: {}", job.id, message);
    else spdlog::info("{}: {}", job.id, v1::JobState_Name(state));
}

void Coordinator::pruneAssets() {
    std::set<std::string> live;
    for (const auto& [id, job] : jobs_) {
        if (job->state != v1::JOB_STATE_RENDERING) continue;
        live.insert(job->spec.bundle_sha256());
        live.insert(job->assets.lights_sha256());
    }
    for (auto it = assets_.begin(); it != assets_.end();) it = live.count(it->first) ? std::next(it) : assets_.erase(it);
}

// ------------------------------------------------------------------ preparation

void Coordinator::prepareLoop() {
    while (true) {
        Job* next = nullptr;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] {
                if (stopping_) return true;
                for (const auto& [id, job] : jobs_)
                    if (job->state == v1::JOB_STATE_QUEUED) return true;
                return false;
            });
            if (stopping_) return;
            for (const auto& [id, job] : jobs_) {
                if (job->state != v1::JOB_STATE_QUEUED) continue;
                if (!next || job->spec.priority() > next->spec.priority() ||
                    (job->spec.priority() == next->spec.priority() && job->sequence < next->sequence))
                    next = job.get();
            }
            next->state = v1::JOB_STATE_PREPARING;
            touch(*next);
        }
        prepare(*next);  // jobs are never erased, so the pointer stays valid
    }
}

void Coordinator::prepare(Job& job) {
    const auto start = Clock::now();
    std::vector<std::pair<std::string, double>> phases;
    try {
        const std::string& sha = job.spec.bundle_sha256();
        auto blob = std::make_shared<const std::string>(
            rpc::readFileText((options_.stateDir / "bundles" / (sha + ".bundle")).string()));
        const v1::SceneBundle bundle = rpc::parseBundleBlob(*blob, options_.limits);
        const fs::path directory = options_.stateDir / "bundles" / sha;
        if (!fs::exists(directory)) rpc::extractBundle(bundle, directory);
        auto t0 = Clock::now();
        rpc::JobScene scene = rpc::loadJobScene(directory, directory / bundle.scene_path(), job.spec, options_.limits);
        phases.emplace_back("load scene", secondsSince(t0));
        std::map<std::string, std::string> sceneNotes;
        addSceneNotes(scene.scene->description(), sceneNotes);
        RenderStatistics statistics;
        t0 = Clock::now();
        const RenderLights lights = prepareLights(*scene.scene, scene.settings, [&](const char*, double f) {
            std::lock_guard lock(mutex_);
            if (std::abs(f - job.preparingFraction) >= 0.01 || f >= 1.0) {
                job.preparingFraction = f;
                touch(job);
            }
        }, &statistics);
        if (statistics.vrlCount > 0) {
            phases.emplace_back("light tracing", statistics.tracingSeconds);
            if (statistics.treeSeconds > 0.0) phases.emplace_back("light tree", statistics.treeSeconds);
        }
        t0 = Clock::now();
        std::shared_ptr<const std::string> lightsBlob;
        if (lights.tree.root() >= 0) {
            const auto bytes = serializeLightTree(lights.tree);
            lightsBlob = std::make_shared<const std::string>(bytes.begin(), bytes.end());
        } else if (!lights.vrls.vrls.empty()) {
            const auto bytes = serializeVrlSet(lights.vrls);
            lightsBlob = std::make_shared<const std::string>(bytes.begin(), bytes.end());
        }
        const std::string lightsSha = lightsBlob ? rpc::sha256Hex(*lightsBlob) : "";
        if (lightsBlob) phases.emplace_back("serialise lights", secondsSince(t0));
        const auto layerNames = renderLayerNames(scene.settings);
        const uint64_t tileSide = uint64_t(scene.settings.tileSize);
        const uint64_t tileCount = ((uint64_t(scene.width) + tileSide - 1) / tileSide) *
                                   ((uint64_t(scene.height) + tileSide - 1) / tileSide);
        if (tileCount > options_.limits.maxTiles)
            throw rpc::JobSpecError("the image would have " + std::to_string(tileCount) + " tiles, over the limit of " +
                                    std::to_string(options_.limits.maxTiles) + "; use a larger tile size");
        const auto tiles = imageTiles(scene.width, scene.height, scene.settings.tileSize);

        // Accepted tiles from before a restart.
        std::vector<v1::TileResult> replay;
        if (fs::exists(job.dir / "tiles.log")) {
            uint64_t good = 0;  // bytes of whole records
            {
                std::ifstream in(job.dir / "tiles.log", std::ios::binary);
                while (true) {
                    uint32_t size = 0;
                    if (!in.read(reinterpret_cast<char*>(&size), 4) || size > uint32_t(rpc::kMaxMessageBytes)) break;
                    std::string record(size, '\0');
                    if (!in.read(record.data(), size)) break;  // a record cut short by a crash
                    v1::TileResult result;
                    if (!result.ParseFromString(record)) break;
                    replay.push_back(std::move(result));
                    good += 4 + uint64_t(size);
                }
            }
            fs::resize_file(job.dir / "tiles.log", good);  // new records go right after the last whole one
        }

        std::lock_guard lock(mutex_);
        if (job.state != v1::JOB_STATE_PREPARING) return;  // cancelled meanwhile
        job.width = scene.width;
        job.height = scene.height;
        job.tiles = tiles;
        for (uint32_t t = 0; t < tiles.size(); ++t) job.tileAt[{tiles[t].x0, tiles[t].y0}] = t;
        job.layerNames = layerNames;
        job.sceneNotes = std::move(sceneNotes);
        job.done.assign(tiles.size(), 0);
        job.queued.assign(tiles.size(), 0);
        job.rejections.assign(tiles.size(), 0);
        job.doneCount = 0;
        job.layers.assign(1 + layerNames.size(), Image(scene.width, scene.height));
        job.renderStatistics = statistics;
        job.assets.set_job_id(job.id);
        *job.assets.mutable_spec() = job.spec;
        job.assets.set_width(uint32_t(scene.width));
        job.assets.set_height(uint32_t(scene.height));
        job.assets.set_samples_per_pixel(scene.settings.samplesPerPixel);
        job.assets.set_max_depth(scene.settings.maxDepth);
        job.assets.set_lights_sha256(lightsSha);
        job.assets.set_lights_size(lightsBlob ? lightsBlob->size() : 0);
        job.assets.set_bundle_size(blob->size());
        job.assets.clear_layer_names();
        for (const auto& name : layerNames) job.assets.add_layer_names(name);
        assets_[sha] = blob;
        if (lightsBlob) assets_[lightsSha] = lightsBlob;
        job.phases = phases;
        job.phases.emplace_back("prepare (total)", secondsSince(start));
        job.state = v1::JOB_STATE_RENDERING;
        for (const auto& result : replay) (void)applyTile(job, result, true);
        job.doneAtStart = job.doneCount;
        for (uint32_t t = 0; t < tiles.size(); ++t)
            if (!job.done[t]) {
                job.pending.push_back(t);
                job.queued[t] = 1;
            }
        job.checkpoint.open(job.dir / "tiles.log", std::ios::binary | std::ios::app);
        job.renderStart = Clock::now();
        spdlog::info("{}: prepared in {:.3f} s: {}x{}, {} tiles ({} restored), {} VRLs, lights blob {} bytes", job.id,
                     secondsSince(start), scene.width, scene.height, tiles.size(), job.doneCount,
                     statistics.vrlCount, lightsBlob ? lightsBlob->size() : 0);
        touch(job);
        if (job.doneCount == tiles.size()) finishJob(job);
    } catch (const std::exception& e) {
        std::lock_guard lock(mutex_);
        if (job.state == v1::JOB_STATE_PREPARING) endJob(job, v1::JOB_STATE_FAILED, e.what());
    }
}

// ------------------------------------------------------------------ workers

v1::RegisterReply Coordinator::registerWorker(const v1::RegisterRequest& request) {
    if (request.protocol_version() != rpc::kProtocolVersion || request.program_version() != VRL_VERSION)
        throw ServiceError(ErrorKind::FailedPrecondition,
                           "version mismatch: the worker runs vrlcuts " + rpc::abbreviate(request.program_version()) +
                               " (protocol " + std::to_string(request.protocol_version()) +
                               ") but this coordinator runs vrlcuts " + VRL_VERSION + " (protocol " +
                               std::to_string(rpc::kProtocolVersion) + "); run workers of the coordinator's release");
    if (request.threads() == 0 || request.threads() > 4096)
        throw ServiceError(ErrorKind::InvalidArgument, "a worker must announce 1..4096 threads");
    std::lock_guard lock(mutex_);
    const std::string id = "w" + std::to_string(++nextWorker_) + "-" + rpc::randomHex(6);
    WorkerRecord& worker = workers_[id];
    worker.name = request.name().empty() ? id : request.name().substr(0, 128);
    worker.threads = request.threads();
    worker.lastHeartbeat = Clock::now();
    spdlog::info("worker {} ('{}', {} threads) registered", id, worker.name, worker.threads);
    v1::RegisterReply reply;
    reply.set_worker_id(id);
    reply.set_heartbeat_interval_ms(uint32_t(options_.heartbeatInterval.count()));
    reply.set_coordinator_version(VRL_VERSION);
    return reply;
}

v1::HeartbeatReply Coordinator::heartbeat(const std::string& workerId) {
    requireWorkerId(workerId);
    std::lock_guard lock(mutex_);
    v1::HeartbeatReply reply;
    const auto it = workers_.find(workerId);
    reply.set_known(it != workers_.end());
    if (it != workers_.end()) it->second.lastHeartbeat = Clock::now();
    reply.set_draining(draining_);
    return reply;
}

v1::LeaseReply Coordinator::leaseTiles(const v1::LeaseRequest& request) {
    const auto start = Clock::now();
    requireWorkerId(request.worker_id());
    std::lock_guard lock(mutex_);
    const auto worker = workers_.find(request.worker_id());
    if (worker == workers_.end())
        throw ServiceError(ErrorKind::FailedPrecondition,
                           "unknown worker '" + rpc::abbreviate(request.worker_id()) + "'; register again");
    worker->second.lastHeartbeat = Clock::now();
    v1::LeaseReply reply;
    reply.set_draining(draining_);
    if (draining_) {
        reply.set_retry_after_ms(1000);
        return reply;
    }
    std::vector<Job*> ready;
    for (const auto& [id, job] : jobs_)
        if (job->state == v1::JOB_STATE_RENDERING && !job->pending.empty()) ready.push_back(job.get());
    std::sort(ready.begin(), ready.end(), [](const Job* a, const Job* b) {
        return a->spec.priority() != b->spec.priority() ? a->spec.priority() > b->spec.priority()
                                                        : a->sequence < b->sequence;
    });
    const uint32_t wanted = std::clamp<uint32_t>(request.max_tiles(), 1, 64);
    std::set<std::string> described;
    for (Job* job : ready) {
        while (uint32_t(reply.leases_size()) < wanted && !job->pending.empty()) {
            const uint32_t tile = job->pending.front();
            job->pending.pop_front();
            job->queued[tile] = 0;
            if (job->done[tile]) continue;  // accepted since it was queued
            const std::string leaseId = job->id + ":" + std::to_string(tile) + ":" + std::to_string(++nextLease_);
            leases_[leaseId] = Lease{job->id, tile, request.worker_id(), Clock::now() + options_.leaseTimeout};
            auto* lease = reply.add_leases();
            lease->set_lease_id(leaseId);
            lease->set_job_id(job->id);
            const TileRect& r = job->tiles[tile];
            lease->mutable_tile()->set_x0(r.x0);
            lease->mutable_tile()->set_y0(r.y0);
            lease->mutable_tile()->set_x1(r.x1);
            lease->mutable_tile()->set_y1(r.y1);
            lease->set_deadline_ms(uint32_t(options_.leaseTimeout.count()));
            if (described.insert(job->id).second) *reply.add_jobs() = job->assets;
            ++statistics_.tilesLeased;
        }
        if (uint32_t(reply.leases_size()) >= wanted) break;
    }
    if (reply.leases_size() == 0) reply.set_retry_after_ms(100);
    statistics_.leaseSeconds += secondsSince(start);
    return reply;
}

std::shared_ptr<const std::string> Coordinator::asset(const std::string& sha256) const {
    requireHash(sha256, "sha256");
    std::lock_guard lock(mutex_);
    const auto it = assets_.find(sha256);
    if (it == assets_.end()) throw ServiceError(ErrorKind::NotFound, "no live job uses asset " + sha256);
    return it->second;
}

std::string Coordinator::applyTile(Job& job, const v1::TileResult& result, bool replay) {
    if (!(result.seconds() >= 0.0 && std::isfinite(result.seconds())))
        return "seconds must be finite and >= 0, got " + std::to_string(result.seconds());
    const auto& t = result.tile();
    const auto at = job.tileAt.find({int(t.x0()), int(t.y0())});
    if (at == job.tileAt.end())
        return "tile (" + std::to_string(t.x0()) + ", " + std::to_string(t.y0()) + ") is not a tile of this job's " +
               std::to_string(job.width) + "x" + std::to_string(job.height) + " image";
    const uint32_t tile = at->second;
    const TileRect& rect = job.tiles[tile];
    if (t.x1() != uint32_t(rect.x1) || t.y1() != uint32_t(rect.y1))
        return "tile bounds [" + std::to_string(t.x0()) + ", " + std::to_string(t.x1()) + ") x [" +
               std::to_string(t.y0()) + ", " + std::to_string(t.y1()) + ") differ from the job's tiling";
    if (job.done[tile]) {
        ++statistics_.duplicatesDropped;
        return "duplicate: this tile was already accepted";
    }
    if (size_t(result.layers_size()) != job.layers.size())
        return "wrong number of layers: " + std::to_string(result.layers_size()) + ", expected " +
               std::to_string(job.layers.size());
    const size_t floats = size_t(rect.width()) * rect.height() * 3;
    for (int l = 0; l < result.layers_size(); ++l) {
        const auto& layer = result.layers(l);
        const std::string& expected = l == 0 ? std::string() : job.layerNames[size_t(l - 1)];
        if (layer.name() != expected)
            return "layer " + std::to_string(l) + " is '" + rpc::abbreviate(layer.name()) + "', expected '" + expected +
                   "'";
        if (layer.rgb().size() != floats * sizeof(float))
            return "layer '" + layer.name() + "' has the wrong size: " + std::to_string(layer.rgb().size()) +
                   " bytes, expected " + std::to_string(floats * sizeof(float)) + " (" + std::to_string(rect.width()) +
                   "x" + std::to_string(rect.height()) + " RGB float32)";
        for (size_t i = 0; i < floats; ++i) {
            float v;
            std::memcpy(&v, layer.rgb().data() + i * sizeof(float), sizeof v);
            if (!std::isfinite(v)) return "layer '" + layer.name() + "' holds a non-finite value";
        }
    }
    for (int l = 0; l < result.layers_size(); ++l) {
        const char* data = result.layers(l).rgb().data();
        for (int y = 0; y < rect.height(); ++y)
            std::memcpy(static_cast<void*>(&job.layers[size_t(l)].at(rect.x0, rect.y0 + y)), data + size_t(y) * rect.width() * 3 * sizeof(float),
                        size_t(rect.width()) * 3 * sizeof(float));
    }
    job.done[tile] = 1;
    ++job.doneCount;
    job.boundExceeded += result.bound_exceeded();
    job.boundedEstimates += result.bounded_estimates();
    if (!replay) {
        std::string name = result.worker_id();
        if (const auto w = workers_.find(result.worker_id()); w != workers_.end()) name = w->second.name;
        auto& share = job.workers[name];
        ++share.tiles;
        share.pixels += uint64_t(rect.width()) * rect.height();
        share.seconds += std::max(0.0, result.seconds());
        if (job.checkpoint.is_open()) {
            std::string bytes;
            result.SerializeToString(&bytes);
            const uint32_t size = uint32_t(bytes.size());
            job.checkpoint.write(reinterpret_cast<const char*>(&size), 4);
            job.checkpoint.write(bytes.data(), std::streamsize(bytes.size()));
            job.checkpoint.flush();
        }
    }
    return {};
}

v1::SubmitTileReply Coordinator::submitTile(const v1::TileResult& result, bool* malformed) {
    const auto start = Clock::now();
    if (malformed) *malformed = false;
    requireWorkerId(result.worker_id());
    std::lock_guard lock(mutex_);
    v1::SubmitTileReply reply;
    Job& job = findJob(result.job_id());
    if (!workers_.count(result.worker_id()))
        throw ServiceError(ErrorKind::FailedPrecondition,
                           "unknown worker '" + rpc::abbreviate(result.worker_id()) + "'; register again");
    // The lease counts only if it is this worker's lease on this job's tile.
    auto leaseIt = leases_.find(result.lease_id());
    if (leaseIt != leases_.end()) {
        const Lease& lease = leaseIt->second;
        const auto at = job.tileAt.find({int(result.tile().x0()), int(result.tile().y0())});
        if (lease.jobId != job.id || lease.workerId != result.worker_id() || at == job.tileAt.end() ||
            at->second != lease.tile)
            leaseIt = leases_.end();
    }
    if (job.state != v1::JOB_STATE_RENDERING) {
        if (leaseIt != leases_.end()) leases_.erase(leaseIt);
        reply.set_reason("job is " + v1::JobState_Name(job.state));
        return reply;
    }
    std::string refused;
    if (leaseIt == leases_.end()) {  // no live lease: a late result still counts, one for a lease never issued not
        const auto at = job.tileAt.find({int(result.tile().x0()), int(result.tile().y0())});
        if (at != job.tileAt.end() && !leaseWasIssued(result.lease_id(), job.id, at->second, nextLease_))
            refused = result.lease_id().empty() ? "lease_id is required"
                                                : "lease '" + rpc::abbreviate(result.lease_id()) +
                                                      "' was never issued for tile " + std::to_string(at->second) +
                                                      " of this job";
    }
    if (refused.empty()) refused = applyTile(job, result, false);
    if (refused.empty()) {
        reply.set_accepted(true);
        ++statistics_.tilesAccepted;
        if (leaseIt != leases_.end()) leases_.erase(leaseIt);  // other leases on the tile expire harmlessly
        touch(job);
        if (job.doneCount == job.tiles.size()) finishJob(job);
    } else {
        reply.set_reason(refused);
        if (refused.rfind("duplicate", 0) != 0) {
            if (malformed) *malformed = true;
            ++statistics_.tilesRejected;
            spdlog::warn("{}: tile result from {} refused: {}", job.id, result.worker_id(), refused);
            if (leaseIt != leases_.end()) {
                const uint32_t tile = leaseIt->second.tile;
                requeue(result.lease_id(), false);
                countFailure(job, tile, refused);
            }
        } else if (leaseIt != leases_.end()) {
            leases_.erase(leaseIt);
        }
    }
    statistics_.submitSeconds += secondsSince(start);
    return reply;
}

void Coordinator::countFailure(Job& job, uint32_t tile, const std::string& reason) {
    if (job.state != v1::JOB_STATE_RENDERING || ++job.rejections[tile] < options_.maxTileRejections) return;
    endJob(job, v1::JOB_STATE_FAILED,
           "tile " + std::to_string(tile) + " failed " + std::to_string(job.rejections[tile]) + " times (last: " +
               reason + ")");
}

void Coordinator::requeue(const std::string& leaseId, bool front) {
    const auto it = leases_.find(leaseId);
    if (it == leases_.end()) return;
    const Lease lease = it->second;
    leases_.erase(it);
    const auto job = jobs_.find(lease.jobId);
    if (job == jobs_.end() || job->second->state != v1::JOB_STATE_RENDERING || job->second->done[lease.tile]) return;
    Job& owner = *job->second;
    if (owner.queued[lease.tile]) return;
    owner.queued[lease.tile] = 1;
    if (front) owner.pending.push_front(lease.tile);
    else owner.pending.push_back(lease.tile);
}

void Coordinator::releaseLeases(const v1::ReleaseRequest& request) {
    requireWorkerId(request.worker_id());
    const std::string failure = rpc::abbreviate(request.failure(), 1024);
    std::lock_guard lock(mutex_);
    for (const auto& id : request.lease_ids()) {
        const auto it = leases_.find(id);
        if (it == leases_.end() || it->second.workerId != request.worker_id()) continue;
        const std::string jobId = it->second.jobId;
        const uint32_t tile = it->second.tile;
        requeue(id, request.failure().empty());
        if (!request.failure().empty())
            if (const auto job = jobs_.find(jobId); job != jobs_.end())
                countFailure(*job->second, tile, "a worker could not shade it: " + failure);
    }
}

void Coordinator::reaperLoop() {
    const auto period = std::clamp(options_.leaseTimeout / 4, std::chrono::milliseconds(20), std::chrono::milliseconds(250));
    std::unique_lock lock(mutex_);
    while (!stopping_) {
        changed_.wait_for(lock, period);
        if (stopping_) break;
        const auto now = Clock::now();
        for (auto it = workers_.begin(); it != workers_.end();) {
            if (now - it->second.lastHeartbeat > options_.heartbeatTimeout) {
                spdlog::warn("worker {} ('{}') missed its heartbeats; its leases go back to the queue", it->first,
                             it->second.name);
                it = workers_.erase(it);
            } else {
                ++it;
            }
        }
        std::vector<std::string> expired;
        for (const auto& [id, lease] : leases_)
            if (lease.deadline < now || !workers_.count(lease.workerId)) expired.push_back(id);
        for (const auto& id : expired) {
            ++statistics_.leasesExpired;
            requeue(id);
        }
    }
}

// ------------------------------------------------------------------ the end of a job

void Coordinator::finishJob(Job& job) {
    RenderStatistics stats = job.renderStatistics;
    ImageSet images = assembleImageSet(std::move(job.layers), job.layerNames, &stats);
    job.layers.clear();
    stats.boundExceeded = job.boundExceeded;
    stats.boundedEstimates = job.boundedEstimates;
    const auto& p = job.spec.parameters();
    images.metadata["vrl.version"] = VRL_VERSION;
    images.metadata["vrl.job"] = job.id;
    images.metadata["vrl.scene"] = job.spec.name();
    images.metadata["vrl.method"] = p.method();
    images.metadata["vrl.spp"] = std::to_string(job.assets.samples_per_pixel());
    images.metadata["vrl.seed"] = std::to_string(p.seed());
    images.metadata["vrl.maxDepth"] = std::to_string(job.assets.max_depth());
    images.metadata["vrl.jitter"] = p.jitter() ? "true" : "false";
    images.metadata["vrl.workers"] = std::to_string(job.workers.size());
    std::string defines;
    for (const auto& [name, value] : std::map<std::string, std::string>(job.spec.defines().begin(), job.spec.defines().end()))
        defines += (defines.empty() ? "" : " ") + name + "=" + value;
    images.metadata["vrl.defines"] = defines;
    if (!job.spec.medium().empty()) images.metadata["vrl.medium"] = job.spec.medium();
    images.metadata.insert(job.sceneNotes.begin(), job.sceneNotes.end());
    images.metadata["vrl.time.render"] = std::to_string(secondsSince(job.renderStart));
    for (const auto& [phase, seconds] : job.phases) images.metadata["vrl.time." + phase] = std::to_string(seconds);
    if (stats.vrlCount > 0) {
        images.metadata["vrl.vrls"] = std::to_string(stats.vrlCount);
        images.metadata["vrl.lightPaths"] = std::to_string(stats.lightPaths);
    }
    if (usesLightTree(p.method())) {
        images.metadata["vrl.error"] = std::to_string(p.error());
        images.metadata["vrl.meanEval"] = std::to_string(stats.meanEvaluated);
        images.metadata["vrl.meanInter"] = std::to_string(stats.meanIntersected);
        images.metadata["vrl.meanCut"] = std::to_string(stats.meanCutSize);
        images.metadata["vrl.boundExceeded"] = std::to_string(stats.boundExceeded);
    }
    try {
        const fs::path temporary = job.dir / "image.partial.exr";
        writeExr(temporary.string(), images);
        fs::rename(temporary, job.dir / "image.exr");
    } catch (const std::exception& e) {
        endJob(job, v1::JOB_STATE_FAILED, std::string("cannot write the image: ") + e.what());
        return;
    }
    job.phases.emplace_back("render", secondsSince(job.renderStart));
    endJob(job, v1::JOB_STATE_DONE, "");
}

// ------------------------------------------------------------------ shutdown

void Coordinator::beginDrain() {
    std::lock_guard lock(mutex_);
    draining_ = true;
    changed_.notify_all();
}

bool Coordinator::draining() const {
    std::lock_guard lock(mutex_);
    return draining_;
}

size_t Coordinator::activeLeases() const {
    std::lock_guard lock(mutex_);
    return leases_.size();
}

CoordinatorStatistics Coordinator::statistics() const {
    std::lock_guard lock(mutex_);
    return statistics_;
}

}  // namespace vrl::server
