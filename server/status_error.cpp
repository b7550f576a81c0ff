#include "server/status_error.h"

#include <spdlog/spdlog.h>

namespace rrg::server {

grpc::Status status_of(std::exception_ptr e) {
  try {
    std::rethrow_exception(e);
  } catch (const StatusError& s) {
    return {s.code(), s.what()};
  } catch (const std::invalid_argument& s) {
    return {grpc::StatusCode::INVALID_ARGUMENT, s.what()};
  } catch (const std::exception& s) {
    spdlog::error("server: internal error: {}", s.what());
    return {grpc::StatusCode::INTERNAL, s.what()};
  } catch (...) {
    return {grpc::StatusCode::INTERNAL, "unknown error"};
  }
}

}  // namespace rrg::server
