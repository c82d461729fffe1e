#include "worker/asset_fetcher.h"

#include "service/common/rpc_common.h"
#include "util/hash.h"
#include "vrl/v1/vrl.grpc.pb.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

namespace vrl::worker {

AssetFetcher::AssetFetcher(std::shared_ptr<grpc::Channel> channel, std::string token, int maxAttempts,
                           std::chrono::milliseconds streamTimeout)
    : channel_(std::move(channel)), token_(std::move(token)), maxAttempts_(maxAttempts), streamTimeout_(streamTimeout) {}

std::string AssetFetcher::fetch(const std::string& sha256, uint64_t expectedSize) {
    auto stub = v1::WorkerGateway::NewStub(channel_);
    std::string blob;
    blob.reserve(std::min<uint64_t>(expectedSize, uint64_t(64) << 20));  // grows with the data beyond that
    std::string problem;
    for (int attempt = 0; attempt < maxAttempts_; ++attempt) {
        if (attempt > 0) {
            std::lock_guard lock(mutex_);
            ++statistics_.retries;
        }
        grpc::ClientContext context;
        rpc::prepareContext(context, token_, streamTimeout_);
        v1::FetchAssetRequest request;
        request.set_sha256(sha256);
        request.set_offset(blob.size());
        auto reader = stub->FetchAsset(&context, request);
        v1::DataChunk chunk;
        bool broken = false;
        while (reader->Read(&chunk)) {
            if (chunk.offset() != blob.size() || util::crc32Of(chunk.data()) != chunk.crc32() ||
                blob.size() + chunk.data().size() > expectedSize) {
                problem = "chunk at offset " + std::to_string(chunk.offset()) + " failed its check";
                spdlog::warn("asset {}: {}; fetching again from offset {}", sha256.substr(0, 12), problem, blob.size());
                std::lock_guard lock(mutex_);
                ++statistics_.chunksRejected;
                broken = true;
                break;
            }
            blob += chunk.data();
        }
        if (broken) context.TryCancel();
        const grpc::Status status = reader->Finish();
        if (!broken && !status.ok()) {
            const auto code = status.error_code();
            if (code == grpc::StatusCode::NOT_FOUND || code == grpc::StatusCode::UNAUTHENTICATED)
                throw std::runtime_error("cannot fetch asset " + sha256 + ": " + rpc::describe(status));
            problem = rpc::describe(status);
            spdlog::warn("asset {}: stream failed ({}); resuming at offset {}", sha256.substr(0, 12), problem, blob.size());
            continue;
        }
        if (broken) continue;
        if (blob.size() < expectedSize) {
            problem = "stream ended at " + std::to_string(blob.size()) + " of " + std::to_string(expectedSize) + " bytes";
            spdlog::warn("asset {}: {}; resuming", sha256.substr(0, 12), problem);
            continue;
        }
        if (util::sha256Hex(blob) != sha256) {
            problem = "the whole blob fails its SHA-256";
            spdlog::warn("asset {}: {}; fetching it again", sha256.substr(0, 12), problem);
            blob.clear();
            continue;
        }
        std::lock_guard lock(mutex_);
        ++statistics_.blobs;
        statistics_.bytes += blob.size();
        return blob;
    }
    throw std::runtime_error("cannot fetch asset " + sha256 + " intact after " + std::to_string(maxAttempts_) +
                             " attempts (last problem: " + problem + ")");
}

FetchStatistics AssetFetcher::statistics() const {
    std::lock_guard lock(mutex_);
    return statistics_;
}

}  // namespace vrl::worker
