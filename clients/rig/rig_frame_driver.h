// RigFrameDriver: a driver that records in the object's frame (the simulated
// rig) made to answer like a registered robot recording in its own frame:
// each command must carry its rig-frame form (the rig is registered to the
// object), and the trace is re-expressed in the rig's base frame (and the
// F/T sensor's, for kRigBaseSensorForces) with the registration the command
// was computed with. surfmap-rig --sim SCENE --frame ... uses it, so the
// rig-frame path runs end to end against a real server.
#pragma once

#include <cstdint>
#include <functional>
#include <map>

#include "absl/status/statusor.h"
#include "clients/sim/rig/rig_driver.h"
#include "server/frames/rig_frames.h"
#include "server/frames/rig_registration.h"

namespace surfmap::rig {

class RigFrameDriver final : public RigDriver {
 public:
  // `fetch`: the registration with this id (GetRigRegistration).
  using FetchRegistration = std::function<absl::StatusOr<RigRegistration>(std::int64_t registration_id)>;
  RigFrameDriver(RigDriver& inner, TraceFrame frame, FetchRegistration fetch)
      : inner_(inner), frame_(frame), fetch_(std::move(fetch)) {}

  // INTERNAL (the loop stops) for a command without a rig frame: the rig is
  // not registered to the object, and every trace it sent would be refused;
  // and when `fetch` fails other than UNAVAILABLE / DEADLINE_EXCEEDED (those
  // pass through: the command fails TRANSIENT and is retried).
  absl::StatusOr<DragTrace> Execute(const ProbeRequest& request) override;

 private:
  RigDriver& inner_;
  const TraceFrame frame_;
  const FetchRegistration fetch_;
  std::map<std::int64_t, RigRegistration> registrations_;  // by id (registrations never change)
};

}  // namespace surfmap::rig
