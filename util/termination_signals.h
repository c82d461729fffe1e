// TerminationSignals: how the programs take SIGINT and SIGTERM.
//
// Contract: while a TerminationSignals lives, SIGINT and SIGTERM run a handler
// (installed with sigaction, so it does not matter which thread the kernel
// picks, including threads that libraries start before main) that records the
// first signal and wakes wait() through a self-pipe. A second signal, when
// `secondSignalExits`, ends the process at once with _exit(128 + signal): the
// "press Ctrl-C again to quit now" of an interactive program. Programs that are
// themselves stopped by a parent (the coordinator and workers of `vrl render
// --workers`, which get SIGINT from the terminal and then SIGTERM from the
// client) pass false and finish their graceful stop. The destructor restores the
// previous handlers. At most one may live at a time (std::logic_error): a signal
// handler can reach only process-wide state, and this class is its only owner.
#pragma once

#include <chrono>

namespace vrl::util {

class TerminationSignals {
public:
    explicit TerminationSignals(bool secondSignalExits = true);
    ~TerminationSignals();
    TerminationSignals(const TerminationSignals&) = delete;
    TerminationSignals& operator=(const TerminationSignals&) = delete;

    // The first SIGINT or SIGTERM taken, 0 if none yet.
    int received() const;
    // Waits until a signal has been taken or `timeout` passes; returns received().
    int wait(std::chrono::milliseconds timeout) const;
    // The conventional exit status of a process stopped by `signal` (130 for SIGINT, 143 for SIGTERM).
    static int exitCode(int signal) { return 128 + signal; }
};

// For the children of `vrl render --workers` (VRL_EXIT_WITH_PARENT=<parent pid>):
// asks the kernel for SIGTERM when the parent dies. Returns false if the parent
// is already gone (the child should exit), true otherwise or when not a child.
bool exitWithParent();

}  // namespace vrl::util
