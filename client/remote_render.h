// Rendering through a coordinator: collect the scene bundle, check it and the
// job against the coordinator's limits (GetServiceInfo) before uploading
// anything, upload (once, by hash), submit, show progress (one bar per phase:
// light tracing, light tree, rendering), fetch the EXR. Used by `vrl submit`
// and by `vrl render --workers N`.
//
// What a user can rely on:
//  - stdout holds results only (the job id with --detach); everything else is on stderr.
//  - SIGINT/SIGTERM while watching: `vrl submit` leaves the job running and prints
//    the commands to re-attach and to cancel; `render --workers` (partialOnSignal)
//    writes the tiles finished so far as a partial EXR, cancels the job. Both exit
//    128 + signal; a second signal exits at once (util::TerminationSignals).
//  - A coordinator that becomes UNAVAILABLE (a restart) is retried with backoff
//    (0.5 s doubling to 8 s) for retryFor, then the job is re-attached by id.
//  - No worker connected for noWorkerWarning while the job waits: one hint on
//    how to start one.
#pragma once

#include "client/command_line_job.h"
#include "client/render_options.h"
#include "service/common/rpc_common.h"
#include "util/termination_signals.h"

#include <chrono>
#include <string>

namespace vrl::client {

struct RemoteOptions {
    std::string address;
    rpc::TlsOptions tls;
    std::string token;
    std::string tokenFile;   // as given (shown in the commands printed for the user)
    int priority = 0;
    bool detach = false;     // print the job id and return once submitted
    std::string attachJob;   // re-attach to this job instead of submitting
    std::chrono::seconds retryFor{300};                  // 0: an unreachable coordinator is an error at once
    std::chrono::milliseconds noWorkerWarning{15000};    // 0: never warn
    bool partialOnSignal = false;  // render --workers: on a signal, write the finished tiles and cancel
};

// Submits `job` (resolveCommandLineJob of `o`), or with remote.attachJob watches
// that job instead (`job` may then be null); `o` gives the outputs and -q.
// Returns the process exit code (0 done, 1 failed/cancelled/unreachable, 2 refused
// input, 128 + signal when interrupted).
int runRemoteRender(const RenderCommandOptions& o, const RemoteOptions& remote, const util::TerminationSignals& signals,
                    const CommandLineJob* job);

}  // namespace vrl::client
