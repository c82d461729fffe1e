// client/: the `vrl` program: render (embedded, --workers), submit, jobs, compare, info.
//
// The `vrl` subcommands. Each registers its flags on the app and, when run,
// stores its process exit code in `exitCode` (0 ok, 1 failure, 2 bad input).
#pragma once

#include <CLI/CLI.hpp>

namespace vrl::client {

void registerRenderCommand(CLI::App& app, int& exitCode);
void registerCompareCommand(CLI::App& app, int& exitCode);
void registerInfoCommand(CLI::App& app, int& exitCode);
// submit, jobs, cancel, health
void registerServiceCommands(CLI::App& app, int& exitCode);

}  // namespace vrl::client
