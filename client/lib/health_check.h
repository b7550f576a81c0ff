#pragma once
// grpc.health.v1.Health/Check as a client: the request and answer are one-field messages, so they
// are written by hand through the generic stub (Debian ships no generated health client code).
// Used by `rrg health` (the container HEALTHCHECK) and the deploy tests.
#include <grpcpp/channel.h>

#include <chrono>
#include <memory>
#include <string>

namespace rrg::service {

// grpc.health.v1.HealthCheckResponse.ServingStatus
enum class HealthStatus { unknown = 0, serving = 1, not_serving = 2, service_unknown = 3 };

const char* to_string(HealthStatus s);

// The status of `service_name` ("" = the whole server). Throws RpcError when the call fails
// (NOT_FOUND: the server does not know that service name; UNAVAILABLE: no server).
HealthStatus check_health(const std::shared_ptr<grpc::Channel>& channel, const std::string& service_name,
                          std::chrono::milliseconds timeout = std::chrono::seconds(5));

}  // namespace rrg::service
