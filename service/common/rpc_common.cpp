#include "service/common/rpc_common.h"

#include <openssl/crypto.h>

#include <cstdlib>
#include <fstream>
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
    // A restarted coordinator is found again within seconds (gRPC's default backoff grows to 120 s),
    // so that clients and workers retrying on their own schedule are not kept waiting by the channel's.
    args.SetInt(GRPC_ARG_INITIAL_RECONNECT_BACKOFF_MS, 250);
    args.SetInt(GRPC_ARG_MIN_RECONNECT_BACKOFF_MS, 250);
    args.SetInt(GRPC_ARG_MAX_RECONNECT_BACKOFF_MS, 4000);
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

std::string describe(const grpc::Status& status) {
    static const char* const kNames[] = {"OK", "CANCELLED", "UNKNOWN", "INVALID_ARGUMENT", "DEADLINE_EXCEEDED",
                                         "NOT_FOUND", "ALREADY_EXISTS", "PERMISSION_DENIED", "RESOURCE_EXHAUSTED",
                                         "FAILED_PRECONDITION", "ABORTED", "OUT_OF_RANGE", "UNIMPLEMENTED",
                                         "INTERNAL", "UNAVAILABLE", "DATA_LOSS", "UNAUTHENTICATED"};
    const int code = int(status.error_code());
    const std::string name = code >= 0 && code <= 16 ? kNames[code] : std::to_string(code);
    return name + ": " + status.error_message();
}

}  // namespace vrl::rpc
