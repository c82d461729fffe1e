// HealthService: the standard gRPC health protocol (grpc.health.v1.Health) for
// the coordinator and the workers, so that container and Kubernetes probes
// (`vrl health`, grpc_health_probe, native gRPC probes) can ask whether a
// program serves. One overall status, for the service name "" (and the
// "vrl.v1.*" names, which share it): SERVING while the program takes work,
// NOT_SERVING while it starts, drains or stops. Any other service name is
// NOT_FOUND, as the protocol asks.
//
// Why our own and not gRPC's default health service: in gRPC 1.51 the default
// one cannot run on a server that registers no other service (the workers'
// health port), which then refuses to start ("At least one of the completion
// queues must be frequently polled"). This one is an ordinary service.
//
// Thread-safe: setServing may be called from any thread; Watch streams follow it
// until the caller cancels or shutdown() is called.
#pragma once

#include "grpc/health/v1/health.grpc.pb.h"

#include <condition_variable>
#include <mutex>

namespace vrl::rpc {

class HealthService final : public grpc::health::v1::Health::Service {
public:
    void setServing(bool serving);
    bool serving() const;
    // Ends every Watch stream (call before the server's Shutdown).
    void shutdown();

    grpc::Status Check(grpc::ServerContext* context, const grpc::health::v1::HealthCheckRequest* request,
                       grpc::health::v1::HealthCheckResponse* reply) override;
    grpc::Status Watch(grpc::ServerContext* context, const grpc::health::v1::HealthCheckRequest* request,
                       grpc::ServerWriter<grpc::health::v1::HealthCheckResponse>* writer) override;

private:
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    bool serving_ = false;
    bool shutdown_ = false;
    uint64_t version_ = 0;
};

}  // namespace vrl::rpc
