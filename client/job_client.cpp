#include "client/job_client.h"

#include "client/output_checks.h"
#include "service/job/scene_bundle.h"
#include "util/atomic_file.h"
#include "util/hash.h"

#include <condition_variable>
#include <fstream>
#include <mutex>
#include <thread>

namespace vrl::client {

namespace {

using namespace std::chrono_literals;

void check(const grpc::Status& status, const std::string& call) {
    if (!status.ok()) throw JobClientError(call + " failed: " + rpc::describe(status), status.error_code());
}

}  // namespace

JobClient::JobClient(const std::string& address, const rpc::TlsOptions& tls, std::string token)
    : channel_(rpc::makeChannel(address, tls)), stub_(v1::JobService::NewStub(channel_)), token_(std::move(token)) {}

v1::ServiceInfo JobClient::serviceInfo(std::chrono::milliseconds timeout) {
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, timeout);
    v1::ServiceInfo reply;
    check(stub_->GetServiceInfo(&context, v1::GetServiceInfoRequest(), &reply), "GetServiceInfo");
    return reply;
}

std::string JobClient::uploadBundle(const std::string& blob, bool* uploaded) {
    const std::string sha256 = util::sha256Hex(blob);
    {
        grpc::ClientContext context;
        rpc::prepareContext(context, token_, 30s);
        v1::BundleRef ref;
        ref.set_sha256(sha256);
        v1::HasBundleReply reply;
        check(stub_->HasBundle(&context, ref, &reply), "HasBundle");
        if (uploaded) *uploaded = !reply.present();
        if (reply.present()) return sha256;
    }
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, std::chrono::minutes(30));
    v1::UploadBundleReply reply;
    auto writer = stub_->UploadBundle(&context, &reply);
    uint64_t offset = 0;
    do {
        const size_t size = std::min<size_t>(rpc::kChunkBytes, blob.size() - offset);
        v1::BundleChunk chunk;
        if (offset == 0) {
            chunk.set_sha256(sha256);
            chunk.set_total_size(blob.size());
        }
        chunk.set_offset(offset);
        chunk.set_data(blob.data() + offset, size);
        chunk.set_crc32(util::crc32Of(chunk.data()));
        if (!writer->Write(chunk)) break;  // the server ended the call; Finish says why
        offset += size;
    } while (offset < blob.size());
    writer->WritesDone();
    check(writer->Finish(), "UploadBundle");
    return sha256;
}

std::string JobClient::submit(const v1::JobSpec& spec) {
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, 30s);
    v1::SubmitJobReply reply;
    check(stub_->SubmitJob(&context, spec, &reply), "SubmitJob");
    return reply.job_id();
}

v1::JobProgress JobClient::watch(const std::string& jobId,
                                 const std::function<void(const v1::JobProgress&)>& onProgress,
                                 const std::function<bool()>& interrupted) {
    // The current call's context, cancelled from the polling thread once `interrupted` says so.
    std::mutex mutex;
    std::condition_variable done;
    grpc::ClientContext* current = nullptr;
    bool stop = false, finished = false;
    std::thread poller;
    if (interrupted)
        poller = std::thread([&] {
            std::unique_lock lock(mutex);
            while (!finished && !stop) {
                done.wait_for(lock, 100ms);
                if (finished) break;
                lock.unlock();
                const bool interrupt = interrupted();
                lock.lock();
                if (interrupt) {
                    stop = true;
                    if (current) current->TryCancel();
                }
            }
        });
    const auto endPoller = [&] {
        {
            std::lock_guard lock(mutex);
            finished = true;
        }
        done.notify_all();
        if (poller.joinable()) poller.join();
    };
    v1::JobProgress last;
    try {
        // Long jobs: re-attach every 10 minutes so no single call needs an unbounded deadline.
        while (true) {
            grpc::ClientContext context;
            rpc::prepareContext(context, token_, 10min);
            {
                std::lock_guard lock(mutex);
                if (stop) throw WatchInterrupted();
                current = &context;
            }
            v1::JobRef ref;
            ref.set_job_id(jobId);
            auto reader = stub_->WatchJob(&context, ref);
            v1::JobProgress progress;
            while (reader->Read(&progress)) {
                last = progress;
                if (onProgress) onProgress(progress);
            }
            const grpc::Status status = reader->Finish();
            {
                std::lock_guard lock(mutex);
                current = nullptr;
                if (stop) throw WatchInterrupted();
            }
            const auto state = last.state();
            if (state == v1::JOB_STATE_DONE || state == v1::JOB_STATE_FAILED || state == v1::JOB_STATE_CANCELLED)
                break;
            if (status.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED) check(status, "WatchJob");
        }
    } catch (...) {
        endPoller();
        throw;
    }
    endPoller();
    return last;
}

void JobClient::fetchImage(const std::string& jobId, const std::filesystem::path& path, bool partial) {
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, 30min);
    v1::JobRef ref;
    ref.set_job_id(jobId);
    ref.set_partial(partial);
    auto reader = stub_->FetchImage(&context, ref);
    std::string blob, sha256;
    uint64_t total = 0;
    v1::DataChunk chunk;
    while (reader->Read(&chunk)) {
        if (chunk.offset() == 0) {
            total = chunk.total_size();
            sha256 = chunk.sha256();
        }
        if (chunk.offset() != blob.size() || util::crc32Of(chunk.data()) != chunk.crc32())
            throw JobClientError("FetchImage: a corrupt chunk at offset " + std::to_string(chunk.offset()),
                                 grpc::StatusCode::DATA_LOSS);
        blob += chunk.data();
    }
    check(reader->Finish(), "FetchImage");
    if (blob.size() != total || util::sha256Hex(blob) != sha256)
        throw JobClientError("FetchImage: the image arrived incomplete or corrupt", grpc::StatusCode::DATA_LOSS);
    util::writeFileAtomically(path, blob);
}

v1::JobState JobClient::cancel(const std::string& jobId) {
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, 30s);
    v1::JobRef ref;
    ref.set_job_id(jobId);
    v1::CancelJobReply reply;
    check(stub_->CancelJob(&context, ref, &reply), "CancelJob");
    return reply.state();
}

std::vector<v1::JobProgress> JobClient::list() {
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, 30s);
    v1::ListJobsReply reply;
    check(stub_->ListJobs(&context, v1::ListJobsRequest(), &reply), "ListJobs");
    return {reply.jobs().begin(), reply.jobs().end()};
}

v1::PurgeJobsReply JobClient::purge(std::chrono::milliseconds olderThan) {
    grpc::ClientContext context;
    rpc::prepareContext(context, token_, 5min);
    v1::PurgeJobsRequest request;
    request.set_older_than_ms(olderThan.count());
    v1::PurgeJobsReply reply;
    check(stub_->PurgeJobs(&context, request, &reply), "PurgeJobs");
    return reply;
}

std::string collectSceneBundle(const std::filesystem::path& scene, const std::map<std::string, std::string>& defines,
                               std::vector<std::filesystem::path>* referenced) {
    // Parsing also reports scene errors (and unused -D) before anything is sent.
    const std::vector<std::filesystem::path> files = sceneInputFiles(scene, defines);
    if (referenced) *referenced = files;
    return rpc::makeBundleBlob(scene, files);
}

}  // namespace vrl::client
