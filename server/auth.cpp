#include "server/auth.h"

#include <openssl/evp.h>
#include <openssl/rand.h>

#include <stdexcept>
#include <vector>

namespace rrg::server {

namespace {
std::string to_hex(const unsigned char* p, size_t n) {
  static const char* digits = "0123456789abcdef";
  std::string s(2 * n, '0');
  for (size_t i = 0; i < n; ++i) {
    s[2 * i] = digits[p[i] >> 4];
    s[2 * i + 1] = digits[p[i] & 15];
  }
  return s;
}

std::string metadata(const grpc::ServerContextBase& ctx, const std::string& key) {
  const auto& md = ctx.client_metadata();
  const auto it = md.find(key);
  if (it == md.end()) return {};
  return std::string(it->second.data(), it->second.size());
}
}  // namespace

std::string random_hex(size_t bytes) {
  std::vector<unsigned char> buf(bytes);
  if (RAND_bytes(buf.data(), int(bytes)) != 1) throw std::runtime_error("auth: RAND_bytes failed");
  return to_hex(buf.data(), bytes);
}

std::string new_session_id() {
  std::string id = random_hex(8);
  id.insert(id.begin(), 's');
  return id;
}
std::string new_token() { return random_hex(32); }

std::string sha256_hex(const std::string& s) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned int n = 0;
  if (EVP_Digest(s.data(), s.size(), md, &n, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("auth: SHA-256 failed");
  return to_hex(md, n);
}

bool constant_time_equal(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

std::optional<std::string> bearer_token(const grpc::ServerContextBase& ctx) {
  const std::string v = metadata(ctx, "authorization");
  static const std::string prefix = "Bearer ";
  if (v.size() <= prefix.size() || v.compare(0, prefix.size(), prefix) != 0) return std::nullopt;
  return v.substr(prefix.size());
}

std::string session_header(const grpc::ServerContextBase& ctx) { return metadata(ctx, "x-rrg-session"); }

}  // namespace rrg::server
