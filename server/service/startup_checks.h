// Checks surfmapd makes before it serves, so that a server that cannot work
// refuses to start with a message naming the file, instead of answering every
// write with an SQL error later.
#pragma once

#include <string>

#include "absl/status/statusor.h"

namespace surfmap {

// The database file (when it exists) and its directory (SQLite writes the
// -wal and -shm files beside it) must be writable by this process.
// FAILED_PRECONDITION naming the path, the user and the system's reason.
absl::Status CheckDatabaseWritable(const std::string& db_path);

// The whole of a PEM file for TLS; FAILED_PRECONDITION naming the config key
// and the path when it cannot be read or holds no PEM block.
absl::StatusOr<std::string> ReadPemFile(const std::string& key, const std::string& path);

}  // namespace surfmap
