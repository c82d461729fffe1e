// `vrl submit`, `vrl jobs`, `vrl cancel`, `vrl health`: the client of a running coordinator.
#include "client/commands.h"

#include "client/command_line_job.h"
#include "client/job_client.h"
#include "client/remote_render.h"
#include "grpc/health/v1/health.grpc.pb.h"
#include "render/description/scene_error.h"
#include "service/job/scene_bundle.h"
#include "util/duration.h"
#include "util/termination_signals.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <cstdlib>
#include <memory>
#include <optional>

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

// A wall-clock time in ms since the epoch as local "YYYY-MM-DD HH:MM:SS"; "-" for none.
std::string whenText(int64_t unixMs) {
    if (unixMs <= 0) return "-";
    const std::time_t seconds = std::time_t(unixMs / 1000);
    std::tm local{};
    localtime_r(&seconds, &local);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &local);
    return text;
}

// How long ago: "3d 4h", "12m 5s"; "-" for none.
std::string agoText(int64_t unixMs) {
    if (unixMs <= 0) return "-";
    const auto now = std::chrono::duration_cast<std::chrono::milliseconds>(
        std::chrono::system_clock::now().time_since_epoch());
    return util::formatDuration(now - std::chrono::milliseconds(unixMs));
}

// Runs body, mapping errors to exit codes: bad input 2 (also what the
// coordinator refuses as invalid or over its limits), the rest 1.
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
        return e.code == grpc::StatusCode::INVALID_ARGUMENT || e.code == grpc::StatusCode::RESOURCE_EXHAUSTED ? 2 : 1;
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
                        "Re-attach to a submitted job by id: wait for it and write its image (no scene needed)");
        cmd->get_option("scene")->required(false);  // not with --attach; checked in runRemoteRender
        auto retryFor = std::make_shared<int>(300);
        cmd->add_option("--retry-for", *retryFor,
                        "Seconds to keep retrying (with backoff) a coordinator that became unreachable, e.g. while it "
                        "restarts; then exit 1 with the command to re-attach")
            ->capture_default_str()->check(CLI::Range(0, 7 * 86400));
        auto noWorkerSeconds = std::make_shared<double>(15.0);
        cmd->add_option("--no-worker-warning", *noWorkerSeconds, "")->group("");  // hidden: tests use 1 s
        cmd->callback([o, c, remote, retryFor, noWorkerSeconds, cmd, &exitCode] {
            exitCode = guarded("submit", [&] {
                if (o->quiet) spdlog::set_level(spdlog::level::warn);
                // Bad input exits 2 before connecting: the outputs, the scene and the job as the coordinator will build it.
                std::optional<CommandLineJob> job;
                if (remote->attachJob.empty() && !o->scene.empty()) {
                    job = resolveCommandLineJob(*o);
                    warnIneffectiveFlags(*cmd, job->resolved.settings.method, true);
                }
                remote->address = c->address;
                remote->tls = c->tls;
                remote->tokenFile = c->tokenFile;
                remote->token = rpc::loadToken(c->tokenFile);
                remote->retryFor = std::chrono::seconds(*retryFor);
                remote->noWorkerWarning = std::chrono::milliseconds(int64_t(*noWorkerSeconds * 1000));
                util::TerminationSignals signals;  // Ctrl-C: leave the job running, say how to re-attach
                return runRemoteRender(*o, *remote, signals, job ? &*job : nullptr);
            });
        });
    }
    {
        auto c = std::make_shared<ConnectionFlags>();
        auto purge = std::make_shared<bool>(false);
        auto olderThan = std::make_shared<std::string>("0");
        auto* cmd = app.add_subcommand("jobs", "List a coordinator's jobs (submitted when, how long ago, finished "
                                               "when), or purge its finished ones");
        addConnectionFlags(*cmd, *c);
        cmd->add_flag("--purge", *purge,
                      "Delete finished jobs (done, failed, cancelled) now, with their images and the scene bundles no "
                      "other job uses; prints what it deleted");
        cmd->add_option("--older-than", *olderThan,
                        "With --purge: only jobs that ended at least this long ago (e.g. 7d, 12h, 30m, 90s; default: "
                        "every finished job)");
        cmd->callback([c, purge, olderThan, &exitCode] {
            exitCode = guarded("jobs", [&] {
                const auto age = util::parseDuration(*olderThan);  // std::invalid_argument: exit 2
                JobClient client(c->address, c->tls, rpc::loadToken(c->tokenFile));
                if (*purge) {
                    const v1::PurgeJobsReply reply = client.purge(age);
                    for (const auto& j : reply.purged())
                        std::printf("purged %s  %s, finished %s, %s\n", j.job_id().c_str(), stateName(j.state()),
                                    whenText(j.finished_unix_ms()).c_str(), j.name().c_str());
                    std::printf("purged %d jobs and %u scene bundles, %.1f MiB freed\n", reply.purged_size(),
                                reply.bundles_removed(), double(reply.bytes_freed()) / double(1 << 20));
                    return 0;
                }
                std::printf("%-18s %-10s %8s %9s  %-19s %9s %-13s %s\n", "JOB", "STATE", "PRIORITY", "TILES",
                            "SUBMITTED", "AGE", "FINISHED", "SCENE");
                for (const auto& j : client.list()) {
                    const std::string finished =
                        j.finished_unix_ms() > 0 ? agoText(j.finished_unix_ms()) + " ago" : std::string("-");
                    // A time-limited job: its passes so far (TILES counts the pass under way).
                    const std::string passes =
                        j.time_limit_seconds() > 0.0
                            ? "  [" + std::to_string(j.passes_done()) + " passes, " +
                                  std::to_string(j.samples_per_pixel()) + " spp]"
                            : std::string();
                    std::printf("%-18s %-10s %8d %4u/%-4u  %-19s %9s %-13s %s%s%s%s\n", j.job_id().c_str(),
                                stateName(j.state()), j.priority(), j.tiles_done(), j.tiles_total(),
                                whenText(j.submitted_unix_ms()).c_str(), agoText(j.submitted_unix_ms()).c_str(),
                                finished.c_str(), j.name().c_str(), passes.c_str(), j.message().empty() ? "" : "  -- ",
                                j.message().c_str());
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
