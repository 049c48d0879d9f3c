#include "clients/rig/spool_file.h"

#include <array>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "clients/rig/control_characters.h"
#include "server/estimate/trace_csv.h"

namespace surfmap::rig {
namespace {

// The header keys, in the order they are written and must be read.
constexpr std::array<std::string_view, 5> kKeys = {"command_id", "job_id", "attempt", "rig_id", "measured_unix_ms"};

// This abseil build's absl::string_view is not std::string_view.
absl::string_view A(std::string_view s) { return absl::string_view(s.data(), s.size()); }

}  // namespace

absl::Status ValidateSpoolHeader(const SpoolHeader& header) {
  if (header.command_id <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("command_id ", header.command_id, " is not a command id (> 0)"));
  }
  if (header.job_id <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("job_id ", header.job_id, " is not a job id (> 0)"));
  }
  if (header.attempt < 0) return absl::InvalidArgumentError(absl::StrCat("attempt ", header.attempt, " is < 0"));
  if (header.rig_id.empty() || header.rig_id.size() > 100) {
    return absl::InvalidArgumentError(
        absl::StrCat("rig_id must have 1..100 characters, has ", header.rig_id.size()));
  }
  if (HasControlCharacter(header.rig_id)) {
    return absl::InvalidArgumentError("rig_id must not contain control characters (newline, tab, ...)");
  }
  if (header.registration_id < 0) {
    return absl::InvalidArgumentError(absl::StrCat("registration_id ", header.registration_id, " is < 0"));
  }
  if (header.frame == TraceFrame::kObject && header.registration_id != 0) {
    return absl::InvalidArgumentError(absl::StrCat("registration_id ", header.registration_id,
                                                   " with the object's frame (a registration is for a rig frame)"));
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> FormatSpoolFile(const SpoolHeader& header, const DragTrace& trace) {
  if (absl::Status valid = ValidateSpoolHeader(header); !valid.ok()) return valid;
  std::string text(kSpoolFileVersionLine);
  absl::StrAppend(&text, "\n# command_id: ", header.command_id, "\n# job_id: ", header.job_id,
                  "\n# attempt: ", header.attempt, "\n# rig_id: ", A(header.rig_id),
                  "\n# measured_unix_ms: ", header.measured_unix_ms, "\n");
  // Object-frame files stay as before frames existed (older rigs read them).
  if (header.frame != TraceFrame::kObject) {
    absl::StrAppend(&text, "# frame: ", A(TraceFrameName(header.frame)), "\n# registration_id: ",
                    header.registration_id, "\n");
  }
  text += FormatTraceCsv(trace);
  return text;
}

absl::StatusOr<SpooledTrace> ParseSpoolFile(std::string_view text, std::string_view source) {
  auto error = [source](int line, std::string_view problem) {
    return absl::InvalidArgumentError(absl::StrCat(A(source), ":", line, ": ", A(problem)));
  };
  SpooledTrace out;
  std::string_view rest = text;
  auto next_line = [&rest]() {
    const size_t end = rest.find('\n');
    std::string_view line = rest.substr(0, end);
    rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return line;
  };
  if (next_line() != kSpoolFileVersionLine) {
    return error(1, absl::StrCat("not a spool file: the first line must be '", A(kSpoolFileVersionLine), "'"));
  }
  for (size_t k = 0; k < kKeys.size(); ++k) {
    const int line_number = static_cast<int>(k) + 2;
    const std::string_view key = kKeys[k];
    const std::string prefix = absl::StrCat("# ", A(key), ": ");
    if (rest.empty()) return error(line_number, absl::StrCat("missing header key '", A(key), "'"));
    std::string_view line = next_line();
    if (line.substr(0, prefix.size()) != prefix) {
      return error(line_number, absl::StrCat("expected '", prefix, "<value>', found '", A(line.substr(0, 60)), "'"));
    }
    const std::string_view value = line.substr(prefix.size());
    if (key == "rig_id") {
      out.header.rig_id = std::string(value);
      continue;
    }
    int64_t number = 0;
    if (!absl::SimpleAtoi(A(value), &number)) {
      return error(line_number, absl::StrCat(A(key), " '", A(value), "' is not an integer"));
    }
    if (key == "command_id") out.header.command_id = number;
    if (key == "job_id") out.header.job_id = number;
    if (key == "measured_unix_ms") out.header.measured_unix_ms = number;
    if (key == "attempt") {
      if (number < 0 || number > 1'000'000) return error(line_number, absl::StrCat("attempt ", number, " is out of range"));
      out.header.attempt = static_cast<int>(number);
    }
  }
  // The optional frame keys: both or neither.
  constexpr std::string_view kFramePrefix = "# frame: ";
  constexpr std::string_view kRegistrationPrefix = "# registration_id: ";
  const int frame_line = static_cast<int>(kKeys.size()) + 2;
  if (rest.substr(0, kFramePrefix.size()) == kFramePrefix) {
    const std::string_view line = next_line();
    absl::StatusOr<TraceFrame> frame = ParseTraceFrame(line.substr(kFramePrefix.size()));
    if (!frame.ok()) return error(frame_line, absl::StrCat("frame: ", frame.status().message()));
    out.header.frame = *frame;
    const std::string_view registration = next_line();
    if (registration.substr(0, kRegistrationPrefix.size()) != kRegistrationPrefix) {
      return error(frame_line + 1, absl::StrCat("expected '", A(kRegistrationPrefix), "<value>' after the frame, found '",
                                                A(registration.substr(0, 60)), "'"));
    }
    const std::string_view value = registration.substr(kRegistrationPrefix.size());
    if (!absl::SimpleAtoi(A(value), &out.header.registration_id)) {
      return error(frame_line + 1, absl::StrCat("registration_id '", A(value), "' is not an integer"));
    }
  }
  if (absl::Status valid = ValidateSpoolHeader(out.header); !valid.ok()) {
    return error(2, absl::StrCat("header: ", valid.message()));
  }
  // The whole text: the header lines are comments to the CSV reader, so its
  // line numbers are the file's.
  absl::StatusOr<DragTrace> trace = ParseTraceCsv(text, source);
  if (!trace.ok()) return trace.status();
  out.trace = *std::move(trace);
  return out;
}

}  // namespace surfmap::rig
