// The external driver protocol (`surfmap-rig --driver "CMD ARGS"`), version 1:
// JSON lines over the driver program's stdin (rig -> driver) and stdout
// (driver -> rig). One JSON object per line, UTF-8, no line breaks inside.
// Unknown fields are ignored by both sides (later versions may add some).
// clients/rig/README.md ("Connect your robot") is the reference.
//
// driver -> rig, once, first:
//   {"type":"ready","protocol":1,"driver":"UR5e + Bota SensONE, tip r=2 mm"}
// rig -> driver, one per probe:
//   {"type":"command","protocol":1,"command_id":17,"job_id":3,"attempt":1,
//    "site":{"level":0,"vertex":12},"position_mm":[x,y,z],"normal":[x,y,z],
//    "drag_direction":[x,y,z],"segment_length_mm":20,"speed_mm_s":10,
//    "normal_force_n":5,"lease_deadline_unix_ms":1795000060000}
// driver -> rig, exactly one answer per command:
//   {"type":"trace","command_id":17,"t":[..],"x":[..],"y":[..],"z":[..],
//    "fx":[..],"fy":[..],"fz":[..],"phase":["fwd",..,"pause",..,"rev",..]}
//   {"type":"failure","command_id":17,"kind":"transient"|"unreachable",
//    "reason":"force ceiling 15 N exceeded at touch-down","stop":false}
// driver -> rig, any time (printed by the rig):
//   {"type":"log","message":"homing done"}
//
// Units and frames: positions mm and directions (unit vectors) in the OBJECT
// frame (the frame of the uploaded mesh); t in s, strictly increasing; tip
// position mm and force N (BY the surface ON the probe) in the object frame.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>
#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "proto/surfmap/v1/surfmap.pb.h"
#include "server/estimate/drag_trace.h"

namespace surfmap::rig {

inline constexpr int kDriverProtocolVersion = 1;

// What a driver says first.
struct DriverReady {
  int protocol = 0;
  std::string driver;  // free text naming the driver and its hardware
};

// One line a driver writes in answer to a command.
struct DriverReply {
  enum class Type { kTrace, kFailure, kLog };
  Type type = Type::kLog;
  std::int64_t command_id = 0;
  DragTrace trace;                                              // kTrace
  surfmap::v1::FailureKind kind = surfmap::v1::FAILURE_KIND_TRANSIENT;  // kFailure
  std::string reason;                                           // kFailure
  bool stop = false;                                            // kFailure: the rig stops after reporting
  std::string message;                                          // kLog
};

// The command line for `request` (no newline).
std::string FormatCommandMessage(const ProbeRequest& request);
// The ready line.
std::string FormatReadyMessage(std::string_view driver);
// The trace line for `command_id`. Non-finite values are written as null
// (JSON has no NaN), which ParseDriverReply rejects.
std::string FormatTraceMessage(std::int64_t command_id, const DragTrace& trace);
// The failure line (kind TRANSIENT or UNREACHABLE).
std::string FormatFailureMessage(std::int64_t command_id, surfmap::v1::FailureKind kind, std::string_view reason,
                                 bool stop = false);

// A command line as a driver reads it (the simulated driver uses this).
// INVALID_ARGUMENT naming the field: not JSON, not a command, wrong protocol,
// a missing or mistyped field, or a request ValidateProbeRequest refuses.
absl::StatusOr<ProbeRequest> ParseCommandMessage(std::string_view line);

// The driver's first line: INVALID_ARGUMENT unless it is a ready message of
// protocol kDriverProtocolVersion (the message quotes the line).
absl::StatusOr<DriverReady> ParseReadyMessage(std::string_view line);

// A line the driver wrote while the rig waits for command
// `expected_command_id`. INVALID_ARGUMENT naming the problem: not JSON (NaN
// or Infinity named as such), an unknown type, another command id, a trace
// whose columns are missing, of different lengths, empty, not numbers (or
// not finite), or whose phases are not fwd/pause/rev, a failure without a
// reason or with an unknown kind.
absl::StatusOr<DriverReply> ParseDriverReply(std::string_view line, std::int64_t expected_command_id);

}  // namespace surfmap::rig
