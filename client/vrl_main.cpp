// vrl: command-line entry point (render, compare, submit, jobs, cancel, health).
// `vrl coordinator ...` and `vrl worker ...` run vrl-coordinator and vrl-worker
// in this executable, so that `render --workers N` needs nothing else on disk.
#include "client/commands.h"
#include "server/coordinator_main.h"
#include "worker/worker_main.h"

#include <cstring>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

int main(int argc, char** argv) {
    // Logs go to stderr, in every mode: stdout holds results only (e.g. J=$(vrl submit --detach ...)).
    spdlog::set_default_logger(spdlog::stderr_color_mt("vrl"));
    if (argc >= 2 && std::strcmp(argv[1], "coordinator") == 0) return vrl::server::coordinatorMain(argc - 1, argv + 1);
    if (argc >= 2 && std::strcmp(argv[1], "worker") == 0) return vrl::worker::workerMain(argc - 1, argv + 1);
    CLI::App app{"vrl: scalable virtual ray lights (VRL Lightcuts) renderer for participating media"};
    app.set_version_flag("--version", std::string("vrl ") + VRL_VERSION);
    app.require_subcommand(1);
    int exitCode = 0;
    vrl::client::registerRenderCommand(app, exitCode);
    vrl::client::registerCompareCommand(app, exitCode);
    vrl::client::registerInfoCommand(app, exitCode);
    vrl::client::registerServiceCommands(app, exitCode);
    app.footer("Also: `vrl coordinator --help` and `vrl worker --help` (the vrl-coordinator and vrl-worker programs).");
    spdlog::set_pattern("[%l] %v");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; every bad flag is bad input: exit 2.
        return app.exit(e) == 0 ? 0 : 2;
    }
    return exitCode;
}
