#include "worker/worker_main.h"

#include "util/termination_signals.h"
#include "worker/worker.h"

#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <unistd.h>
#include <thread>

namespace vrl::worker {

int workerMain(int argc, char** argv) {
    CLI::App app{"vrl-worker: shades image tiles leased from a vrl-coordinator with the scalable VRL estimator"};
    app.set_version_flag("--version", std::string("vrl-worker ") + VRL_VERSION + " (protocol vrl.v1)");
    WorkerOptions options;
    std::string tokenFile, logLevel = "info";
    app.add_option("--coordinator", options.coordinator, "coordinator address (host:port)")->capture_default_str();
    app.add_option("--threads", options.threads, "shading threads (0: all cores)")->capture_default_str()
        ->check(CLI::Range(0, 4096));
    app.add_option("--name", options.name, "name shown in job progress (default: host:pid)");
    app.add_option("--token-file", tokenFile,
                   "file whose first line is the coordinator's shared token (default: VRL_TOKEN)");
    app.add_option("--tls-ca", options.tls.caFile, "PEM CA of the coordinator's certificate: connect with TLS");
    app.add_option("--tls-cert", options.tls.certFile, "PEM client certificate (with --tls-ca)");
    app.add_option("--tls-key", options.tls.keyFile, "PEM private key of --tls-cert");
    app.add_option("--cache-dir", options.cacheDir,
                   "where downloaded bundles are kept by hash (default: a temporary folder removed at exit)");
    app.add_option("--max-cached-jobs", options.maxCachedJobs, "jobs kept loaded at once")->capture_default_str()
        ->check(CLI::Range(size_t(1), size_t(1024)));
    app.add_option("--health-listen", options.healthListen,
                   "serve the gRPC health service here (e.g. 0.0.0.0:50052) for liveness probes");
    app.add_option("--log-level", logLevel, "trace, debug, info, warn, error")->capture_default_str()
        ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;
    }
    if (options.tls.certFile.empty() != options.tls.keyFile.empty()) {
        std::fprintf(stderr, "vrl-worker: error: --tls-cert and --tls-key go together\n");
        return 2;
    }
    spdlog::set_level(spdlog::level::from_str(logLevel));
    // Before exitWithParent's PR_SET_PDEATHSIG, so that its SIGTERM is always caught. A second signal
    // does not cut the tiles in flight short.
    util::TerminationSignals signals(false);
    if (!util::exitWithParent()) return 1;  // started by `vrl render --workers`, whose process is gone
    try {
        options.token = rpc::loadToken(tokenFile);
        Worker worker(options);
        std::atomic<bool> finished{false};
        std::thread signalThread([&] {
            while (!finished) {
                if (const int signal = signals.wait(std::chrono::milliseconds(200))) {
                    spdlog::info("signal {}: finishing the tiles in flight", signal);
                    worker.stop();
                    return;
                }
            }
        });
        int code = 0;
        try {
            worker.run();
        } catch (const WorkerRefused& e) {
            spdlog::error("{}", e.what());
            code = 3;
        } catch (const std::exception& e) {
            spdlog::error("{}", e.what());
            code = 1;
        }
        finished = true;
        signalThread.join();
        return code;
    } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
        return 1;
    }
}

}  // namespace vrl::worker
