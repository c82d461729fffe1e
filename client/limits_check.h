// Refusing a job before uploading it: `vrl submit` asks the coordinator for its
// ServiceInfo (GetServiceInfo) and checks the scene bundle and the job against
// the coordinator's limits, so that a bundle the coordinator would refuse is
// never sent. Each message gives the size, the limit and the vrl-coordinator
// flag that raises it.
#pragma once

#include "vrl/v1/vrl.pb.h"

#include <cstdint>
#include <string>

namespace vrl::client {

// Throws std::invalid_argument (exit 2) naming what is over which limit;
// std::runtime_error if the coordinator speaks another protocol version.
void checkAgainstLimits(const v1::ServiceInfo& info, uint64_t bundleBytes, size_t bundleFiles,
                        const v1::JobSpec& spec, const std::string& address);

}  // namespace vrl::client
