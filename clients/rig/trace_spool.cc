#include "clients/rig/trace_spool.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "server/estimate/trace_csv.h"

namespace surfmap::rig {
namespace fs = std::filesystem;
namespace {

constexpr char kTraceSuffix[] = ".trace.csv";
constexpr char kReasonSuffix[] = ".reason";
constexpr char kTempPrefix[] = ".tmp-";

absl::Status ErrnoError(const char* what, const fs::path& path, int error) {
  const std::string message = absl::StrCat(what, " ", path.string(), ": ", std::strerror(error));
  if (error == EACCES || error == EPERM || error == EROFS) return absl::PermissionDeniedError(message);
  if (error == ENOENT) return absl::NotFoundError(message);
  return absl::InternalError(message);
}

bool EndsWith(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

// Makes a rename or unlink inside `dir` durable.
absl::Status SyncDirectory(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoError("cannot open directory", dir, errno);
  const int result = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (result != 0) return ErrnoError("cannot fsync directory", dir, error);
  return absl::OkStatus();
}

// temp file in the same directory, fsync, rename over `target`, fsync the directory.
absl::Status WriteFileAtomically(const fs::path& target, std::string_view content) {
  const fs::path temp = target.parent_path() / absl::StrCat(kTempPrefix, target.filename().string(), ".", ::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return ErrnoError("cannot create", temp, errno);
  size_t written = 0;
  while (written < content.size()) {
    const ssize_t n = ::write(fd, content.data() + written, content.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      ::unlink(temp.c_str());
      return ErrnoError("cannot write", temp, error);
    }
    written += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int error = errno;
    ::close(fd);
    ::unlink(temp.c_str());
    return ErrnoError("cannot fsync", temp, error);
  }
  ::close(fd);
  if (::rename(temp.c_str(), target.c_str()) != 0) {
    const int error = errno;
    ::unlink(temp.c_str());
    return ErrnoError("cannot rename into", target, error);
  }
  return SyncDirectory(target.parent_path());
}

int64_t UnixMillisNow() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

std::string RigIdPathComponent(std::string_view rig_id) {
  std::string out;
  const bool dots_only = rig_id.find_first_not_of('.') == std::string_view::npos;
  for (unsigned char c : rig_id) {
    const bool plain = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' ||
                       c == '_' || (c == '.' && !dots_only);
    if (plain) {
      out.push_back(static_cast<char>(c));
    } else {
      out += absl::StrFormat("%%%02X", c);
    }
  }
  return out;
}

absl::StatusOr<fs::path> DefaultSpoolDir(std::string_view rig_id) {
  const fs::path tail = fs::path("surfmap") / "spool" / RigIdPathComponent(rig_id);
  if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg != nullptr && fs::path(xdg).is_absolute()) {
    return fs::path(xdg) / tail;
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && fs::path(home).is_absolute()) {
    return fs::path(home) / ".local" / "state" / tail;
  }
  return absl::FailedPreconditionError(
      "no spool directory: neither XDG_STATE_HOME nor HOME is an absolute path; pass --spool DIR");
}

absl::StatusOr<std::unique_ptr<TraceSpool>> TraceSpool::Open(const fs::path& dir) {
  if (dir.empty()) return absl::InvalidArgumentError("spool directory is empty");
  const fs::path absolute = fs::absolute(dir).lexically_normal();
  std::error_code error;
  fs::create_directories(absolute / "rejected", error);
  if (error) {
    return ErrnoError("cannot create spool directory", absolute / "rejected", error.value());
  }
  const int fd = ::open(absolute.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return ErrnoError("cannot open spool directory", absolute, errno);
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int lock_error = errno;
    ::close(fd);
    if (lock_error == EWOULDBLOCK) {
      return absl::FailedPreconditionError(absl::StrCat(
          "spool ", absolute.string(),
          " is in use by another rig process (each rig needs its own spool: a different --rig-id or --spool)"));
    }
    return ErrnoError("cannot lock spool directory", absolute, lock_error);
  }
  std::unique_ptr<TraceSpool> spool(new TraceSpool(absolute, fd));
  for (const fs::path& d : {absolute, absolute / "rejected"}) {
    for (const fs::directory_entry& entry : fs::directory_iterator(d, error)) {
      if (entry.path().filename().string().rfind(kTempPrefix, 0) == 0) fs::remove(entry.path(), error);
    }
  }
  return spool;
}

TraceSpool::~TraceSpool() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // closing the descriptor releases the flock
}

absl::StatusOr<fs::path> TraceSpool::Add(const SpoolHeader& header, const DragTrace& trace) {
  absl::StatusOr<std::string> text = FormatSpoolFile(header, trace);
  if (!text.ok()) return text.status();
  std::string name = absl::StrFormat("%013d-command-%d", header.measured_unix_ms, header.command_id);
  fs::path file = dir_ / absl::StrCat(name, kTraceSuffix);
  for (int n = 2; fs::exists(file) || fs::exists(rejected_dir() / file.filename()); ++n) {
    file = dir_ / absl::StrCat(name, "-", n, kTraceSuffix);
  }
  // Read it back before it counts as spooled: what cannot be read here would
  // be stuck in the spool after a restart.
  absl::StatusOr<SpooledTrace> readable = ParseSpoolFile(*text, file.filename().string());
  if (!readable.ok()) {
    const fs::path rejected = rejected_dir() / file.filename();
    absl::Status written = WriteFileAtomically(rejected, *text);
    if (written.ok()) {
      written = WriteFileAtomically(rejected.string() + std::string(kReasonSuffix),
                                    absl::StrCat("not submitted: the trace is invalid: ", readable.status().message(), "\n"));
    }
    if (!written.ok()) return written;
    return absl::InvalidArgumentError(
        absl::StrCat("trace is invalid (", readable.status().message(), "); kept in ", rejected.string()));
  }
  if (absl::Status written = WriteFileAtomically(file, *text); !written.ok()) return written;
  return file;
}

absl::StatusOr<std::vector<fs::path>> TraceSpool::Pending() const {
  std::vector<fs::path> files;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir_, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kTempPrefix, 0) == 0 || !EndsWith(name, kTraceSuffix)) continue;
    if (!entry.is_regular_file(error)) continue;
    files.push_back(entry.path());
  }
  if (error) return ErrnoError("cannot list spool directory", dir_, error.value());
  std::sort(files.begin(), files.end());  // the names start with the time they were measured
  return files;
}

absl::StatusOr<SpooledTrace> TraceSpool::Read(const fs::path& file) const {
  std::ifstream in(file, std::ios::binary);
  if (!in) return ErrnoError("cannot open spooled trace", file, errno);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return ErrnoError("cannot read spooled trace", file, errno);
  return ParseSpoolFile(text.str(), file.string());
}

absl::Status TraceSpool::CheckInSpool(const fs::path& file) const {
  if (file.parent_path() != dir_) {
    return absl::InvalidArgumentError(absl::StrCat(file.string(), " is not a file of the spool ", dir_.string()));
  }
  return absl::OkStatus();
}

absl::Status TraceSpool::Remove(const fs::path& file) {
  if (absl::Status in_spool = CheckInSpool(file); !in_spool.ok()) return in_spool;
  if (::unlink(file.c_str()) != 0) return ErrnoError("cannot delete spooled trace", file, errno);
  // No fsync of the directory: should a crash bring the file back, it is
  // resubmitted and answered already_accepted (the same rig, the same
  // samples), then deleted. One fsync less per trace.
  return absl::OkStatus();
}

absl::StatusOr<fs::path> TraceSpool::Reject(const fs::path& file, std::string_view reason) {
  if (absl::Status in_spool = CheckInSpool(file); !in_spool.ok()) return in_spool;
  const fs::path target = rejected_dir() / file.filename();
  // The reason first: a crash between the two steps leaves the trace in the
  // spool (resubmitted, refused again), never a rejected trace without reason.
  absl::Status written = WriteFileAtomically(target.string() + std::string(kReasonSuffix),
                                             absl::StrCat(absl::string_view(reason.data(), reason.size()), "\nrejected_unix_ms: ", UnixMillisNow(), "\n"));
  if (!written.ok()) return written;
  if (::rename(file.c_str(), target.c_str()) != 0) return ErrnoError("cannot move spooled trace to", target, errno);
  if (absl::Status synced = SyncDirectory(rejected_dir()); !synced.ok()) return synced;
  if (absl::Status synced = SyncDirectory(dir_); !synced.ok()) return synced;
  return target;
}

void TraceSpool::RemoveDirectoriesIfEmpty() {
  std::error_code error;
  if (fs::is_empty(rejected_dir(), error) && !error) fs::remove(rejected_dir(), error);
  if (fs::is_empty(dir_, error) && !error) fs::remove(dir_, error);
}

}  // namespace surfmap::rig
