#include "proto/rpc_common.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <sys/prctl.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace vrl::rpc {

std::string readFileText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read '" + path + "'");
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string loadToken(const std::string& tokenFile) {
    std::string token;
    if (!tokenFile.empty()) {
        token = readFileText(tokenFile);
        token = token.substr(0, token.find_first_of("\r\n"));
        if (token.empty()) throw std::runtime_error("the token file '" + tokenFile + "' is empty");
    } else if (const char* env = std::getenv("VRL_TOKEN")) {
        token = env;
    }
    return token;
}

namespace {

grpc::ChannelArguments channelArguments() {
    grpc::ChannelArguments args;
    args.SetInt(GRPC_ARG_KEEPALIVE_TIME_MS, int(kKeepaliveTime.count()));
    args.SetInt(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, int(kKeepaliveTimeout.count()));
    args.SetInt(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
    args.SetInt(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
    args.SetMaxReceiveMessageSize(kMaxMessageBytes);
    args.SetMaxSendMessageSize(kMaxMessageBytes);
    return args;
}

}  // namespace

std::shared_ptr<grpc::Channel> makeChannel(const std::string& address, const TlsOptions& tls) {
    std::shared_ptr<grpc::ChannelCredentials> credentials;
    if (!tls.caFile.empty()) {
        grpc::SslCredentialsOptions options;
        options.pem_root_certs = readFileText(tls.caFile);
        if (!tls.certFile.empty()) {
            options.pem_cert_chain = readFileText(tls.certFile);
            options.pem_private_key = readFileText(tls.keyFile);
        }
        credentials = grpc::SslCredentials(options);
    } else {
        credentials = grpc::InsecureChannelCredentials();
    }
    return grpc::CreateCustomChannel(address, credentials, channelArguments());
}

void configureServer(grpc::ServerBuilder& builder, const std::string& address, const TlsOptions& tls,
                     int* selectedPort) {
    std::shared_ptr<grpc::ServerCredentials> credentials;
    if (!tls.certFile.empty()) {
        if (tls.keyFile.empty()) throw std::runtime_error("--tls-cert needs --tls-key");
        grpc::SslServerCredentialsOptions options(
            tls.clientCaFile.empty() ? GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE
                                     : GRPC_SSL_REQUEST_CLIENT_CERTIFICATE_AND_VERIFY);
        options.pem_key_cert_pairs.push_back({readFileText(tls.keyFile), readFileText(tls.certFile)});
        if (!tls.clientCaFile.empty()) options.pem_root_certs = readFileText(tls.clientCaFile);
        credentials = grpc::SslServerCredentials(options);
    } else {
        credentials = grpc::InsecureServerCredentials();
    }
    builder.AddListeningPort(address, credentials, selectedPort);
    // Agree with the clients' keepalive: pings every kKeepaliveTime are welcome.
    builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, int(kKeepaliveTime.count()));
    builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, int(kKeepaliveTimeout.count()));
    builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
    builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                               int(kKeepaliveTime.count() / 2));
    builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PINGS_WITHOUT_DATA, 0);
    builder.SetMaxReceiveMessageSize(kMaxMessageBytes);
    builder.SetMaxSendMessageSize(kMaxMessageBytes);
}

void prepareContext(grpc::ClientContext& context, const std::string& token, std::chrono::milliseconds timeout) {
    context.set_deadline(std::chrono::system_clock::now() + timeout);
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
}

grpc::Status checkToken(const grpc::ServerContext& context, const std::string& expected) {
    if (expected.empty()) return grpc::Status::OK;
    const auto& metadata = context.client_metadata();
    const auto it = metadata.find("authorization");
    const std::string wanted = "Bearer " + expected;
    if (it == metadata.end())
        return {grpc::StatusCode::UNAUTHENTICATED,
                "this coordinator requires a token (--token-file or VRL_TOKEN); the call carried none"};
    const bool same = it->second.size() == wanted.size() &&
                      CRYPTO_memcmp(it->second.data(), wanted.data(), wanted.size()) == 0;  // constant time
    if (!same) return {grpc::StatusCode::UNAUTHENTICATED, "wrong token"};
    return grpc::Status::OK;
}

std::string sha256Hex(std::string_view bytes) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    if (EVP_Digest(bytes.data(), bytes.size(), digest, &length, EVP_sha256(), nullptr) != 1)
        throw std::runtime_error("SHA-256 failed");
    static constexpr char kHex[] = "0123456789abcdef";
    std::string hex;
    for (unsigned int i = 0; i < length; ++i) {
        hex += kHex[digest[i] >> 4];
        hex += kHex[digest[i] & 15];
    }
    return hex;
}

uint32_t crc32Of(std::string_view bytes) {
    return static_cast<uint32_t>(
        crc32_z(crc32_z(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(bytes.data()), bytes.size()));
}

bool takeTerminationSignals(sigset_t& signals) {
    sigemptyset(&signals);
    sigaddset(&signals, SIGINT);
    sigaddset(&signals, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &signals, nullptr);
    if (std::getenv("VRL_EXIT_WITH_PARENT")) {
        prctl(PR_SET_PDEATHSIG, SIGTERM);
        if (getppid() == 1) return false;
    }
    return true;
}

std::string randomHex(size_t digits) {
    std::random_device device;
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (size_t i = 0; i < digits; ++i) out += kHex[device() & 15];
    return out;
}

std::string describe(const grpc::Status& status) {
    static const char* const kNames[] = {"OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED",
                                         "NOT_FOUND", "ALREADY_EXISTS", "PERMISSION_DENIED", "RESOURCE_EXHAUSTED",
                                         "FAILED_PRECONDITION", "ABORTED", "OUT_OF_RANGE", "UNIMPLEMENTED",
                                         "INTERNAL", "UNAVAILABLE", "DATA_LOSS", "UNAUTHENTICATED"};
    const int code = int(status.error_code());
    const std::string name = code >= 0 && code <= 16 ? kNames[code] : std::to_string(code);
    return name + ": " + status.error_message();
}

std::string abbreviate(std::string_view text, size_t max) {
    if (text.size() <= max) return std::string(text);
    return std::string(text.substr(0, max)) + "... (" + std::to_string(text.size()) + " bytes)";
}

}  // namespace vrl::rpc
