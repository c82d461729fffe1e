// Termination signals for the long-running programs (coordinator, worker, and
// the worker processes of `vrl render --workers`).
#pragma once

#include <csignal>

namespace vrl::util {

// Blocks SIGINT and SIGTERM in this thread and every thread started after (the
// caller takes them with sigwait on `signals`), and, when VRL_EXIT_WITH_PARENT
// is set (children of `vrl render --workers`), asks for SIGTERM when the parent
// dies. Returns false if the parent is already gone.
bool takeTerminationSignals(sigset_t& signals);

}  // namespace vrl::util
