#include "server/coordinator_main.h"

#include "server/coordinator_service.h"
#include "util/atomic_file.h"
#include "util/duration.h"
#include "util/termination_signals.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <fstream>
#include <optional>

namespace vrl::server {

int coordinatorMain(int argc, char** argv) {
    CLI::App app{"vrl-coordinator: loads scenes, traces light paths, builds the VRL light tree once per job, and "
                 "leases image tiles to vrl-worker processes over gRPC"};
    app.set_version_flag("--version", std::string("vrl-coordinator ") + VRL_VERSION + " (protocol vrl.v1)");
    ServerOptions server;
    CoordinatorOptions options;
    std::string tokenFile, portFile, logLevel = "info", retention = "7d", removeOnExit;
    double leaseTimeout = 30.0, heartbeatTimeout = 10.0, drainTimeout = 30.0;
    int threads = 0;
    uint64_t maxBundleMiB = options.limits.maxBundleBytes >> 20;
    app.add_option("--listen", server.listen, "address to serve on (host:port; port 0 picks a free one)")
        ->capture_default_str();
    app.add_option("--state-dir", options.stateDir,
                   "bundles, job records, checkpoints and finished EXRs live here (kept across restarts)")
        ->capture_default_str();
    app.add_option("--token-file", tokenFile,
                   "file whose first line is the shared token every client and worker must send (default: the "
                   "VRL_TOKEN environment variable; none: no check)");
    app.add_option("--tls-cert", server.tls.certFile, "PEM server certificate: serve TLS");
    app.add_option("--tls-key", server.tls.keyFile, "PEM private key of --tls-cert");
    app.add_option("--tls-client-ca", server.tls.clientCaFile,
                   "PEM CA: workers must present a client certificate it signed");
    app.add_option("--lease-timeout", leaseTimeout, "seconds before an unreturned tile is leased again")
        ->capture_default_str()->check(CLI::Range(0.05, 86400.0));
    app.add_option("--heartbeat-timeout", heartbeatTimeout,
                   "seconds of silence after which a worker is considered dead and its tiles requeued")
        ->capture_default_str()->check(CLI::Range(0.05, 86400.0));
    app.add_option("--drain-timeout", drainTimeout, "seconds to wait for outstanding leases on SIGTERM")
        ->capture_default_str()->check(CLI::Range(0.0, 86400.0));
    app.add_option("--threads", threads, "threads for light tracing and tree building (0: all cores)")
        ->capture_default_str()->check(CLI::Range(0, 4096));
    app.add_option("--port-file", portFile, "write the bound port here once serving (for --listen ...:0)");
    app.add_option("--max-bundle-mib", maxBundleMiB, "largest scene bundle accepted, MiB")->capture_default_str()
        ->check(CLI::Range(uint64_t(1), uint64_t(1) << 20));
    app.add_option("--max-files", options.limits.maxBundleFiles, "most files in one scene bundle")
        ->capture_default_str()->check(CLI::Range(1u, 1000000u));
    app.add_option("--max-vrls", options.limits.maxVrls, "most VRLs (or light paths) one job may ask for")
        ->capture_default_str();
    app.add_option("--max-pixels", options.limits.maxPixels, "most pixels in one image")->capture_default_str();
    app.add_option("--retention", retention,
                   "finished jobs (done, failed, cancelled) are deleted this long after they end, with their images "
                   "and the bundles no other job uses (e.g. 7d, 12h, 30m, 90s; 0: keep them)")
        ->capture_default_str();
    // Hidden: `vrl render --workers` names its temporary folder, removed when this process ends (also
    // when the client was killed: the coordinator then gets SIGTERM from PR_SET_PDEATHSIG).
    app.add_option("--remove-on-exit", removeOnExit, "")->group("");
    app.add_option("--log-level", logLevel, "trace, debug, info, warn, error")->capture_default_str()
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    try {
        options.retention = util::parseDuration(retention);
    } catch (const std::invalid_argument& e) {
        std::fprintf(stderr, "vrl-coordinator: --retention: %s\n", e.what());
        return 2;
    }
    spdlog::set_level(spdlog::level::from_str(logLevel));
    // A second signal does not cut the drain short (the children of `vrl render --workers` run in a
    // process group of their own and are stopped by their client's SIGTERM, or by PR_SET_PDEATHSIG,
    // and a client killed by its second Ctrl-C while stopping us sends both). Made before `cleanup`
    // so that it outlives it: once the handlers are restored a late SIGTERM kills this process
    // outright, which left the --remove-on-exit folder behind when it came during the teardown.
    // Made before exitWithParent's PR_SET_PDEATHSIG too, so that signal is never fatal.
    util::TerminationSignals signals(false);
    // Removes the --remove-on-exit folder however this function returns.
    const std::unique_ptr<const std::string, void (*)(const std::string*)> cleanup(
        removeOnExit.empty() ? nullptr : &removeOnExit, [](const std::string* path) {
            std::error_code error;
            std::filesystem::remove_all(*path, error);
        });
    options.leaseTimeout = std::chrono::milliseconds(int64_t(leaseTimeout * 1000));
    options.heartbeatTimeout = std::chrono::milliseconds(int64_t(heartbeatTimeout * 1000));
    options.heartbeatInterval = std::max(std::chrono::milliseconds(10), options.heartbeatTimeout / 5);
    options.limits.maxBundleBytes = maxBundleMiB << 20;

    if (!util::exitWithParent()) return 1;  // started by `vrl render --workers`, whose process is gone

    std::optional<tbb::global_control> threadLimit;
    if (threads > 0) threadLimit.emplace(tbb::global_control::max_allowed_parallelism, size_t(threads));
    try {
        server.token = rpc::loadToken(tokenFile);
        Coordinator coordinator(options);
        CoordinatorServer service(coordinator, server);
        spdlog::info("vrl-coordinator {} serving on {} (port {}), state in '{}'", VRL_VERSION, server.listen,
                     service.port(), options.stateDir.string());
        if (!portFile.empty()) {
            util::writeFileAtomically(portFile, std::to_string(service.port()) + "\n");
        }
        int signal = 0;
        while ((signal = signals.wait(std::chrono::hours(1))) == 0) {
        }
        spdlog::info("signal {}: draining leases (at most {} s)", signal, drainTimeout);
        service.shutdown(std::chrono::milliseconds(int64_t(drainTimeout * 1000)));
        spdlog::info("stopped");
        return 0;
    } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
        return 1;
    }
}

}  // namespace vrl::server
