// The spool file: one measured trace waiting for the server's acknowledgement
// (TraceSpool keeps a directory of them). It is the project's drag-trace CSV
// (server/estimate/trace_csv.h) preceded by a fixed comment header, so
// `surfmap fit FILE` reads it as it is:
//
//   # surfmap spooled trace v1
//   # command_id: 17
//   # job_id: 3
//   # attempt: 1
//   # rig_id: lab-arm-1
//   # measured_unix_ms: 1795000000123
//   # frame: rig_base                      only for a trace in a rig's frame
//   # registration_id: 7                   (both, or neither)
//   t,x,y,z,fx,fy,fz,phase
//   0,9.9899,-5.0072,2.9973,-0.64094,-0.03418,6.09862,fwd
//   ...
//
// The first line is exactly the version line; then every key once, in this
// order (frame and registration_id optional: a file without them, as every
// file written before frames existed, holds a trace in the object's frame);
// then the CSV. The trace is resubmitted in the frame and with the
// registration it was measured in, whatever the frame of the run that
// resubmits it. Numbers are written with the shortest text that reads
// back to the same double, so a resubmitted trace is bit-identical to the
// first submission (the server answers `already_accepted` only to identical
// samples). The Python client writes and reads the same format
// (clients/python/surfmap_client/spool.py).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "server/estimate/drag_trace.h"
#include "server/frames/rig_frames.h"

namespace surfmap::rig {

inline constexpr std::string_view kSpoolFileVersionLine = "# surfmap spooled trace v1";

// Who measured the trace, for which command.
struct SpoolHeader {
  std::int64_t command_id = 0;
  std::int64_t job_id = 0;
  int attempt = 0;
  std::string rig_id;
  std::int64_t measured_unix_ms = 0;  // when the rig spooled it (informational)
  TraceFrame frame = TraceFrame::kObject;  // the frame the trace's samples are in
  std::int64_t registration_id = 0;        // a rig frame's registration (0 = the latest)
};

// INVALID_ARGUMENT naming the field: command_id <= 0, job_id <= 0, attempt
// < 0, a rig id of 0 or more than 100 characters or with a control character
// (it is one line of the header), registration_id < 0, or a registration
// with the object's frame.
absl::Status ValidateSpoolHeader(const SpoolHeader& header);

struct SpooledTrace {
  SpoolHeader header;
  DragTrace trace;
};

// The file's text. Validates the header, not the trace.
absl::StatusOr<std::string> FormatSpoolFile(const SpoolHeader& header, const DragTrace& trace);

// Parses a spool file. INVALID_ARGUMENT "<source>:<line>: <problem>" for a
// missing or different version line, a missing, repeated, unknown or
// out-of-order key, a value that is not a number, an invalid header, or any
// problem of the trace CSV (ParseTraceCsv's checks).
absl::StatusOr<SpooledTrace> ParseSpoolFile(std::string_view text, std::string_view source);

}  // namespace surfmap::rig
