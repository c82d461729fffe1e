// ServiceLimits in and out of its API message (v1::ServiceLimits): the
// coordinator sends its limits in GetServiceInfo, the client checks a job
// against them before uploading. One mapping, field by field, both ways.
#pragma once

#include "service/common/limits.h"
#include "vrl/v1/vrl.pb.h"

namespace vrl::rpc {

v1::ServiceLimits toProto(const ServiceLimits& limits);
ServiceLimits fromProto(const v1::ServiceLimits& limits);

}  // namespace vrl::rpc
