// TempDir: a fresh directory under the system temp dir, removed with
// everything in it when the object dies. Integration tests keep the server's
// database, port file and log in one, so parallel tests never collide.
#pragma once

#include <filesystem>
#include <string>

#include "absl/status/statusor.h"

namespace surfmap::itest {

class TempDir {
 public:
  // `prefix` names the directory (e.g. "surfmap-itest"): mkdtemp adds a
  // random suffix. INTERNAL when the directory cannot be created.
  static absl::StatusOr<TempDir> Create(const std::string& prefix);

  TempDir(TempDir&& other) noexcept;
  TempDir& operator=(TempDir&& other) noexcept;
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir();

  const std::filesystem::path& path() const { return path_; }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  explicit TempDir(std::filesystem::path path) : path_(std::move(path)) {}
  void Remove();

  std::filesystem::path path_;
};

}  // namespace surfmap::itest
