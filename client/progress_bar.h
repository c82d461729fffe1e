// ProgressBar: a thread-safe progress line on stderr for one phase. On a
// terminal it redraws in place with the elapsed time and an ETA; otherwise
// (logs, CI, a pipe) it prints a line every 10% with the elapsed time and ETA.
#pragma once

#include <chrono>
#include <mutex>
#include <string>

namespace vrl::client {

class ProgressBar {
public:
    explicit ProgressBar(std::string label);
    void update(double fraction);  // safe from any thread; fraction in [0, 1]
    // With a detail (e.g. "120/300 tiles, ETA 4.2 s") shown instead of the elapsed/left times.
    void update(double fraction, const std::string& detail);
    void finish();

private:
    std::string label_;
    std::mutex mutex_;
    bool terminal_;
    int lastShown_ = -1;  // per-mille on a terminal, per-ten otherwise
    bool finished_ = false;
    std::chrono::steady_clock::time_point start_;
};

}  // namespace vrl::client
