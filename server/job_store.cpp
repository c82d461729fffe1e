#include "server/job_store.h"

#include "service/common/rpc_common.h"
#include "service/common/service_error.h"
#include "service/job/scene_bundle.h"
#include "util/atomic_file.h"
#include "util/hash.h"
#include "util/random_id.h"
#include "util/strings.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <set>

namespace vrl::server {

namespace fs = std::filesystem;
using rpc::ErrorKind;
using rpc::ServiceError;

void requireHash(const std::string& sha256, const char* what) {
    if (sha256.empty())
        throw ServiceError(ErrorKind::InvalidArgument, std::string(what) + " is required (a SHA-256: 64 lowercase hex digits)");
    if (!util::isSha256Hex(sha256))
        throw ServiceError(ErrorKind::InvalidArgument, std::string(what) + " '" + util::abbreviate(sha256) +
                                                           "' is not a SHA-256 (64 lowercase hex digits)");
}

JobStore::JobStore(fs::path stateDir, const rpc::ServiceLimits& limits)
    : stateDir_(std::move(stateDir)), limits_(limits) {
    fs::create_directories(stateDir_ / "bundles");
    fs::create_directories(stateDir_ / "jobs");
    loadState();
}

void JobStore::loadState() {
    std::vector<std::unique_ptr<Job>> loaded;
    for (const auto& entry : fs::directory_iterator(stateDir_ / "jobs")) {
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
                job->submittedUnixMs = record.submitted_unix_ms();
                if (!isTerminal(record.state())) {  // written at submission: only its time counts
                    loaded.push_back(std::move(job));
                    continue;
                }
                job->finishedUnixMs = record.finished_unix_ms();
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
        spdlog::info("state: {} jobs in '{}', {} to resume", jobs_.size(), stateDir_.string(), resumed);
}

// ------------------------------------------------------------------ on disk

bool JobStore::hasBundle(const std::string& sha256) const {
    requireHash(sha256, "sha256");
    return fs::exists(bundleFile(sha256));
}

void JobStore::storeBundle(const std::string& sha256, const std::string& blob) const {
    requireHash(sha256, "the bundle's sha256");
    const std::string actual = util::sha256Hex(blob);
    if (actual != sha256)
        throw ServiceError(ErrorKind::InvalidArgument,
                           "the uploaded bundle's SHA-256 is " + actual + ", not the announced " + sha256);
    v1::SceneBundle bundle;
    try {
        bundle = rpc::parseBundleBlob(blob, limits_);
    } catch (const rpc::BundleError& e) {
        throw ServiceError(ErrorKind::InvalidArgument, std::string("refused scene bundle: ") + e.what());
    }
    const fs::path directory = bundleDirectory(sha256);
    if (!fs::exists(directory)) rpc::extractBundle(bundle, directory);
    util::writeFileAtomically(bundleFile(sha256), blob);
    spdlog::info("bundle {}: {} files, {} bytes", sha256.substr(0, 12), bundle.entries_size(), blob.size());
}

fs::path JobStore::bundleFile(const std::string& sha256) const {
    return stateDir_ / "bundles" / (sha256 + ".bundle");
}

fs::path JobStore::bundleDirectory(const std::string& sha256) const {
    return stateDir_ / "bundles" / sha256;
}

std::unique_ptr<Job> JobStore::newJob(const v1::JobSpec& spec) const {
    auto job = std::make_unique<Job>();
    job->id = "job-" + util::randomHex(12);
    job->submittedUnixMs = unixMillisecondsNow();
    job->spec = spec;
    job->dir = stateDir_ / "jobs" / job->id;
    return job;
}

void JobStore::writeSpec(const Job& job) const {
    fs::create_directories(job.dir);
    std::string bytes;
    job.spec.SerializeToString(&bytes);
    util::writeFileAtomically(job.dir / "spec.pb", bytes);
}

// Each record: its size (4 bytes, host order), then a serialised TileResult.
std::vector<v1::TileResult> JobStore::readCheckpoint(const Job& job) const {
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
    return replay;
}

// ------------------------------------------------------------------ jobs

void JobStore::add(std::unique_ptr<Job> job) {
    job->sequence = nextSequence_++;
    const std::string id = job->id;
    jobs_.emplace(id, std::move(job));
}

Job& JobStore::find(const std::string& jobId) const {
    if (jobId.empty()) throw ServiceError(ErrorKind::InvalidArgument, "job_id is required");
    const auto it = jobs_.find(jobId);
    if (it == jobs_.end()) throw ServiceError(ErrorKind::NotFound, "no job '" + util::abbreviate(jobId) + "'");
    return *it->second;
}

std::vector<const Job*> JobStore::bySequence() const {
    std::vector<const Job*> ordered;
    for (const auto& [id, job] : jobs_) ordered.push_back(job.get());
    std::sort(ordered.begin(), ordered.end(), [](const Job* a, const Job* b) { return a->sequence < b->sequence; });
    return ordered;
}

void JobStore::openCheckpoint(Job& job) {
    job.checkpoint.open(job.dir / "tiles.log", std::ios::binary | std::ios::app);
}

void JobStore::appendCheckpoint(Job& job, const v1::TileResult& result) {
    if (!job.checkpoint.is_open()) return;
    std::string bytes;
    result.SerializeToString(&bytes);
    const uint32_t size = uint32_t(bytes.size());
    job.checkpoint.write(reinterpret_cast<const char*>(&size), 4);
    job.checkpoint.write(bytes.data(), std::streamsize(bytes.size()));
    job.checkpoint.flush();
}

void JobStore::closeCheckpoint(Job& job) {
    if (job.checkpoint.is_open()) job.checkpoint.close();
    std::error_code error;
    fs::remove(job.dir / "tiles.log", error);
}

void JobStore::writeRecord(const Job& job) {
    const v1::JobProgress record = progressOf(job);
    std::string bytes;
    record.SerializeToString(&bytes);
    try {
        util::writeFileAtomically(job.dir / "record.pb", bytes);
    } catch (const std::exception& e) {
        spdlog::error("{}: cannot record its end: {}", job.id, e.what());
    }
}

namespace {

uint64_t sizeOnDisk(const fs::path& path) {
    std::error_code error;
    if (fs::is_regular_file(path, error)) return fs::file_size(path, error);
    uint64_t bytes = 0;
    for (auto it = fs::recursive_directory_iterator(path, error); !error && it != fs::recursive_directory_iterator();
         it.increment(error))
        if (it->is_regular_file(error)) bytes += it->file_size(error);
    return bytes;
}

uint64_t removeAll(const fs::path& path) {
    const uint64_t bytes = sizeOnDisk(path);
    std::error_code error;
    fs::remove_all(path, error);
    if (error) spdlog::warn("purge: cannot remove '{}': {}", path.string(), error.message());
    return bytes;
}

}  // namespace

uint64_t JobStore::purge(const std::vector<std::string>& ids, std::chrono::milliseconds orphanAge,
                         uint32_t* bundlesRemoved) {
    uint64_t freed = 0;
    std::set<std::string> candidates;  // bundles of purged jobs
    for (const auto& id : ids) {
        const auto it = jobs_.find(id);
        if (it == jobs_.end() || !isTerminal(it->second->state)) continue;
        candidates.insert(it->second->spec.bundle_sha256());
        freed += removeAll(it->second->dir);
        jobs_.erase(it);
    }
    std::set<std::string> used;
    for (const auto& [id, job] : jobs_) used.insert(job->spec.bundle_sha256());
    // Bundles no job uses: those of purged jobs at once; others (uploaded, never submitted) once old enough,
    // so that a bundle uploaded just before its job is submitted survives.
    const auto oldest = fs::file_time_type::clock::now() - orphanAge;
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(stateDir_ / "bundles", error)) {
        const fs::path file = entry.path();
        if (file.extension() != ".bundle") continue;
        const std::string sha = file.stem().string();
        if (used.count(sha)) continue;
        std::error_code timeError;
        const auto written = fs::last_write_time(file, timeError);
        if (!candidates.count(sha) && (timeError || written > oldest)) continue;
        freed += removeAll(file) + removeAll(bundleDirectory(sha));
        assets_.erase(sha);
        if (bundlesRemoved) ++*bundlesRemoved;
    }
    return freed;
}

// ------------------------------------------------------------------ assets

void JobStore::publishAsset(const std::string& sha256, std::shared_ptr<const std::string> blob) {
    assets_[sha256] = std::move(blob);
}

std::shared_ptr<const std::string> JobStore::asset(const std::string& sha256) const {
    const auto it = assets_.find(sha256);
    if (it == assets_.end()) throw ServiceError(ErrorKind::NotFound, "no live job uses asset " + sha256);
    return it->second;
}

void JobStore::pruneAssets() {
    std::set<std::string> live;
    for (const auto& [id, job] : jobs_) {
        if (job->state != v1::JOB_STATE_RENDERING) continue;
        live.insert(job->spec.bundle_sha256());
        live.insert(job->assets.lights_sha256());
    }
    for (auto it = assets_.begin(); it != assets_.end();) it = live.count(it->first) ? std::next(it) : assets_.erase(it);
}

}  // namespace vrl::server
