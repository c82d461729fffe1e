// The `vrl-coordinator` program (also `vrl coordinator`): flags, signals, logs.
#pragma once

namespace vrl::server {

// Parses flags and serves until SIGINT/SIGTERM, then drains leases and exits.
// Returns the process exit code (0 ok, 1 runtime failure, 2 bad flags).
int coordinatorMain(int argc, char** argv);

}  // namespace vrl::server
