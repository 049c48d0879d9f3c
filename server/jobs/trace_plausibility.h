// Is a submitted trace physically the answer to its command? Checked before
// the trace is fitted or stored, so a trace from another object, another
// frame, a broken sensor or a hostile client cannot enter the map nor cost
// the server more than one pass over its samples.
//
// Every check compares a measured value with a limit a job can tune
// (TraceLimits, defaults a real lab accepts: registration errors of a few mm,
// drags reversed or shortened at an open edge, curved surfaces) and fails with
// INVALID_ARGUMENT naming the check, the value and the limit.
//
// A trace that is not a drag at all (fewer than 20 samples, a number that is
// not finite, time not increasing) is "malformed" and simply refused; a drag
// that fails a physical check is "implausible" and kept for inspection (see
// ProbeProtocol). The physical checks, before the fit (O(samples)):
//   time         duration at most max_duration_factor x the commanded
//                drag's duration (+ 30 s for slow rigs)
//   rate         sample rate in [min_rate_hz, max_rate_hz]
//   offset       every position within segment_length + max_offset_mm of the
//                commanded site
//   length       forward path length in [min_length_fraction, max_length_fraction]
//                x segment_length
//   direction    the forward pass's line, seen along the commanded normal,
//                within max_direction_deg of the commanded drag direction
//                (either way: rigs may reverse at an edge)
//   surface      (imports only) every sample within max_offset_mm of the surface
// After the fit (cheap: uses its normal and mu):
//   normal       the estimated normal where the drag passed the site (any
//                pair within 1 mm of it) within max_normal_deg of the
//                commanded normal; not the drag's mean: over a sharp edge the
//                normal turns 90 degrees
//   force        mean normal force (each sample along its own estimated
//                normal) in [commanded / normal_force_factor,
//                commanded x normal_force_factor]
//   friction     mu in [0, max_mu] (friction opposes the motion)
#pragma once

#include <string>

#include "absl/status/status.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/fit_trace.h"
#include "server/plan/probe_command.h"

namespace surfmap {

struct TraceLimits {
  double max_offset_mm = 10.0;        // beyond the segment's reach from the site
  double min_length_fraction = 0.25;  // an open edge may shorten a drag
  double max_length_fraction = 2.0;
  double max_direction_deg = 45.0;
  double max_normal_deg = 30.0;
  double normal_force_factor = 3.0;
  double max_mu = 2.0;                // well above any material the method maps
  double max_duration_factor = 20.0;
  double min_rate_hz = 5.0;
  double max_rate_hz = 1e6;

  // Names the first invalid field.
  bool IsValid(std::string* why) const;
};

// The checks before the fit.
absl::Status CheckTraceAgainstCommand(const DragTrace& trace, const ProbeCommand& command, const TraceLimits& limits);
// An imported drag (import_locate.h): its largest distance from the object's
// surface, sample `sample`, within max_offset_mm ("surface" check). A leased
// trace needs no such check: its command's site is on the surface and the
// offset check measures from there.
absl::Status CheckTraceNearSurface(double max_distance_mm, int sample, const TraceLimits& limits);
// The checks on the fit.
absl::Status CheckFitAgainstCommand(const DragTrace& trace, const TraceFit& fit, const ProbeCommand& command,
                                    const TraceLimits& limits);

// The name of the physical check a refusal came from ("offset", ...), read
// back from its message (the word after "implausible trace: "); empty for a
// malformed trace or any other error.
std::string PlausibilityCheckName(const absl::Status& refusal);

}  // namespace surfmap
