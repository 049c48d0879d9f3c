#include "clients/rig/rig_frame_driver.h"

#include "absl/strings/str_cat.h"

namespace surfmap::rig {

absl::StatusOr<DragTrace> RigFrameDriver::Execute(const ProbeRequest& request) {
  if (!request.rig_frame || request.rig_frame->registration_id <= 0) {
    return absl::InternalError(absl::StrCat(
        "command ", request.command_id, " came without its rig-frame form: this rig is not registered to the job's "
        "object (surfmap object register OBJECT --rig RIG_ID ...), so it cannot send traces in ",
        std::string(TraceFrameName(frame_)), " frame"));
  }
  const std::int64_t id = request.rig_frame->registration_id;
  auto it = registrations_.find(id);
  if (it == registrations_.end()) {
    absl::StatusOr<RigRegistration> fetched = fetch_(id);
    if (!fetched.ok()) {
      const absl::StatusCode code = fetched.status().code();
      const std::string why = absl::StrCat("registration ", id, ": ", fetched.status().message());
      // The server unreachable or slow: this command fails TRANSIENT and the
      // next one fetches again. Anything else (NOT_FOUND, PERMISSION_DENIED,
      // a registration that does not validate) is the same for every
      // command: stop rather than burn each command's retries on it.
      if (code == absl::StatusCode::kUnavailable || code == absl::StatusCode::kDeadlineExceeded) {
        return absl::Status(code, why);
      }
      return absl::InternalError(absl::StrCat(why, " (", absl::StatusCodeToString(code), ")"));
    }
    it = registrations_.emplace(id, *fetched).first;
  }
  absl::StatusOr<DragTrace> trace = inner_.Execute(request);
  if (!trace.ok()) return trace.status();
  return TraceFromObjectFrame(*trace, frame_, it->second);
}

}  // namespace surfmap::rig
