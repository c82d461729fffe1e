// `vrl submit`, `vrl jobs`, `vrl cancel`, `vrl health`: the client of a running coordinator.
#include "client/commands.h"

#include "client/job_client.h"
#include "client/remote_render.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "render/scene/scene_error.h"
#include "service/job/scene_bundle.h"

#include <cstdio>
#include <cstdlib>
#include <memory>

namespace vrl::client {

namespace {

struct ConnectionFlags {
    std::string address;
    std::string tokenFile;
    rpc::TlsOptions tls;
};

void addConnectionFlags(CLI::App& cmd, ConnectionFlags& c) {
    const char* env = std::getenv("VRL_COORDINATOR");
    c.address = env ? env : "localhost:50051";
    cmd.add_option("--coordinator", c.address, "Coordinator address host:port (default: $VRL_COORDINATOR or "
                                               "localhost:50051)");
    cmd.add_option("--token-file", c.tokenFile, "File whose first line is the coordinator's token (default: "
                                                "$VRL_TOKEN)");
    cmd.add_option("--tls-ca", c.tls.caFile, "PEM CA of the coordinator's certificate: connect with TLS");
}

const char* stateName(v1::JobState state) {
    switch (state) {
        case v1::JOB_STATE_QUEUED: return "queued";
        case v1::JOB_STATE_PREPARING: return "preparing";
        case v1::JOB_STATE_RENDERING: return "rendering";
        case v1::JOB_STATE_DONE: return "done";
        case v1::JOB_STATE_FAILED: return "failed";
        case v1::JOB_STATE_CANCELLED: return "cancelled";
        default: return "?";
    }
}

// Runs body, mapping errors to exit codes: bad input 2, the rest 1.
template <class Body>
int guarded(const char* command, Body&& body) {
    try {
        return body();
    } catch (const SceneError& e) {
        std::fprintf(stderr, "vrl %s: scene error: %s\n", command, e.what());
        return 2;
    } catch (const rpc::BundleError& e) {
        std::fprintf(stderr, "vrl %s: error: %s\n", command, e.what());
        return 2;
    } catch (const JobClientError& e) {
        std::fprintf(stderr, "vrl %s: error: %s\n", command, e.what());
        return e.code == grpc::StatusCode::INVALID_ARGUMENT ? 2 : 1;
    } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "vrl %s: error: %s\n", command, e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "vrl %s: error: %s\n", command, e.what());
        return 1;
    }
}

}  // namespace

void registerServiceCommands(CLI::App& app, int& exitCode) {
    {
        auto o = std::make_shared<RenderCommandOptions>();
        auto c = std::make_shared<ConnectionFlags>();
        auto remote = std::make_shared<RemoteOptions>();
        auto* cmd = app.add_subcommand("submit", "Render a scene on a running coordinator and its workers; "
                                                 "writes the OpenEXR image like `render`");
        addRenderOptions(*cmd, *o);
        addConnectionFlags(*cmd, *c);
        cmd->add_option("--priority", remote->priority, "Higher runs first (default 0)");
        cmd->add_option("--tile-size", o->tileSize, "Tile side in pixels (default 32)")->check(CLI::Range(1u, 256u));
        cmd->add_flag("--detach", remote->detach, "Print the job id once submitted and exit (re-attach with --attach)");
        cmd->add_option("--attach", remote->attachJob,
                        "Re-attach to a submitted job by id: wait for it and write its image (the scene is not read)");
        cmd->callback([o, c, remote, &exitCode] {
            exitCode = guarded("submit", [&] {
                remote->address = c->address;
                remote->tls = c->tls;
                remote->token = rpc::loadToken(c->tokenFile);
                return runRemoteRender(*o, *remote);
            });
        });
    }
    {
        auto c = std::make_shared<ConnectionFlags>();
        auto* cmd = app.add_subcommand("jobs", "List a coordinator's jobs");
        addConnectionFlags(*cmd, *c);
        cmd->callback([c, &exitCode] {
            exitCode = guarded("jobs", [&] {
                JobClient client(c->address, c->tls, rpc::loadToken(c->tokenFile));
                std::printf("%-18s %-10s %8s %9s  %s\n", "JOB", "STATE", "PRIORITY", "TILES", "SCENE");
                for (const auto& j : client.list()) {
                    std::printf("%-18s %-10s %8d %4u/%-4u  %s%s%s\n", j.job_id().c_str(), stateName(j.state()),
                                j.priority(), j.tiles_done(), j.tiles_total(), j.name().c_str(),
                                j.message().empty() ? "" : "  -- ", j.message().c_str());
                }
                return 0;
            });
        });
    }
    {
        auto c = std::make_shared<ConnectionFlags>();
        auto job = std::make_shared<std::string>();
        auto* cmd = app.add_subcommand("cancel", "Cancel a job on a coordinator");
        cmd->add_option("job", *job, "Job id (see `vrl jobs`)")->required();
        addConnectionFlags(*cmd, *c);
        cmd->callback([c, job, &exitCode] {
            exitCode = guarded("cancel", [&] {
                JobClient client(c->address, c->tls, rpc::loadToken(c->tokenFile));
                std::printf("%s: %s\n", job->c_str(), stateName(client.cancel(*job)));
                return 0;
            });
        });
    }
    {
        auto c = std::make_shared<ConnectionFlags>();
        auto* cmd = app.add_subcommand("health", "Ask a coordinator or worker's gRPC health service; exit 0 when "
                                                 "SERVING (for container health checks)");
        cmd->add_option("--address", c->address, "host:port")->required();
        cmd->add_option("--tls-ca", c->tls.caFile, "PEM CA: connect with TLS");
        cmd->callback([c, &exitCode] {
            exitCode = guarded("health", [&] {
                auto stub = grpc::health::v1::Health::NewStub(rpc::makeChannel(c->address, c->tls));
                grpc::ClientContext context;
                context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
                grpc::health::v1::HealthCheckResponse reply;
                const grpc::Status status = stub->Check(&context, grpc::health::v1::HealthCheckRequest(), &reply);
                if (!status.ok()) {
                    std::printf("%s: unreachable (%s)\n", c->address.c_str(), rpc::describe(status).c_str());
                    return 1;
                }
                std::printf("%s: %s\n", c->address.c_str(),
                            grpc::health::v1::HealthCheckResponse::ServingStatus_Name(reply.status()).c_str());
                return reply.status() == grpc::health::v1::HealthCheckResponse::SERVING ? 0 : 1;
            });
        });
    }
}

}  // namespace vrl::client
