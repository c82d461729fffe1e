// ServiceError: an error the service reports to its caller, with a kind that
// does not depend on gRPC, and the one place where a kind becomes a
// grpc::Status. Core code (the coordinator) throws these; the gRPC fronts
// catch them and answer with toStatus; anything else is INTERNAL.
#pragma once

#include <grpcpp/support/status.h>

#include <stdexcept>
#include <string>

namespace vrl::rpc {

enum class ErrorKind { InvalidArgument, NotFound, FailedPrecondition, ResourceExhausted };

struct ServiceError : std::runtime_error {
    ServiceError(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind(kind) {}
    ErrorKind kind;
};

// INVALID_ARGUMENT, NOT_FOUND, FAILED_PRECONDITION or RESOURCE_EXHAUSTED with the error's message.
grpc::Status toStatus(const ServiceError& error);

}  // namespace vrl::rpc
