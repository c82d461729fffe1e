#include "client/local_cluster.h"

#include "service/common/rpc_common.h"
#include "util/random_id.h"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <random>
#include <stdexcept>
#include <thread>

extern char** environ;

namespace vrl::client {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

pid_t LocalCluster::spawn(const std::vector<std::string>& arguments) {
    std::vector<char*> argv;
    for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    std::vector<std::string> environment;
    for (char** e = environ; *e; ++e)
        if (std::string(*e).rfind("VRL_TOKEN=", 0) != 0) environment.emplace_back(*e);
    environment.push_back("VRL_TOKEN=" + token_);  // never on a command line, where ps could show it
    std::vector<char*> envp;
    for (auto& e : environment) envp.push_back(e.data());
    envp.push_back(nullptr);
    // VRL_EXIT_WITH_PARENT makes them stop if this process dies without cleaning up.
    environment.push_back("VRL_EXIT_WITH_PARENT=" + std::to_string(getpid()));
    envp.clear();
    for (auto& e : environment) envp.push_back(e.data());
    envp.push_back(nullptr);
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, 0);  // a group of its own: the terminal's Ctrl-C is this process's
    pid_t pid = 0;
    const int error = posix_spawn(&pid, "/proc/self/exe", nullptr, &attributes, argv.data(), envp.data());
    posix_spawnattr_destroy(&attributes);
    if (error != 0) throw std::runtime_error("cannot start '" + arguments[0] + " " + arguments[1] + "'");
    return pid;
}

LocalCluster::LocalCluster(int workers, int threadsPerWorker, const std::string& logLevel) {
    token_ = util::randomHex(32);
    stateDir_ = fs::temp_directory_path() / ("vrl-local-" + std::to_string(getpid()) + "-" + util::randomHex(8));
    fs::create_directories(stateDir_);
    const fs::path portFile = stateDir_ / "port";
    processes_.emplace_back("coordinator", spawn({"vrl", "coordinator", "--listen", "127.0.0.1:0", "--state-dir",
                                                  (stateDir_ / "state").string(), "--port-file", portFile.string(),
                                                  "--log-level", logLevel, "--drain-timeout", "5",
                                                  "--retention", "0", "--remove-on-exit", stateDir_.string()}));
    const auto until = std::chrono::steady_clock::now() + 30s;
    while (!fs::exists(portFile)) {
        if (!exitedProcesses().empty()) throw std::runtime_error("the local coordinator exited at start");
        if (std::chrono::steady_clock::now() > until) throw std::runtime_error("the local coordinator did not start in 30 s");
        std::this_thread::sleep_for(10ms);
    }
    int port = 0;
    std::ifstream(portFile) >> port;
    address_ = "127.0.0.1:" + std::to_string(port);
    for (int w = 0; w < workers; ++w)
        processes_.emplace_back("worker " + std::to_string(w + 1),
                                spawn({"vrl", "worker", "--coordinator", address_, "--threads",
                                       std::to_string(threadsPerWorker), "--name", "local-" + std::to_string(w + 1),
                                       "--log-level", logLevel}));
}

std::vector<std::string> LocalCluster::exitedProcesses() {
    std::vector<std::string> exited;
    for (auto& [name, pid] : processes_) {
        if (pid <= 0) {
            exited.push_back(name);
            continue;
        }
        int status = 0;
        if (waitpid(pid, &status, WNOHANG) == pid) {
            pid = -1;
            exited.push_back(name);
        }
    }
    return exited;
}

LocalCluster::~LocalCluster() {
    // Workers first (they return their leases), then the coordinator.
    for (size_t round = 0; round < 2; ++round) {
        for (size_t i = 0; i < processes_.size(); ++i) {
            const bool coordinator = i == 0;
            if ((round == 0) == coordinator) continue;
            if (processes_[i].second > 0) kill(processes_[i].second, SIGTERM);
        }
        for (size_t i = 0; i < processes_.size(); ++i) {
            const bool coordinator = i == 0;
            if ((round == 0) == coordinator) continue;
            pid_t& pid = processes_[i].second;
            const auto until = std::chrono::steady_clock::now() + 10s;
            while (pid > 0) {
                int status = 0;
                if (waitpid(pid, &status, WNOHANG) == pid) {
                    pid = -1;
                } else if (std::chrono::steady_clock::now() > until) {
                    kill(pid, SIGKILL);
                    waitpid(pid, &status, 0);
                    pid = -1;
                } else {
                    std::this_thread::sleep_for(5ms);
                }
            }
        }
    }
    std::error_code error;
    fs::remove_all(stateDir_, error);
}

}  // namespace vrl::client
