#pragma once
// An error that carries its gRPC status code from deep in the server to the RPC boundary, and the
// mapping of every exception to a status: std::invalid_argument -> INVALID_ARGUMENT (the message
// names the field), StatusError -> its code, anything else -> INTERNAL.
#include <grpcpp/support/status.h>

#include <exception>
#include <stdexcept>
#include <string>

namespace rrg::server {

class StatusError : public std::runtime_error {
 public:
  StatusError(grpc::StatusCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  grpc::StatusCode code() const { return code_; }

 private:
  grpc::StatusCode code_;
};

inline StatusError not_found(const std::string& m) { return {grpc::StatusCode::NOT_FOUND, m}; }
inline StatusError unauthenticated(const std::string& m) { return {grpc::StatusCode::UNAUTHENTICATED, m}; }
inline StatusError exhausted(const std::string& m) { return {grpc::StatusCode::RESOURCE_EXHAUSTED, m}; }

// The status for the exception being handled (call inside a catch block) or for `e`.
grpc::Status status_of(std::exception_ptr e);

}  // namespace rrg::server
