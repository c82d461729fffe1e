#include "service/common/health_service.h"

#include <chrono>
#include <string>

namespace vrl::rpc {

namespace {

using grpc::health::v1::HealthCheckResponse;

bool knownService(const std::string& name) { return name.empty() || name.rfind("vrl.v1.", 0) == 0; }

}  // namespace

void HealthService::setServing(bool serving) {
    {
        std::lock_guard lock(mutex_);
        if (serving_ == serving) return;
        serving_ = serving;
        ++version_;
    }
    changed_.notify_all();
}

bool HealthService::serving() const {
    std::lock_guard lock(mutex_);
    return serving_;
}

void HealthService::shutdown() {
    {
        std::lock_guard lock(mutex_);
        shutdown_ = true;
        serving_ = false;
        ++version_;
    }
    changed_.notify_all();
}

grpc::Status HealthService::Check(grpc::ServerContext*, const grpc::health::v1::HealthCheckRequest* request,
                                  HealthCheckResponse* reply) {
    if (!knownService(request->service()))
        return {grpc::StatusCode::NOT_FOUND, "unknown service '" + request->service().substr(0, 64) + "'"};
    reply->set_status(serving() ? HealthCheckResponse::SERVING : HealthCheckResponse::NOT_SERVING);
    return grpc::Status::OK;
}

grpc::Status HealthService::Watch(grpc::ServerContext* context, const grpc::health::v1::HealthCheckRequest* request,
                                  grpc::ServerWriter<HealthCheckResponse>* writer) {
    std::unique_lock lock(mutex_);
    uint64_t sent = ~uint64_t(0);
    while (!context->IsCancelled()) {
        if (sent != version_) {
            sent = version_;
            HealthCheckResponse reply;
            reply.set_status(!knownService(request->service()) ? HealthCheckResponse::SERVICE_UNKNOWN
                             : serving_                         ? HealthCheckResponse::SERVING
                                                                : HealthCheckResponse::NOT_SERVING);
            lock.unlock();
            const bool written = writer->Write(reply);
            lock.lock();
            if (!written) break;
        }
        if (shutdown_) break;
        // Wakes on a change, and every 200 ms to notice a cancelled call.
        changed_.wait_for(lock, std::chrono::milliseconds(200));
    }
    return grpc::Status::OK;
}

}  // namespace vrl::rpc
