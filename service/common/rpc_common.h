// service/common/: what every gRPC party shares (channels, TLS, token, deadlines,
// keepalive, limits, the ServiceError -> grpc::Status mapping). No renderer here.
//
// What both ends of a vrlcuts gRPC connection share: keepalive and message-size
// settings that agree on both sides, TLS credentials, the shared token, the
// checksums used on every streamed chunk, and call deadlines.
#pragma once

#include <grpcpp/grpcpp.h>

#include "vrl/v1/vrl.pb.h"

#include <csignal>

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace vrl::rpc {

inline constexpr uint32_t kProtocolVersion = 14;         // vrl.v1 ProtocolVersion CURRENT
static_assert(kProtocolVersion == uint32_t(::vrl::v1::PROTOCOL_VERSION_CURRENT),
              "the handshake's protocol version must be the proto's PROTOCOL_VERSION_CURRENT");
inline constexpr size_t kChunkBytes = 1 << 20;           // streamed blobs: at most 1 MiB per message
inline constexpr int kMaxMessageBytes = 64 << 20;        // a tile result of 64 MiB at most (e.g. 256x256 x 8 layers)
inline constexpr std::chrono::milliseconds kKeepaliveTime{20000};
inline constexpr std::chrono::milliseconds kKeepaliveTimeout{10000};

// TLS files; empty strings mean "not used".
struct TlsOptions {
    std::string caFile;    // client: the CA that signed the server's certificate
    std::string certFile;  // server: its certificate; worker: its client certificate
    std::string keyFile;
    std::string clientCaFile;  // server: require client certificates signed by this CA (from workers)
    bool enabled() const { return !caFile.empty() || !certFile.empty(); }
};

// Reads a file whole; throws std::runtime_error naming it.
std::string readFileText(const std::string& path);

// The shared token: the file's first line if `tokenFile` is set, else the
// environment variable VRL_TOKEN, else empty (no token).
std::string loadToken(const std::string& tokenFile);

// A channel to `address` with keepalive and message-size settings; TLS when
// `tls.caFile` is set (certFile/keyFile add a client certificate).
std::shared_ptr<grpc::Channel> makeChannel(const std::string& address, const TlsOptions& tls);

// Adds the listening port with plaintext or TLS credentials and the server side
// of the keepalive settings. Throws std::runtime_error if a TLS file is unreadable.
void configureServer(grpc::ServerBuilder& builder, const std::string& address, const TlsOptions& tls,
                     int* selectedPort);

// Sets the deadline and, when non-empty, "authorization: Bearer <token>".
void prepareContext(grpc::ClientContext& context, const std::string& token, std::chrono::milliseconds timeout);

// OK when `expected` is empty or the call carries it (compared in constant
// time); UNAUTHENTICATED with a message otherwise.
grpc::Status checkToken(const grpc::ServerContext& context, const std::string& expected);

// "DEADLINE_EXCEEDED: message" for logs and errors.
std::string describe(const grpc::Status& status);

}  // namespace vrl::rpc
