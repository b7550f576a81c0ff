#include "client/lib/health_check.h"

#include "client/lib/service_client.h"

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/support/byte_buffer.h>

#include <future>
#include <stdexcept>
#include <vector>

namespace rrg::service {

const char* to_string(HealthStatus s) {
  switch (s) {
    case HealthStatus::serving: return "SERVING";
    case HealthStatus::not_serving: return "NOT_SERVING";
    case HealthStatus::service_unknown: return "SERVICE_UNKNOWN";
    default: return "UNKNOWN";
  }
}

HealthStatus check_health(const std::shared_ptr<grpc::Channel>& channel, const std::string& service_name,
                          std::chrono::milliseconds timeout) {
  if (service_name.size() > 127) throw std::invalid_argument("health: service name longer than 127 bytes");
  grpc::GenericStub stub(channel);
  grpc::ClientContext ctx;
  ctx.set_deadline(std::chrono::system_clock::now() + timeout);
  // HealthCheckRequest { string service = 1; }: tag 0x0a, one-byte length, bytes.
  std::string req;
  if (!service_name.empty()) req = std::string("\x0a") + char(service_name.size()) + service_name;
  grpc::Slice slice(req);
  grpc::ByteBuffer in(&slice, 1), out;
  std::promise<grpc::Status> done;
  stub.UnaryCall(&ctx, "/grpc.health.v1.Health/Check", grpc::StubOptions(), &in, &out,
                 [&](grpc::Status st) { done.set_value(st); });
  const grpc::Status st = done.get_future().get();
  if (!st.ok()) throw RpcError("Health/Check '" + service_name + "'", st);
  std::vector<grpc::Slice> slices;
  (void)out.Dump(&slices);
  std::string bytes;
  for (const auto& sl : slices) bytes.append(reinterpret_cast<const char*>(sl.begin()), sl.size());
  // HealthCheckResponse { ServingStatus status = 1; }: tag 0x08, varint (< 128); empty = UNKNOWN.
  if (bytes.size() >= 2 && bytes[0] == '\x08' && bytes[1] >= 0 && bytes[1] <= 3) return HealthStatus(bytes[1]);
  return HealthStatus::unknown;
}

}  // namespace rrg::service
