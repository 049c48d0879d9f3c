#include "server/service/startup_checks.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"

namespace surfmap {

absl::Status CheckDatabaseWritable(const std::string& db_path) {
  namespace fs = std::filesystem;
  std::error_code error;
  const fs::path path(db_path);
  const bool exists = fs::exists(path, error);
  fs::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  const auto refuse = [&](const std::string& what, const std::string& target) {
    return absl::FailedPreconditionError(absl::StrCat(
        "database ", db_path, ": ", what, " '", target, "' is not writable by this process (uid ", getuid(),
        "): ", std::strerror(errno), "; surfmapd writes every trace there, so it does not start"));
  };
  if (exists) {
    if (fs::is_directory(path, error)) {
      return absl::FailedPreconditionError(absl::StrCat("database ", db_path, " is a directory, not a file"));
    }
    if (access(db_path.c_str(), R_OK | W_OK) != 0) return refuse("the file", db_path);
  } else if (!fs::is_directory(dir, error)) {
    return absl::FailedPreconditionError(
        absl::StrCat("database ", db_path, ": its directory '", dir.string(), "' does not exist"));
  }
  // The journal (-wal, -shm) is created beside the file on every open.
  if (access(dir.c_str(), W_OK | X_OK) != 0) return refuse("its directory", dir.string());
  return absl::OkStatus();
}

absl::StatusOr<std::string> ReadPemFile(const std::string& key, const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return absl::FailedPreconditionError(
        absl::StrCat(key, ": cannot read '", path, "': ", std::strerror(errno)));
  }
  std::stringstream text;
  text << in.rdbuf();
  if (text.str().find("-----BEGIN ") == std::string::npos) {
    return absl::FailedPreconditionError(absl::StrCat(key, ": '", path, "' holds no PEM block (-----BEGIN ...)"));
  }
  return text.str();
}

}  // namespace surfmap
