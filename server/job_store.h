// JobStore: the jobs and what of them lives on disk under the state directory:
//   bundles/<sha>.bundle, bundles/<sha>/    uploaded scene bundles, and extracted
//   jobs/<id>/spec.pb                       every job's spec, written at submission
//   jobs/<id>/record.pb                     the job's JobProgress at submission (its submit time),
//                                           then as it ended (state, finish time, phases)
//   jobs/<id>/tiles.log                     checkpoint: the accepted tiles of an unfinished job
//   jobs/<id>/image.exr                     a done job's image (tile_assembly.h writes it)
// plus the blobs (bundle, lights) that workers fetch while a job renders.
// On construction it reloads every job found there (loadState): finished ones
// keep their record, the others are queued again and their checkpoint is
// replayed when they are prepared. purge() deletes finished jobs and the
// bundles no remaining job uses (vrl-coordinator --retention, vrl jobs --purge).
//
// Not thread-safe by itself: the Coordinator calls it with its mutex held. The
// methods under "on disk" use nothing but the state directory and the limits,
// which never change, and touch no job in the store, so the Coordinator calls
// them without the lock (bundle uploads and checkpoint reads must not stall
// the workers).
#pragma once

#include "server/job.h"
#include "service/common/limits.h"
#include "vrl/v1/vrl.pb.h"

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace vrl::server {

// Refuses (InvalidArgument) a missing or malformed SHA-256 in the field `what`.
void requireHash(const std::string& sha256, const char* what);

class JobStore {
public:
    // Creates <stateDir>/bundles and <stateDir>/jobs and loads the jobs found there.
    JobStore(std::filesystem::path stateDir, const rpc::ServiceLimits& limits);

    // --- on disk (no lock needed)
    const std::filesystem::path& stateDir() const { return stateDir_; }
    // Checks the hash (InvalidArgument), then whether its bundle was uploaded.
    bool hasBundle(const std::string& sha256) const;
    // Verifies the hash, validates (limits, paths, links), extracts and stores the bundle.
    void storeBundle(const std::string& sha256, const std::string& blob) const;
    std::filesystem::path bundleFile(const std::string& sha256) const;       // bundles/<sha>.bundle
    std::filesystem::path bundleDirectory(const std::string& sha256) const;  // bundles/<sha>/, extracted
    // A new job (fresh id, spec, directory), not yet stored nor written.
    std::unique_ptr<Job> newJob(const v1::JobSpec& spec) const;
    void writeSpec(const Job& job) const;  // creates the job's directory and its spec.pb
    // The tile results in the job's checkpoint, up to the last whole record; cuts the
    // file there, so that new records follow it.
    std::vector<v1::TileResult> readCheckpoint(const Job& job) const;

    // --- jobs (lock held)
    void add(std::unique_ptr<Job> job);  // numbers it after every job stored so far
    Job& find(const std::string& jobId) const;  // InvalidArgument if empty, NotFound if unknown
    const std::map<std::string, std::unique_ptr<Job>>& jobs() const { return jobs_; }
    std::vector<const Job*> bySequence() const;  // in submission order
    void openCheckpoint(Job& job);  // appends from now on
    void appendCheckpoint(Job& job, const v1::TileResult& result);
    void closeCheckpoint(Job& job);  // and removes tiles.log: the job has ended
    void writeRecord(const Job& job);  // record.pb: the job as it is now; a failure is logged only
    // Deletes the finished jobs `ids` (records, images, directories) and then every
    // bundle that they used and no remaining job does, plus bundles no job uses
    // that were uploaded longer than `orphanAge` ago. Returns the bytes freed and
    // counts the bundles removed in `bundlesRemoved`.
    uint64_t purge(const std::vector<std::string>& ids, std::chrono::milliseconds orphanAge, uint32_t* bundlesRemoved);

    // --- blobs workers fetch (lock held)
    void publishAsset(const std::string& sha256, std::shared_ptr<const std::string> blob);
    std::shared_ptr<const std::string> asset(const std::string& sha256) const;  // NotFound if no live job uses it
    void pruneAssets();  // keeps those of RENDERING jobs

private:
    void loadState();

    std::filesystem::path stateDir_;
    rpc::ServiceLimits limits_;
    std::map<std::string, std::unique_ptr<Job>> jobs_;
    std::map<std::string, std::shared_ptr<const std::string>> assets_;
    uint64_t nextSequence_ = 0;
};

}  // namespace vrl::server
