#include "service/common/service_error.h"

namespace vrl::rpc {

grpc::Status toStatus(const ServiceError& error) {
    switch (error.kind) {
        case ErrorKind::InvalidArgument: return {grpc::StatusCode::INVALID_ARGUMENT, error.what()};
        case ErrorKind::NotFound: return {grpc::StatusCode::NOT_FOUND, error.what()};
        case ErrorKind::FailedPrecondition: return {grpc::StatusCode::FAILED_PRECONDITION, error.what()};
        case ErrorKind::ResourceExhausted: return {grpc::StatusCode::RESOURCE_EXHAUSTED, error.what()};
    }
    return {grpc::StatusCode::INTERNAL, error.what()};
}

}  // namespace vrl::rpc
