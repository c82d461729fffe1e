// AssetFetcher against a fake coordinator that corrupts and truncates chunks:
// a bad chunk is rejected and fetched again, a short stream resumed, and a blob
// that never matches its hash is an error, not a silently wrong scene.
#include "service/common/rpc_common.h"
#include "util/hash.h"
#include "vrl/v1/vrl.grpc.pb.h"
#include "worker/asset_fetcher.h"

#include <gtest/gtest.h>

#include <atomic>

namespace vrl {
namespace {

// Serves one blob; `fault(call)` says what to do wrong on the call-th stream.
enum class Fault { None, CorruptSecondChunk, StopAfterFirstChunk, WrongBytesGoodCrc };

class FakeGateway final : public v1::WorkerGateway::Service {
public:
    FakeGateway(std::string blob, std::vector<Fault> faults) : blob_(std::move(blob)), faults_(std::move(faults)) {}
    grpc::Status FetchAsset(grpc::ServerContext*, const v1::FetchAssetRequest* request,
                            grpc::ServerWriter<v1::DataChunk>* writer) override {
        const size_t call = calls_++;
        const Fault fault = call < faults_.size() ? faults_[call] : Fault::None;
        uint64_t offset = request->offset();
        for (int index = 0; offset < blob_.size(); ++index) {
            const size_t size = std::min<size_t>(rpc::kChunkBytes, blob_.size() - offset);
            v1::DataChunk chunk;
            chunk.set_offset(offset);
            chunk.set_data(blob_.substr(offset, size));
            chunk.set_crc32(util::crc32Of(chunk.data()));
            if (fault == Fault::CorruptSecondChunk && index == 1) (*chunk.mutable_data())[10] ^= 0x40;  // CRC now wrong
            if (fault == Fault::WrongBytesGoodCrc) {
                (*chunk.mutable_data())[0] ^= 1;
                chunk.set_crc32(util::crc32Of(chunk.data()));  // passes the chunk check, fails the SHA-256
            }
            writer->Write(chunk);
            offset += size;
            if (fault == Fault::StopAfterFirstChunk) break;  // a stream cut short, status OK
        }
        return grpc::Status::OK;
    }
    size_t calls() const { return calls_; }

private:
    std::string blob_;
    std::vector<Fault> faults_;
    std::atomic<size_t> calls_{0};
};

struct Served {
    explicit Served(FakeGateway& service) {
        grpc::ServerBuilder builder;
        builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port);
        builder.RegisterService(&service);
        server = builder.BuildAndStart();
        channel = rpc::makeChannel("127.0.0.1:" + std::to_string(port), {});
    }
    ~Served() { server->Shutdown(); }
    int port = 0;
    std::unique_ptr<grpc::Server> server;
    std::shared_ptr<grpc::Channel> channel;
};

std::string testBlob() {
    std::string blob(2 * rpc::kChunkBytes + 12345, '\0');
    uint32_t state = 12345;
    for (char& c : blob) c = char((state = state * 1664525u + 1013904223u) >> 24);
    return blob;
}

TEST(AssetFetcher, ACorruptChunkIsRejectedAndFetchedAgain) {
    const std::string blob = testBlob();
    FakeGateway service(blob, {Fault::CorruptSecondChunk});
    Served served(service);
    worker::AssetFetcher fetcher(served.channel, "");
    EXPECT_EQ(fetcher.fetch(util::sha256Hex(blob), blob.size()), blob);
    EXPECT_EQ(fetcher.statistics().chunksRejected, 1u);
    EXPECT_EQ(service.calls(), 2u);  // resumed at the bad chunk's offset
}

TEST(AssetFetcher, ATruncatedStreamIsResumed) {
    const std::string blob = testBlob();
    FakeGateway service(blob, {Fault::StopAfterFirstChunk, Fault::StopAfterFirstChunk});
    Served served(service);
    worker::AssetFetcher fetcher(served.channel, "");
    EXPECT_EQ(fetcher.fetch(util::sha256Hex(blob), blob.size()), blob);
    EXPECT_EQ(fetcher.statistics().retries, 2u);
}

TEST(AssetFetcher, ABlobThatNeverMatchesItsHashIsAnError) {
    const std::string blob = testBlob();
    FakeGateway service(blob, std::vector<Fault>(10, Fault::WrongBytesGoodCrc));
    Served served(service);
    worker::AssetFetcher fetcher(served.channel, "", 3);
    try {
        fetcher.fetch(util::sha256Hex(blob), blob.size());
        FAIL() << "a blob failing its SHA-256 was accepted";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("SHA-256"), std::string::npos) << e.what();
    }
    EXPECT_EQ(service.calls(), 3u);
}

TEST(AssetFetcher, AGoodStreamIsFetchedInOneCall) {
    const std::string blob = testBlob();
    FakeGateway service(blob, {});
    Served served(service);
    worker::AssetFetcher fetcher(served.channel, "");
    EXPECT_EQ(fetcher.fetch(util::sha256Hex(blob), blob.size()), blob);
    EXPECT_EQ(service.calls(), 1u);
    EXPECT_EQ(fetcher.statistics().chunksRejected, 0u);
}

}  // namespace
}  // namespace vrl
