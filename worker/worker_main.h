// The `vrl-worker` program (also `vrl worker`): flags, SIGTERM, logs.
#pragma once

namespace vrl::worker {

// Serves a coordinator until SIGINT/SIGTERM (tiles in flight are finished and
// returned). Exit codes: 0 ok, 1 runtime failure, 2 bad flags, 3 refused by
// the coordinator (version, token, certificate).
int workerMain(int argc, char** argv);

}  // namespace vrl::worker
