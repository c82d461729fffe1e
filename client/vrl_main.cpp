// vrl: command-line entry point (render, compare).
#include "client/commands.h"

#include <spdlog/spdlog.h>

int main(int argc, char** argv) {
    CLI::App app{"vrl: scalable virtual ray lights (VRL Lightcuts) renderer for participating media"};
    app.set_version_flag("--version", std::string("vrl ") + VRL_VERSION);
    app.require_subcommand(1);
    int exitCode = 0;
    vrl::registerRenderCommand(app, exitCode);
    vrl::registerCompareCommand(app, exitCode);
    spdlog::set_pattern("[%l] %v");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version exit 0; every bad flag is bad input: exit 2.
        return app.exit(e) == 0 ? 0 : 2;
    }
    return exitCode;
}
