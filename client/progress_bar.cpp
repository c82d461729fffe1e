#include "client/progress_bar.h"

#include <unistd.h>

#include <cstdio>

namespace vrl::client {

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)), terminal_(isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}

void ProgressBar::update(double fraction) { update(fraction, std::string()); }

void ProgressBar::update(double fraction, const std::string& detail) {
    std::lock_guard lock(mutex_);
    if (finished_) return;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (terminal_) {
        const int perMille = int(fraction * 1000.0);
        if (perMille == lastShown_) return;
        lastShown_ = perMille;
        const int width = 40, filled = int(fraction * width);
        const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
        char times[96];
        std::snprintf(times, sizeof times, "%.1fs elapsed, ~%.1fs left", elapsed, eta);
        std::fprintf(stderr, "\r%s [%s%s] %5.1f%%  %s ", label_.c_str(), std::string(filled, '#').c_str(),
                     std::string(width - filled, '.').c_str(), fraction * 100.0,
                     detail.empty() ? times : detail.c_str());
    } else {
        const int tenth = int(fraction * 10.0);
        if (tenth == lastShown_) return;
        lastShown_ = tenth;
        char eta[48] = "";
        if (fraction > 0.0 && fraction < 1.0 && detail.empty())
            std::snprintf(eta, sizeof eta, ", ETA %.1fs", elapsed * (1.0 - fraction) / fraction);
        std::fprintf(stderr, "%s %3d%% (%.1fs%s%s%s)\n", label_.c_str(), tenth * 10, elapsed, eta,
                     detail.empty() ? "" : ", ", detail.c_str());
    }
    std::fflush(stderr);
}

void ProgressBar::finish() {
    std::lock_guard lock(mutex_);
    if (terminal_ && !finished_) std::fprintf(stderr, "\n");
    finished_ = true;
}

}  // namespace vrl::client
