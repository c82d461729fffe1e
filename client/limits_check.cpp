#include "client/limits_check.h"

#include "service/common/limits_proto.h"
#include "service/common/rpc_common.h"
#include "service/job/job_scene.h"

#include <cstdio>
#include <stdexcept>

namespace vrl::client {

namespace {

std::string mebibytes(uint64_t bytes) {
    char text[64];
    std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / double(1 << 20));
    return text;
}

}  // namespace

void checkAgainstLimits(const v1::ServiceInfo& info, uint64_t bundleBytes, size_t bundleFiles,
                        const v1::JobSpec& spec, const std::string& address) {
    if (info.protocol_version() != rpc::kProtocolVersion)
        throw std::runtime_error("the coordinator at " + address + " (vrl " + info.program_version() +
                                 ") speaks protocol " + std::to_string(info.protocol_version()) + ", this vrl " +
                                 VRL_VERSION + " protocol " + std::to_string(rpc::kProtocolVersion) +
                                 "; use a vrl of the coordinator's version");
    const v1::ServiceLimits& l = info.limits();
    const std::string nothingSent = " of the coordinator at " + address + " (nothing was uploaded); ";
    if (bundleBytes > l.max_bundle_bytes()) {
        const uint64_t mib = (bundleBytes + (1 << 20) - 1) >> 20;
        throw std::invalid_argument("the scene bundle is " + mebibytes(bundleBytes) + " (" + std::to_string(bundleBytes) +
                                    " bytes), over the limit of " + mebibytes(l.max_bundle_bytes()) + nothingSent +
                                    "start vrl-coordinator with --max-bundle-mib " + std::to_string(mib) +
                                    " or more to accept it");
    }
    if (bundleFiles > l.max_bundle_files())
        throw std::invalid_argument("the scene bundle holds " + std::to_string(bundleFiles) +
                                    " files, over the limit of " + std::to_string(l.max_bundle_files()) + nothingSent +
                                    "start vrl-coordinator with --max-files " + std::to_string(bundleFiles) +
                                    " or more to accept it");
    const auto& p = spec.parameters();
    const uint64_t vrls = std::max(p.vrl_count(), p.light_paths());
    if (vrls > l.max_vrls())
        throw std::invalid_argument("the job asks for " + std::to_string(vrls) + " VRLs or light paths, over the limit of " +
                                    std::to_string(l.max_vrls()) + nothingSent + "start vrl-coordinator with --max-vrls " +
                                    std::to_string(vrls) + " or more to accept it");
    const uint64_t pixels = uint64_t(p.width()) * p.height();
    if (pixels > l.max_pixels())
        throw std::invalid_argument("the image has " + std::to_string(pixels) + " pixels (" + std::to_string(p.width()) +
                                    "x" + std::to_string(p.height()) + "), over the limit of " +
                                    std::to_string(l.max_pixels()) + nothingSent +
                                    "start vrl-coordinator with --max-pixels " + std::to_string(pixels) +
                                    " or more to accept it");
    const rpc::ServiceLimits limits = rpc::fromProto(l);
    try {
        rpc::validateJobSpec(spec, limits);
    } catch (const rpc::JobSpecError& e) {
        throw std::invalid_argument(std::string(e.what()) + " (refused before upload: the coordinator at " + address +
                                    " would not accept this job)");
    }
}

}  // namespace vrl::client
