// AssetFetcher: downloads a job's blob (scene bundle or serialised lights) from
// the coordinator's FetchAsset stream and proves it intact: every chunk must
// start where the last ended and match its CRC-32, and the whole blob must
// match its SHA-256. A bad chunk or a stream that stops early is fetched again
// from the last good offset; a whole-blob mismatch starts over.
#pragma once

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

namespace vrl::worker {

struct FetchStatistics {
    uint64_t blobs = 0, bytes = 0;
    uint64_t chunksRejected = 0;  // CRC or offset mismatches
    uint64_t retries = 0;         // streams started again
};

class AssetFetcher {
public:
    AssetFetcher(std::shared_ptr<grpc::Channel> channel, std::string token, int maxAttempts = 5,
                 std::chrono::milliseconds streamTimeout = std::chrono::minutes(10));
    // Throws std::runtime_error naming the asset once maxAttempts streams failed,
    // or at once for NOT_FOUND / UNAUTHENTICATED.
    std::string fetch(const std::string& sha256, uint64_t expectedSize);
    FetchStatistics statistics() const;

private:
    std::shared_ptr<grpc::Channel> channel_;
    std::string token_;
    int maxAttempts_;
    std::chrono::milliseconds streamTimeout_;
    mutable std::mutex mutex_;
    FetchStatistics statistics_;
};

}  // namespace vrl::worker
