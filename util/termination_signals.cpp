#include "util/termination_signals.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace vrl::util {

namespace {

// The state the handler reaches. A signal handler cannot be given a pointer, so
// this is the one process-wide object; TerminationSignals owns it while alive.
struct HandlerState {
    std::atomic<bool> owned{false};
    std::atomic<int> first{0};
    std::atomic<bool> secondSignalExits{true};
    int pipe[2] = {-1, -1};
    struct sigaction previousInterrupt {};
    struct sigaction previousTerminate {};
};
HandlerState state;

extern "C" void onTerminationSignal(int signal) {
    int none = 0;
    if (!state.first.compare_exchange_strong(none, signal)) {
        if (state.secondSignalExits.load()) _exit(128 + signal);
        return;
    }
    const int savedErrno = errno;
    const char byte = char(signal);
    [[maybe_unused]] const ssize_t written = write(state.pipe[1], &byte, 1);
    errno = savedErrno;
}

}  // namespace

TerminationSignals::TerminationSignals(bool secondSignalExits) {
    if (state.owned.exchange(true)) throw std::logic_error("only one TerminationSignals may exist at a time");
    if (pipe2(state.pipe, O_CLOEXEC | O_NONBLOCK) != 0) {
        state.owned = false;
        throw std::runtime_error("cannot create the signal pipe");
    }
    state.first = 0;
    state.secondSignalExits = secondSignalExits;
    struct sigaction action {};
    action.sa_handler = onTerminationSignal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, &state.previousInterrupt);
    sigaction(SIGTERM, &action, &state.previousTerminate);
    // Threads that blocked these signals before (none of ours do) would never take them; unblock here too.
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
}

TerminationSignals::~TerminationSignals() {
    sigaction(SIGINT, &state.previousInterrupt, nullptr);
    sigaction(SIGTERM, &state.previousTerminate, nullptr);
    close(state.pipe[0]);
    close(state.pipe[1]);
    state.pipe[0] = state.pipe[1] = -1;
    state.owned = false;
}

int TerminationSignals::received() const { return state.first.load(); }

int TerminationSignals::wait(std::chrono::milliseconds timeout) const {
    if (const int signal = received()) return signal;
    pollfd fd{state.pipe[0], POLLIN, 0};
    poll(&fd, 1, int(std::max<std::chrono::milliseconds::rep>(0, timeout.count())));
    return received();
}

bool exitWithParent() {
    const char* parent = std::getenv("VRL_EXIT_WITH_PARENT");
    if (!parent) return true;
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    // The parent's pid, not "is my parent init?": in a container the parent may be pid 1.
    return std::to_string(getppid()) == parent;
}

}  // namespace vrl::util
