#include "server/job.h"

#include "render/core/timing.h"

#include <algorithm>

namespace vrl::server {

bool isTerminal(v1::JobState state) {
    return state == v1::JOB_STATE_DONE || state == v1::JOB_STATE_FAILED || state == v1::JOB_STATE_CANCELLED;
}

int64_t unixMillisecondsNow() {
    return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

v1::JobProgress progressOf(const Job& job) {
    v1::JobProgress p;
    p.set_job_id(job.id);
    p.set_state(job.state);
    p.set_name(job.spec.name());
    p.set_priority(job.spec.priority());
    p.set_message(job.message);
    p.set_tiles_total(uint32_t(job.tiles.size()));
    // A time-limited job renders pass after pass: its tiles count the pass under way.
    p.set_tiles_done(job.passes.progressive() ? job.passes.tilesInCurrentPass() : job.doneCount);
    p.set_passes_done(uint32_t(job.passes.passesDone()));
    p.set_passes_total(uint32_t(job.passes.passesTotal()));
    p.set_samples_per_pixel(samplesAfter(job.passes.passesDone(), job.settings.samplesPerPixel));
    p.set_time_limit_seconds(job.settings.timeLimitSeconds);
    p.set_preparing_fraction(job.preparingFraction);
    p.set_preparing_phase(job.preparingPhase);
    for (const std::string& phase : job.preparingPhasesDone) p.add_preparing_phases_done(phase);
    p.set_submitted_unix_ms(job.submittedUnixMs);
    p.set_finished_unix_ms(job.finishedUnixMs);
    double eta = -1.0;
    if (job.state == v1::JOB_STATE_RENDERING && job.deadline) {
        eta = std::max(0.0, std::chrono::duration<double>(*job.deadline - std::chrono::steady_clock::now()).count());
    } else if (job.state == v1::JOB_STATE_RENDERING && job.doneCount > job.doneAtStart) {
        const double elapsed = secondsSince(job.renderStart);
        eta = elapsed / double(job.doneCount - job.doneAtStart) * double(job.tiles.size() - job.doneCount);
    } else if (job.state == v1::JOB_STATE_DONE) {
        eta = 0.0;
    }
    p.set_eta_seconds(eta);
    for (const auto& [name, share] : job.workers) {
        auto* w = p.add_workers();
        w->set_worker(name);
        w->set_tiles(share.tiles);
        w->set_pixels_per_second(share.seconds > 0.0 ? double(share.pixels) / share.seconds : 0.0);
    }
    for (const auto& [phase, seconds] : job.phases) {
        auto* t = p.add_phases();
        t->set_phase(phase);
        t->set_seconds(seconds);
    }
    return p;
}

}  // namespace vrl::server
