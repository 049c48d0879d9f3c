// TraceSpool: the directory where a rig keeps every measured trace until the
// server has acknowledged it, so no measurement is lost to a server restart,
// a network outage or a crash of the rig itself.
//
//   DIR/<measured_unix_ms>-command-<id>.trace.csv     waiting for an OK answer
//   DIR/rejected/<same name>                          refused for good, with
//   DIR/rejected/<same name>.reason                   the server's reason
//
// The rig writes the file (spool_file.h) BEFORE the first submission and
// deletes it only after an OK answer (fresh or already_accepted); on start it
// resubmits what is left. Files are written atomically (temp file, fsync,
// rename, fsync of the directory), so after a crash a file is either complete
// or absent. A trace the server refuses for good (ALREADY_EXISTS,
// FAILED_PRECONDITION, INVALID_ARGUMENT, ...) is moved to rejected/ next to a
// file saying why: never silently dropped.
//
// One process at a time: Open takes an exclusive flock(2) on DIR (the Python
// client takes the same lock), so two rigs never submit each other's traces.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/statusor.h"
#include "clients/rig/spool_file.h"

namespace surfmap::rig {

class TraceSpool {
 public:
  // Creates DIR and DIR/rejected (with parents) and locks DIR. Deletes temp
  // files left by a write a crash interrupted (their trace was never
  // submitted: the command's lease expires and the server re-issues it).
  // Errors: FAILED_PRECONDITION when another process holds the spool,
  // PERMISSION_DENIED / INTERNAL naming the path when it cannot be created.
  static absl::StatusOr<std::unique_ptr<TraceSpool>> Open(const std::filesystem::path& dir);

  ~TraceSpool();  // releases the lock
  TraceSpool(const TraceSpool&) = delete;
  TraceSpool& operator=(const TraceSpool&) = delete;

  // Spools a measured trace; returns its file. A trace that would not read
  // back (NaN, no reverse pass, time not increasing: the server would refuse
  // it too) goes straight to rejected/ and INVALID_ARGUMENT names the file
  // and the problem.
  absl::StatusOr<std::filesystem::path> Add(const SpoolHeader& header, const DragTrace& trace);

  // The traces waiting, oldest first.
  absl::StatusOr<std::vector<std::filesystem::path>> Pending() const;

  // Reads a spooled file (ParseSpoolFile's errors; NOT_FOUND when gone).
  absl::StatusOr<SpooledTrace> Read(const std::filesystem::path& file) const;

  // After an OK answer. Not made durable: a file a crash brings back is
  // resubmitted and answered already_accepted.
  absl::Status Remove(const std::filesystem::path& file);

  // Moves `file` to rejected/ after writing `reason` beside it; returns the
  // new path.
  absl::StatusOr<std::filesystem::path> Reject(const std::filesystem::path& file, std::string_view reason);

  // At exit: removes rejected/ and DIR when both are empty, so short-lived
  // rigs leave nothing behind. Errors are ignored (best effort).
  void RemoveDirectoriesIfEmpty();

  const std::filesystem::path& dir() const { return dir_; }
  std::filesystem::path rejected_dir() const { return dir_ / "rejected"; }

 private:
  TraceSpool(std::filesystem::path dir, int lock_fd) : dir_(std::move(dir)), lock_fd_(lock_fd) {}
  absl::Status CheckInSpool(const std::filesystem::path& file) const;

  std::filesystem::path dir_;
  int lock_fd_;
};

// The rig id as one path component: [A-Za-z0-9._-] kept, every other byte as
// %XX (so "lab/arm 1" -> "lab%2Farm%201"; "." and ".." are escaped too).
std::string RigIdPathComponent(std::string_view rig_id);

// $XDG_STATE_HOME/surfmap/spool/<RigIdPathComponent(rig_id)>, or
// $HOME/.local/state/surfmap/spool/... when XDG_STATE_HOME is unset or not
// absolute. FAILED_PRECONDITION when neither variable gives an absolute path.
absl::StatusOr<std::filesystem::path> DefaultSpoolDir(std::string_view rig_id);

}  // namespace surfmap::rig
