#include "client/remote_render.h"

#include "client/job_client.h"
#include "client/limits_check.h"
#include "client/output_checks.h"
#include "client/progress_bar.h"
#include "render/core/timing.h"
#include "render/image/exr_io.h"
#include "render/image/preview_image.h"
#include "service/job/scene_bundle.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>

namespace vrl::client {

namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr std::chrono::milliseconds kFirstBackoff = 500ms, kMaxBackoff = 8s;

bool ended(v1::JobState state) {
    return state == v1::JOB_STATE_DONE || state == v1::JOB_STATE_FAILED || state == v1::JOB_STATE_CANCELLED;
}

std::string connectionFlags(const RemoteOptions& remote) {
    std::string flags = " --coordinator " + remote.address;
    if (!remote.tokenFile.empty()) flags += " --token-file " + remote.tokenFile;
    if (!remote.tls.caFile.empty()) flags += " --tls-ca " + remote.tls.caFile;
    return flags;
}

std::string reattachCommand(const std::string& jobId, const RemoteOptions& remote, const RenderCommandOptions& o) {
    return "vrl submit --attach " + jobId + connectionFlags(remote) + " -o " + o.output +
           (o.preview.empty() ? "" : " --preview " + o.preview);
}

std::string cancelCommand(const std::string& jobId, const RemoteOptions& remote) {
    return "vrl cancel " + jobId + connectionFlags(remote);
}

// Retries calls that found the coordinator UNAVAILABLE (restarting): backoff 0.5 s doubling to
// 8 s, for at most `limit` since the first failure, and says so on stderr.
class Reconnection {
public:
    Reconnection(std::chrono::seconds limit, const util::TerminationSignals& signals, std::string address)
        : limit_(limit), signals_(signals), address_(std::move(address)) {}

    // After a failed call: true once it has waited for the next attempt; false when the error is not
    // UNAVAILABLE, the limit has passed (expired()) or a signal came.
    bool retry(const JobClientError& error) {
        if (error.code != grpc::StatusCode::UNAVAILABLE || limit_.count() == 0) return false;
        const auto now = Clock::now();
        if (!since_) {
            since_ = now;
            backoff_ = kFirstBackoff;
            std::fprintf(stderr, "vrl: the coordinator at %s is unavailable (%s); retrying for up to %lld s\n",
                         address_.c_str(), error.what(), (long long)limit_.count());
        }
        if (now - *since_ >= limit_) {
            expired_ = true;
            return false;
        }
        if (signals_.wait(std::chrono::duration_cast<std::chrono::milliseconds>(backoff_)) != 0) return false;
        backoff_ = std::min<std::chrono::milliseconds>(backoff_ * 2, kMaxBackoff);
        return true;
    }
    // A call went through: if it followed failures, says the job is re-attached.
    void succeeded(const std::string& jobId) {
        if (!since_) return;
        std::fprintf(stderr, "vrl: the coordinator at %s is back; re-attached to job %s\n", address_.c_str(),
                     jobId.c_str());
        since_.reset();
    }
    bool expired() const { return expired_; }

private:
    std::chrono::seconds limit_;
    const util::TerminationSignals& signals_;
    std::string address_;
    std::optional<Clock::time_point> since_;
    std::chrono::milliseconds backoff_ = kFirstBackoff;
    bool expired_ = false;
};

// One progress bar per phase (the coordinator's preparation phases, then "rendering"); a
// phase's bar ends at 100% once the next phase (or the end of the job) shows it is over.
class ProgressDisplay {
public:
    explicit ProgressDisplay(bool quiet) : quiet_(quiet) {}

    void show(const v1::JobProgress& p) {
        if (quiet_) return;
        // Phases that ended since the last update, each as a finished bar (one may have begun and
        // ended between two polls).
        for (; shownDone_ < p.preparing_phases_done_size(); ++shownDone_) {
            begin(p.preparing_phases_done(shownDone_));
            end(true);
        }
        if (p.state() == v1::JOB_STATE_PREPARING) {
            begin(p.preparing_phase().empty() ? "loading the scene" : p.preparing_phase());
            bar_->update(std::clamp(p.preparing_fraction(), 0.0, 1.0));
        } else if (p.state() == v1::JOB_STATE_RENDERING && p.tiles_total() > 0) {
            begin(renderingLabel(p));  // a time-limited job: one bar per pass, as the embedded render shows
            bar_->update(double(p.tiles_done()) / p.tiles_total(), detail(p));
        } else if (p.state() == v1::JOB_STATE_DONE) {
            if (bar_ && label_.rfind("rendering", 0) == 0 && p.time_limit_seconds() <= 0.0) bar_->update(1.0, detail(p));
            end(true);
        } else if (ended(p.state())) {
            end(false);
        }
    }
    void stop() { end(false); }

private:
    static std::string renderingLabel(const v1::JobProgress& p) {
        if (p.time_limit_seconds() <= 0.0) return "rendering";
        return "rendering pass " + std::to_string(p.passes_done() + 1) + " (" + std::to_string(p.passes_done()) +
               " done, " + std::to_string(p.samples_per_pixel()) + " spp)";
    }
    static std::string detail(const v1::JobProgress& p) {
        char text[128];
        if (p.time_limit_seconds() > 0.0 && p.state() == v1::JOB_STATE_RENDERING)
            std::snprintf(text, sizeof text, "%u/%u tiles, %d workers, %.1f s left", p.tiles_done(), p.tiles_total(),
                          p.workers_size(), std::max(0.0, p.eta_seconds()));
        else if (p.eta_seconds() >= 0 && p.state() == v1::JOB_STATE_RENDERING)
            std::snprintf(text, sizeof text, "%u/%u tiles, %d workers, ETA %.1f s", p.tiles_done(), p.tiles_total(),
                          p.workers_size(), p.eta_seconds());
        else
            std::snprintf(text, sizeof text, "%u/%u tiles", p.tiles_done(), p.tiles_total());
        return text;
    }
    void begin(const std::string& label) {
        if (bar_ && label == label_) return;
        end(true);  // the previous phase is over
        bar_ = std::make_unique<ProgressBar>(label);
        label_ = label;
    }
    void end(bool complete) {
        if (!bar_) return;
        if (complete && label_.rfind("rendering", 0) != 0) bar_->update(1.0);
        bar_->finish();
        bar_.reset();
        label_.clear();
    }

    bool quiet_;
    std::unique_ptr<ProgressBar> bar_;
    std::string label_;
    int shownDone_ = 0;  // entries of preparing_phases_done shown
};

// Once: "no worker has connected ..." when the coordinator has had no worker for `after` while the job waits.
// tick() runs on JobClient::watch's polling thread.
class NoWorkerHint {
public:
    NoWorkerHint(JobClient& client, const RemoteOptions& remote)
        : client_(client), address_(remote.address), after_(remote.noWorkerWarning), lastSeen_(Clock::now()) {}

    void tick() {
        if (after_.count() == 0 || shown_) return;
        const auto now = Clock::now();
        if (now - lastAsked_ < 1s) return;
        lastAsked_ = now;
        v1::ServiceInfo info;
        try {
            info = client_.serviceInfo(2s);
        } catch (const JobClientError&) {
            return;  // unreachable: the watch itself reports that
        }
        if (info.workers_connected() > 0) {
            lastSeen_ = now;
            return;
        }
        if (now - lastSeen_ < after_) return;
        shown_ = true;
        const long long seconds = std::chrono::duration_cast<std::chrono::seconds>(after_).count();
        std::fprintf(stderr, "vrl: no worker has connected to %s for %lld s; start one with: vrl-worker --coordinator %s%s\n",
                     address_.c_str(), seconds, address_.c_str(),
                     info.token_required() ? " --token-file FILE (the coordinator requires its token; or set VRL_TOKEN)"
                                           : "");
    }

private:
    JobClient& client_;
    std::string address_;
    std::chrono::milliseconds after_;
    Clock::time_point lastSeen_, lastAsked_{};
    bool shown_ = false;
};

// Submits the job (resolved, its outputs checked: what remains is the coordinator's limits); returns the job id.
std::string submitScene(JobClient& client, const RenderCommandOptions& o, const RemoteOptions& remote,
                        const CommandLineJob* job) {
    if (!job) throw std::invalid_argument("give a scene file to submit, or --attach JOB to re-attach to a submitted job");
    v1::JobSpec spec = job->spec;
    spec.set_priority(remote.priority);
    size_t bundleFiles = 0;  // the bundle's entries: the files the parse met, each once, the scene among them
    const std::string blob = rpc::makeBundleBlob(o.scene, job->sceneFiles, &bundleFiles);
    checkAgainstLimits(client.serviceInfo(), blob.size(), bundleFiles, spec, remote.address);
    bool uploaded = false;
    spec.set_bundle_sha256(client.uploadBundle(blob, &uploaded));
    spdlog::info("scene bundle {} ({} bytes) {}", spec.bundle_sha256().substr(0, 12), blob.size(),
                 uploaded ? "uploaded" : "already held by the coordinator");
    const std::string jobId = client.submit(spec);
    if (!o.quiet) std::fprintf(stderr, "job %s submitted to %s\n", jobId.c_str(), remote.address.c_str());
    return jobId;
}

// A signal while watching: submit leaves the job and says how to come back; render --workers keeps
// the finished tiles and cancels the job.
int interrupted(JobClient& client, const std::string& jobId, int signal, const RenderCommandOptions& o,
                const RemoteOptions& remote) {
    std::fprintf(stderr, "\n");
    if (!remote.partialOnSignal) {
        std::fprintf(stderr,
                     "vrl: interrupted (signal %d); job %s keeps running on %s.\n"
                     "  re-attach: %s\n"
                     "  cancel:    %s\n",
                     signal, jobId.c_str(), remote.address.c_str(), reattachCommand(jobId, remote, o).c_str(),
                     cancelCommand(jobId, remote).c_str());
        return util::TerminationSignals::exitCode(signal);
    }
    std::fprintf(stderr, "vrl: interrupted (signal %d): keeping the tiles finished so far\n", signal);
    try {
        client.fetchImage(jobId, o.output, true);
        const ImageSet images = readExr(o.output);
        const auto done = images.metadata.find("vrl.partial"), total = images.metadata.find("vrl.tilesTotal");
        if (done != images.metadata.end() && total != images.metadata.end())
            std::fprintf(stderr, "vrl: partial image with %.0f of %.0f tiles written to %s (unfinished pixels are 0; "
                                 "layer \"coverage\" marks the finished ones)\n",
                         metadataNumber(done->second), metadataNumber(total->second), o.output.c_str());
        else if (const auto passes = images.metadata.find("vrl.progressive.passes"); passes != images.metadata.end())
            std::fprintf(stderr, "vrl: wrote the %.0f completed passes (%.0f spp) to %s\n",
                         metadataNumber(passes->second), metadataNumber(images.metadata.at("vrl.spp")), o.output.c_str());
        else
            std::fprintf(stderr, "vrl: the whole image was done: written to %s\n", o.output.c_str());
        if (!o.preview.empty()) writePreviewPng(images.image, o.preview, autoExposure(images.image));
    } catch (const JobClientError& e) {
        std::fprintf(stderr, "vrl: no partial image written: %s\n", e.what());
    }
    try {
        client.cancel(jobId);
    } catch (const JobClientError& e) {
        std::fprintf(stderr, "vrl: could not cancel job %s: %s\n", jobId.c_str(), e.what());
    }
    return util::TerminationSignals::exitCode(signal);
}

int unreachable(const std::string& jobId, const RemoteOptions& remote, const RenderCommandOptions& o) {
    std::fprintf(stderr,
                 "vrl: error: the coordinator at %s stayed unreachable for %lld s (--retry-for); the job may still "
                 "run there.\n  re-attach later: %s\n",
                 remote.address.c_str(), (long long)remote.retryFor.count(), reattachCommand(jobId, remote, o).c_str());
    return 1;
}

}  // namespace

int runRemoteRender(const RenderCommandOptions& o, const RemoteOptions& remote, const util::TerminationSignals& signals,
                    const CommandLineJob* job) {
    const auto start = Clock::now();
    JobClient client(remote.address, remote.tls, remote.token);
    std::string jobId = remote.attachJob;
    if (jobId.empty()) {
        jobId = submitScene(client, o, remote, job);
        if (remote.detach) {
            std::printf("%s\n", jobId.c_str());
            return 0;
        }
    } else {
        checkOutputPaths(o.output, o.preview, {});
    }

    Reconnection reconnection(remote.retryFor, signals, remote.address);
    ProgressDisplay display(o.quiet);
    NoWorkerHint noWorker(client, remote);
    v1::JobProgress last;
    while (true) {
        try {
            last = client.watch(
                jobId,
                [&](const v1::JobProgress& p) {
                    reconnection.succeeded(jobId);
                    display.show(p);
                },
                [&] {
                    noWorker.tick();
                    return signals.received() != 0;
                });
            break;
        } catch (const WatchInterrupted&) {
            display.stop();
            return interrupted(client, jobId, signals.received(), o, remote);
        } catch (const JobClientError& e) {
            if (reconnection.retry(e)) continue;
            display.stop();
            if (signals.received() != 0) return interrupted(client, jobId, signals.received(), o, remote);
            if (reconnection.expired()) return unreachable(jobId, remote, o);
            throw;
        }
    }
    display.stop();
    if (last.state() != v1::JOB_STATE_DONE) {
        std::fprintf(stderr, "vrl: job %s %s%s%s\n", jobId.c_str(),
                     last.state() == v1::JOB_STATE_CANCELLED ? "was cancelled" : "failed",
                     last.message().empty() ? "" : ": ", last.message().c_str());
        return 1;
    }
    while (true) {
        try {
            client.fetchImage(jobId, o.output);
            reconnection.succeeded(jobId);
            break;
        } catch (const JobClientError& e) {
            if (reconnection.retry(e)) continue;
            if (signals.received() != 0) return util::TerminationSignals::exitCode(signals.received());
            if (reconnection.expired()) return unreachable(jobId, remote, o);
            throw;
        }
    }
    if (!o.preview.empty()) {
        const ImageSet images = readExr(o.output);
        writePreviewPng(images.image, o.preview, autoExposure(images.image));
    }
    if (last.time_limit_seconds() > 0.0 && last.passes_done() == 0)
        std::fprintf(stderr, "vrl: the time limit ran out in the first pass: %s is a partial image (unfinished tiles "
                             "are 0; see its 'coverage' layer and vrl.partial)\n", o.output.c_str());
    if (o.quiet) return 0;  // -q: warnings and errors only
    std::fprintf(stderr, "summary: job %s, %u tiles, %.3f s in all -> %s\n", jobId.c_str(), last.tiles_total(),
                 secondsSince(start), o.output.c_str());
    if (last.time_limit_seconds() > 0.0)
        std::fprintf(stderr, "  progressive: %u passes completed in the %.3g s time limit -> %d spp\n",
                     last.passes_done(), last.time_limit_seconds(), last.samples_per_pixel());
    for (const auto& phase : last.phases()) std::fprintf(stderr, "  %-18s %8.3f s\n", phase.phase().c_str(), phase.seconds());
    for (const auto& w : last.workers())
        std::fprintf(stderr, "  worker %-16s %6llu tiles, %.3g pixels/s per thread\n", w.worker().c_str(),
                     (unsigned long long)w.tiles(), w.pixels_per_second());
    return 0;
}

}  // namespace vrl::client
