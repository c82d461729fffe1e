// CoordinatorServer: the Coordinator on the network. Serves vrl.v1.JobService
// (clients) and vrl.v1.WorkerGateway (workers) plus the standard gRPC health
// service, checks the shared token on every call of both, and shuts down
// gracefully: health goes NOT_SERVING, no new leases, outstanding leases are
// awaited (up to a drain timeout), then the server stops.
#pragma once

#include "server/coordinator.h"
#include "service/common/health_service.h"
#include "service/common/rpc_common.h"

#include <grpcpp/grpcpp.h>

#include <memory>
#include <string>

namespace vrl::server {

struct ServerOptions {
    std::string listen = "0.0.0.0:50051";
    rpc::TlsOptions tls;   // certFile/keyFile: TLS; clientCaFile: workers must present certificates
    std::string token;     // empty: no token required (a warning is logged)
};

class CoordinatorServer {
public:
    // Starts listening; throws std::runtime_error if the address cannot be bound.
    CoordinatorServer(Coordinator& coordinator, const ServerOptions& options);
    ~CoordinatorServer();
    int port() const { return port_; }
    // Drains leases for at most `drainTimeout`, then stops serving.
    void shutdown(std::chrono::milliseconds drainTimeout);
    void wait();

private:
    class JobServiceImpl;
    class WorkerGatewayImpl;
    Coordinator& coordinator_;
    std::unique_ptr<JobServiceImpl> jobService_;
    std::unique_ptr<WorkerGatewayImpl> workerGateway_;
    rpc::HealthService health_;  // grpc.health.v1: SERVING until shutdown begins
    std::unique_ptr<grpc::Server> server_;
    int port_ = 0;
    bool stopped_ = false;
};

}  // namespace vrl::server
