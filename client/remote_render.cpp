#include "client/remote_render.h"

#include "client/job_client.h"
#include "client/progress_bar.h"
#include "render/core/timing.h"
#include "render/image/exr_io.h"
#include "render/image/preview_image.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <cstdio>
#include <memory>

namespace vrl::client {

int runRemoteRender(const RenderCommandOptions& o, const RemoteOptions& remote) {
    const auto start = std::chrono::steady_clock::now();
    JobClient client(remote.address, remote.tls, remote.token);
    std::string jobId = remote.attachJob;
    if (jobId.empty()) {
        v1::JobSpec spec = makeJobSpec(o);
        spec.set_priority(remote.priority);
        const std::string blob = collectSceneBundle(o.scene, parseDefines(o.defines));
        bool uploaded = false;
        spec.set_bundle_sha256(client.uploadBundle(blob, &uploaded));
        spdlog::info("scene bundle {} ({} bytes) {}", spec.bundle_sha256().substr(0, 12), blob.size(),
                     uploaded ? "uploaded" : "already held by the coordinator");
        jobId = client.submit(spec);
        std::fprintf(stderr, "job %s submitted to %s\n", jobId.c_str(), remote.address.c_str());
        if (remote.detach) {
            std::printf("%s\n", jobId.c_str());
            return 0;
        }
    }
    std::unique_ptr<ProgressBar> bar;
    v1::JobState shown = v1::JOB_STATE_UNSPECIFIED;
    const v1::JobProgress last = client.watch(jobId, [&](const v1::JobProgress& p) {
        if (o.quiet) return;
        if (p.state() != shown && (p.state() == v1::JOB_STATE_PREPARING || p.state() == v1::JOB_STATE_RENDERING)) {
            if (bar) bar->finish();
            bar = std::make_unique<ProgressBar>(p.state() == v1::JOB_STATE_PREPARING ? "preparing" : "rendering");
            shown = p.state();
        }
        if (!bar) return;
        if (p.state() == v1::JOB_STATE_PREPARING) {
            bar->update(p.preparing_fraction());
        } else if (p.state() == v1::JOB_STATE_RENDERING && p.tiles_total() > 0) {
            char detail[128];
            if (p.eta_seconds() >= 0)
                std::snprintf(detail, sizeof detail, "%u/%u tiles, %d workers, ETA %.1f s", p.tiles_done(),
                              p.tiles_total(), p.workers_size(), p.eta_seconds());
            else
                std::snprintf(detail, sizeof detail, "%u/%u tiles", p.tiles_done(), p.tiles_total());
            bar->update(double(p.tiles_done()) / p.tiles_total(), detail);
        }
    });
    if (bar) bar->finish();
    if (last.state() != v1::JOB_STATE_DONE) {
        std::fprintf(stderr, "vrl: job %s %s%s%s\n", jobId.c_str(),
                     last.state() == v1::JOB_STATE_CANCELLED ? "was cancelled" : "failed",
                     last.message().empty() ? "" : ": ", last.message().c_str());
        return 1;
    }
    client.fetchImage(jobId, o.output);
    if (!o.preview.empty()) {
        const ImageSet images = readExr(o.output);
        writePreviewPng(images.image, o.preview, autoExposure(images.image));
    }
    std::fprintf(stderr, "summary: job %s, %u tiles, %.3f s in all -> %s\n", jobId.c_str(), last.tiles_total(),
                 secondsSince(start), o.output.c_str());
    for (const auto& phase : last.phases()) std::fprintf(stderr, "  %-18s %8.3f s\n", phase.phase().c_str(), phase.seconds());
    for (const auto& w : last.workers())
        std::fprintf(stderr, "  worker %-16s %6llu tiles, %.3g pixels/s per thread\n", w.worker().c_str(),
                     (unsigned long long)w.tiles(), w.pixels_per_second());
    return 0;
}

}  // namespace vrl::client
