// LocalCluster: `vrl render --workers N`. Starts a coordinator and N worker
// processes on loopback (this very executable, as `vrl coordinator` and `vrl
// worker`), with a fresh random token and a temporary state directory, and
// stops them (SIGTERM, SIGKILL after a grace period) when destroyed.
#pragma once

#include <filesystem>
#include <string>
#include <sys/types.h>
#include <vector>

namespace vrl::client {

class LocalCluster {
public:
    // Throws std::runtime_error if a process cannot start or the coordinator
    // does not come up within 30 s.
    LocalCluster(int workers, int threadsPerWorker, const std::string& logLevel);
    ~LocalCluster();
    LocalCluster(const LocalCluster&) = delete;
    LocalCluster& operator=(const LocalCluster&) = delete;

    const std::string& address() const { return address_; }
    const std::string& token() const { return token_; }
    // Throws if a process has exited (a worker that died leaves its tiles to the others, so only reports).
    std::vector<std::string> exitedProcesses();

private:
    pid_t spawn(const std::vector<std::string>& arguments);
    std::filesystem::path stateDir_;
    std::string token_, address_;
    std::vector<std::pair<std::string, pid_t>> processes_;  // coordinator first
};

}  // namespace vrl::client
