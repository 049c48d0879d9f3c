// RequestGate: every RPC handler's first step. It identifies the caller and
// checks what the call needs, so TLS client identities and per-token roles can
// be switched on in the config without touching any handler.
//
// Roles, weakest first: kRead (dashboards: list, get, query, watch), kProbe
// (rigs: lease commands, submit traces), kSteer (upload, create/pause/resume/
// cancel jobs, refit). A steering token may also probe and read.
//
// With no tokens configured every caller has kSteer (a lab on loopback). With
// tokens, a call must carry `authorization: Bearer <token>` metadata.
//
// Tokens are kept as SHA-256 digests and a presented token is compared with
// every one of them by CRYPTO_memcmp (fixed 32 bytes, no early exit, no
// lookup in an ordered map): the time a refusal takes says nothing about how
// close a guess was. Refusals are logged at warn with the peer and the method,
// never the token.
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include <grpcpp/server_context.h>
#include "absl/status/status.h"

namespace surfmap {

enum class Role { kRead = 0, kProbe = 1, kSteer = 2 };

// "read", "probe", "steer".
bool ParseRole(const std::string& text, Role* role);
const char* RoleName(Role role);

class RequestGate {
 public:
  // token -> role; empty = open access (everyone kSteer).
  explicit RequestGate(const std::map<std::string, Role>& tokens = {});

  // OK, or UNAUTHENTICATED (no or unknown token) / PERMISSION_DENIED (role too
  // weak). `method` names the call in the message.
  absl::Status Admit(const grpc::ServerContextBase& context, Role needed, const char* method) const;

  // The role of `token` (constant time over the configured tokens), or false.
  bool RoleOf(std::string_view token, Role* role) const;

 private:
  using Digest = std::array<unsigned char, 32>;
  struct Entry {
    Digest digest;
    Role role;
  };
  static Digest Hash(std::string_view token);
  std::vector<Entry> tokens_;
};

}  // namespace surfmap
