#pragma once
// Bearer-token auth of the service: random session ids and tokens, the token's SHA-256 kept in
// snapshots (so a restarted server can let the token's owner Load the session without ever
// storing the token), and reading `authorization: Bearer <t>` / `x-rrg-session` metadata.
#include <grpcpp/server_context.h>

#include <optional>
#include <string>

namespace rrg::server {

std::string random_hex(size_t bytes);          // OpenSSL RAND_bytes, lower-case hex
std::string new_session_id();                  // "s" + 16 hex digits
std::string new_token();                       // 32 random bytes, hex
std::string sha256_hex(const std::string& s);
bool constant_time_equal(const std::string& a, const std::string& b);

// The token of `authorization: Bearer <token>`, or nullopt when the header is missing/malformed.
std::optional<std::string> bearer_token(const grpc::ServerContextBase& ctx);
// The `x-rrg-session` header, or "" when absent.
std::string session_header(const grpc::ServerContextBase& ctx);

}  // namespace rrg::server
