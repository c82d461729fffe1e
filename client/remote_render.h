// Rendering through a coordinator: collect and upload the scene bundle (once,
// by hash), submit, show progress (tiles, ETA), fetch the EXR. Used by `vrl
// submit` and by `vrl render --workers N`.
#pragma once

#include "client/render_options.h"
#include "service/common/rpc_common.h"

#include <string>

namespace vrl::client {

struct RemoteOptions {
    std::string address;
    rpc::TlsOptions tls;
    std::string token;
    int priority = 0;
    bool detach = false;     // print the job id and return once submitted
    std::string attachJob;   // re-attach to this job instead of submitting
};

// Returns the process exit code (0 done, 1 failed/cancelled/unreachable, 2 refused input).
int runRemoteRender(const RenderCommandOptions& o, const RemoteOptions& remote);

}  // namespace vrl::client
