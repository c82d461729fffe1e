#include "server/coordinator_service.h"

#include "util/hash.h"
#include "vrl/v1/vrl.grpc.pb.h"

#include <spdlog/spdlog.h>

#include <fstream>
#include <thread>

namespace vrl::server {

namespace {

// Runs `body` after the token check, mapping exceptions to statuses.
template <class Body>
grpc::Status guarded(const grpc::ServerContext* context, const std::string& token, Body&& body) {
    if (grpc::Status status = rpc::checkToken(*context, token); !status.ok()) return status;
    try {
        return body();
    } catch (const ServiceError& e) {
        return rpc::toStatus(e);
    } catch (const std::exception& e) {
        spdlog::error("internal error: {}", e.what());
        return {grpc::StatusCode::INTERNAL, e.what()};
    }
}

// Streams `blob` from `offset` in chunks of at most kChunkBytes, each with its CRC-32.
grpc::Status streamBlob(grpc::ServerContext* context, const std::string& blob, const std::string& sha256,
                        uint64_t offset, grpc::ServerWriter<v1::DataChunk>* writer) {
    if (offset > blob.size()) return {grpc::StatusCode::OUT_OF_RANGE, "offset beyond the end of the blob"};
    bool first = true;
    do {
        if (context->IsCancelled()) return {grpc::StatusCode::CANCELLED, "the caller went away"};
        const size_t size = std::min<size_t>(rpc::kChunkBytes, blob.size() - offset);
        v1::DataChunk chunk;
        chunk.set_offset(offset);
        chunk.set_data(blob.data() + offset, size);
        chunk.set_crc32(util::crc32Of(chunk.data()));
        if (first) {
            chunk.set_total_size(blob.size());
            chunk.set_sha256(sha256);
            first = false;
        }
        if (!writer->Write(chunk)) return {grpc::StatusCode::CANCELLED, "the caller went away"};
        offset += size;
    } while (offset < blob.size());
    return grpc::Status::OK;
}

}  // namespace

class CoordinatorServer::JobServiceImpl final : public v1::JobService::Service {
public:
    JobServiceImpl(Coordinator& coordinator, std::string token) : c_(coordinator), token_(std::move(token)) {}

    grpc::Status HasBundle(grpc::ServerContext* context, const v1::BundleRef* request,
                           v1::HasBundleReply* reply) override {
        return guarded(context, token_, [&] {
            reply->set_present(c_.hasBundle(request->sha256()));
            return grpc::Status::OK;
        });
    }

    grpc::Status UploadBundle(grpc::ServerContext* context, grpc::ServerReader<v1::BundleChunk>* reader,
                              v1::UploadBundleReply* reply) override {
        return guarded(context, token_, [&]() -> grpc::Status {
            std::string blob, sha256;
            uint64_t total = 0;
            v1::BundleChunk chunk;
            bool first = true;
            const uint64_t limit = c_.limits().maxBundleBytes;
            while (reader->Read(&chunk)) {
                if (first) {
                    sha256 = chunk.sha256();
                    total = chunk.total_size();
                    (void)c_.hasBundle(sha256);  // refuses a missing or malformed hash before reading the rest
                    if (total > limit)
                        return {grpc::StatusCode::RESOURCE_EXHAUSTED,
                                "scene bundle of " + std::to_string(total) + " bytes exceeds the limit of " +
                                    std::to_string(limit) + " bytes"};
                    first = false;
                }
                if (chunk.offset() != blob.size())
                    return {grpc::StatusCode::DATA_LOSS, "bundle chunk at offset " + std::to_string(chunk.offset()) +
                                                             ", expected " + std::to_string(blob.size())};
                if (util::crc32Of(chunk.data()) != chunk.crc32())
                    return {grpc::StatusCode::DATA_LOSS, "bundle chunk at offset " + std::to_string(chunk.offset()) +
                                                             " fails its CRC-32; upload again"};
                if (blob.size() + chunk.data().size() > total)
                    return {grpc::StatusCode::INVALID_ARGUMENT, "the bundle is longer than its announced size"};
                blob += chunk.data();
            }
            if (first) return {grpc::StatusCode::INVALID_ARGUMENT, "empty upload"};
            if (blob.size() != total)
                return {grpc::StatusCode::DATA_LOSS, "the upload stopped at " + std::to_string(blob.size()) + " of " +
                                                         std::to_string(total) + " bytes"};
            c_.storeBundle(sha256, blob);
            reply->set_sha256(sha256);
            return grpc::Status::OK;
        });
    }

    grpc::Status SubmitJob(grpc::ServerContext* context, const v1::JobSpec* request,
                           v1::SubmitJobReply* reply) override {
        return guarded(context, token_, [&] {
            reply->set_job_id(c_.submitJob(*request));
            return grpc::Status::OK;
        });
    }

    grpc::Status WatchJob(grpc::ServerContext* context, const v1::JobRef* request,
                          grpc::ServerWriter<v1::JobProgress>* writer) override {
        return guarded(context, token_, [&]() -> grpc::Status {
            uint64_t version = ~uint64_t(0);
            while (!context->IsCancelled()) {
                const uint64_t now = c_.waitForChange(request->job_id(), version, std::chrono::milliseconds(500));
                if (now == version && !c_.draining()) continue;
                version = now;
                const v1::JobProgress progress = c_.jobProgress(request->job_id());
                if (!writer->Write(progress)) break;
                const auto state = progress.state();
                if (state == v1::JOB_STATE_DONE || state == v1::JOB_STATE_FAILED || state == v1::JOB_STATE_CANCELLED)
                    return grpc::Status::OK;
                if (c_.draining())
                    return {grpc::StatusCode::UNAVAILABLE, "the coordinator is shutting down; re-attach later"};
            }
            return grpc::Status::OK;
        });
    }

    grpc::Status FetchImage(grpc::ServerContext* context, const v1::JobRef* request,
                            grpc::ServerWriter<v1::DataChunk>* writer) override {
        return guarded(context, token_, [&] {
            const std::string blob = request->partial() ? c_.partialImage(request->job_id())
                                                        : rpc::readFileText(c_.imageFile(request->job_id()).string());
            return streamBlob(context, blob, util::sha256Hex(blob), 0, writer);
        });
    }

    grpc::Status CancelJob(grpc::ServerContext* context, const v1::JobRef* request,
                           v1::CancelJobReply* reply) override {
        return guarded(context, token_, [&] {
            reply->set_state(c_.cancelJob(request->job_id()));
            return grpc::Status::OK;
        });
    }

    grpc::Status ListJobs(grpc::ServerContext* context, const v1::ListJobsRequest*, v1::ListJobsReply* reply) override {
        return guarded(context, token_, [&] {
            for (auto& job : c_.listJobs()) *reply->add_jobs() = std::move(job);
            return grpc::Status::OK;
        });
    }

    grpc::Status PurgeJobs(grpc::ServerContext* context, const v1::PurgeJobsRequest* request,
                           v1::PurgeJobsReply* reply) override {
        return guarded(context, token_, [&]() -> grpc::Status {
            if (request->older_than_ms() < 0)
                return {grpc::StatusCode::INVALID_ARGUMENT, "older_than_ms must be >= 0"};
            *reply = c_.purgeJobs(std::chrono::milliseconds(request->older_than_ms()));
            return grpc::Status::OK;
        });
    }

    grpc::Status GetServiceInfo(grpc::ServerContext* context, const v1::GetServiceInfoRequest*,
                                v1::ServiceInfo* reply) override {
        return guarded(context, token_, [&] {
            *reply = c_.serviceInfo();
            reply->set_token_required(!token_.empty());
            return grpc::Status::OK;
        });
    }

private:
    Coordinator& c_;
    std::string token_;
};

class CoordinatorServer::WorkerGatewayImpl final : public v1::WorkerGateway::Service {
public:
    WorkerGatewayImpl(Coordinator& coordinator, std::string token, bool requireCertificate)
        : c_(coordinator), token_(std::move(token)), requireCertificate_(requireCertificate) {}

    grpc::Status Register(grpc::ServerContext* context, const v1::RegisterRequest* request,
                          v1::RegisterReply* reply) override {
        return guardedWorker(context, [&]() -> grpc::Status {
            *reply = c_.registerWorker(*request);
            return grpc::Status::OK;
        });
    }

    grpc::Status Heartbeat(grpc::ServerContext* context, const v1::HeartbeatRequest* request,
                           v1::HeartbeatReply* reply) override {
        return guardedWorker(context, [&] {
            *reply = c_.heartbeat(request->worker_id());
            return grpc::Status::OK;
        });
    }

    grpc::Status LeaseTiles(grpc::ServerContext* context, const v1::LeaseRequest* request,
                            v1::LeaseReply* reply) override {
        return guardedWorker(context, [&] {
            *reply = c_.leaseTiles(*request);
            return grpc::Status::OK;
        });
    }

    grpc::Status FetchAsset(grpc::ServerContext* context, const v1::FetchAssetRequest* request,
                            grpc::ServerWriter<v1::DataChunk>* writer) override {
        return guardedWorker(context, [&] {
            const auto blob = c_.asset(request->sha256());
            return streamBlob(context, *blob, request->sha256(), request->offset(), writer);
        });
    }

    grpc::Status SubmitTile(grpc::ServerContext* context, const v1::TileResult* request,
                            v1::SubmitTileReply* reply) override {
        return guardedWorker(context, [&]() -> grpc::Status {
            bool malformed = false;
            *reply = c_.submitTile(*request, &malformed);
            if (malformed) return {grpc::StatusCode::INVALID_ARGUMENT, "tile result refused: " + reply->reason()};
            return grpc::Status::OK;  // taken, or dropped as a duplicate or for a job no longer rendering
        });
    }

    grpc::Status ReleaseLeases(grpc::ServerContext* context, const v1::ReleaseRequest* request,
                               v1::ReleaseReply*) override {
        return guardedWorker(context, [&] {
            c_.releaseLeases(*request);
            return grpc::Status::OK;
        });
    }

private:
    // The token, and with --tls-client-ca a verified client certificate, on every worker call.
    template <class Body>
    grpc::Status guardedWorker(grpc::ServerContext* context, Body&& body) {
        if (requireCertificate_ && !context->auth_context()->IsPeerAuthenticated())
            return {grpc::StatusCode::UNAUTHENTICATED, "workers must present a client certificate"};
        return guarded(context, token_, std::forward<Body>(body));
    }

    Coordinator& c_;
    std::string token_;
    bool requireCertificate_;
};

CoordinatorServer::CoordinatorServer(Coordinator& coordinator, const ServerOptions& options)
    : coordinator_(coordinator),
      jobService_(std::make_unique<JobServiceImpl>(coordinator, options.token)),
      workerGateway_(std::make_unique<WorkerGatewayImpl>(coordinator, options.token, !options.tls.clientCaFile.empty())) {
    grpc::ServerBuilder builder;
    rpc::configureServer(builder, options.listen, options.tls, &port_);
    builder.RegisterService(jobService_.get());
    builder.RegisterService(workerGateway_.get());
    builder.RegisterService(&health_);
    server_ = builder.BuildAndStart();
    if (!server_ || port_ == 0) throw std::runtime_error("cannot listen on '" + options.listen + "' (in use? bad address?)");
    health_.setServing(true);
    if (options.token.empty())
        spdlog::warn("no token set (--token-file or VRL_TOKEN): anyone who can reach port {} can submit jobs", port_);
}

CoordinatorServer::~CoordinatorServer() { shutdown(std::chrono::milliseconds(0)); }

void CoordinatorServer::shutdown(std::chrono::milliseconds drainTimeout) {
    if (stopped_) return;
    stopped_ = true;
    health_.setServing(false);
    coordinator_.beginDrain();
    const auto until = std::chrono::steady_clock::now() + drainTimeout;
    while (coordinator_.activeLeases() > 0 && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (coordinator_.activeLeases() > 0)
        spdlog::warn("stopping with {} leases outstanding (their tiles are rendered again after a restart)",
                     coordinator_.activeLeases());
    health_.shutdown();  // ends Watch streams, so Shutdown need not wait for them
    server_->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(2));
}

void CoordinatorServer::wait() { server_->Wait(); }

}  // namespace vrl::server
