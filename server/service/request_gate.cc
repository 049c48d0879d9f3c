#include "server/service/request_gate.h"

#include "absl/strings/str_cat.h"

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

RequestGate::RequestGate(std::map<std::string, Role> tokens) : tokens_(std::move(tokens)) {}

absl::Status RequestGate::Admit(const grpc::ServerContextBase& context, Role needed, const char* method) const {
  if (tokens_.empty()) return absl::OkStatus();
  const auto& metadata = context.client_metadata();
  auto it = metadata.find("authorization");
  if (it == metadata.end()) {
    return absl::UnauthenticatedError(absl::StrCat(method, ": missing 'authorization: Bearer <token>' metadata"));
  }
  std::string value(it->second.data(), it->second.size());
  constexpr std::string_view kBearer = "Bearer ";
  if (value.rfind(kBearer, 0) != 0) {
    return absl::UnauthenticatedError(absl::StrCat(method, ": authorization metadata must be 'Bearer <token>'"));
  }
  auto role = tokens_.find(value.substr(kBearer.size()));
  if (role == tokens_.end()) return absl::UnauthenticatedError(absl::StrCat(method, ": unknown token"));
  if (static_cast<int>(role->second) < static_cast<int>(needed)) {
    return absl::PermissionDeniedError(
        absl::StrCat(method, " needs role '", RoleName(needed), "', the token has '", RoleName(role->second), "'"));
  }
  return absl::OkStatus();
}

}  // namespace surfmap
