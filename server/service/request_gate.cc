#include "server/service/request_gate.h"

#include <openssl/crypto.h>
#include <openssl/sha.h>
#include <spdlog/spdlog.h>
#include "absl/strings/str_cat.h"
#include "server/base/utf8_text.h"

namespace surfmap {

bool ParseRole(const std::string& text, Role* role) {
  if (text == "read") *role = Role::kRead;
  else if (text == "probe") *role = Role::kProbe;
  else if (text == "steer") *role = Role::kSteer;
  else return false;
  return true;
}

const char* RoleName(Role role) {
  switch (role) {
    case Role::kRead: return "read";
    case Role::kProbe: return "probe";
    case Role::kSteer: return "steer";
  }
  return "?";
}

RequestGate::RequestGate(const std::map<std::string, Role>& tokens) {
  for (const auto& [token, role] : tokens) tokens_.push_back({Hash(token), role});
}

RequestGate::Digest RequestGate::Hash(std::string_view token) {
  Digest digest;
  SHA256(reinterpret_cast<const unsigned char*>(token.data()), token.size(), digest.data());
  return digest;
}

bool RequestGate::RoleOf(std::string_view token, Role* role) const {
  const Digest presented = Hash(token);
  bool found = false;
  // Every entry is compared, whatever matched before: the loop's time depends
  // only on how many tokens are configured.
  for (const Entry& entry : tokens_) {
    const bool match = CRYPTO_memcmp(presented.data(), entry.digest.data(), presented.size()) == 0;
    if (match) *role = entry.role;
    found |= match;
  }
  return found;
}

namespace {

// Logged at warn: who was refused, for which call and why (never the token).
absl::Status Refuse(const grpc::ServerContextBase& context, const char* method, absl::Status refusal) {
  spdlog::warn("auth refused rpc={} peer={} code={} reason=\"{}\"", method, EscapeForLog(context.peer()),
               absl::StatusCodeToString(refusal.code()), EscapeForLog(std::string(refusal.message())));
  return refusal;
}

}  // namespace

absl::Status RequestGate::Admit(const grpc::ServerContextBase& context, Role needed, const char* method) const {
  if (tokens_.empty()) return absl::OkStatus();
  const auto& metadata = context.client_metadata();
  auto it = metadata.find("authorization");
  if (it == metadata.end()) {
    return Refuse(context, method,
                  absl::UnauthenticatedError(absl::StrCat(method, ": missing 'authorization: Bearer <token>' metadata")));
  }
  const std::string_view value(it->second.data(), it->second.size());
  constexpr std::string_view kBearer = "Bearer ";
  if (value.substr(0, kBearer.size()) != kBearer) {
    return Refuse(context, method,
                  absl::UnauthenticatedError(absl::StrCat(method, ": authorization metadata must be 'Bearer <token>'")));
  }
  Role role = Role::kRead;  // set by RoleOf when it returns true
  if (!RoleOf(value.substr(kBearer.size()), &role)) {
    return Refuse(context, method, absl::UnauthenticatedError(absl::StrCat(method, ": unknown token")));
  }
  if (static_cast<int>(role) < static_cast<int>(needed)) {
    return Refuse(context, method,
                  absl::PermissionDeniedError(absl::StrCat(method, " needs role '", RoleName(needed),
                                                           "', the token has '", RoleName(role), "'")));
  }
  return absl::OkStatus();
}

}  // namespace surfmap
