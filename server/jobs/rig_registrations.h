// The rigs' registrations to objects (server/frames/rig_registration.h),
// keyed by (object, rig name = the rig_id the rig leases with): stored
// append-only in the Store (a new registration is the next version; a trace
// keeps naming the one it was converted with), the latest of each key held
// in memory so a lease computes its rig-frame command without a read.
//
// Every registration read (at start-up, registered, or read by id) is kept
// decoded by id too: registrations are append-only, so a refit converts its
// rig-frame traces without reading or decoding their registration again.
//
// Locks: mu_ is a leaf, held only to read or replace a map entry; the store
// is never called under it.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/base/thread_annotations.h"
#include "absl/status/statusor.h"
#include "server/base/mutex.h"
#include "server/estimate/drag_trace.h"
#include "server/frames/rig_frames.h"
#include "server/frames/rig_registration.h"
#include "storage/store.h"

namespace surfmap {

struct RegisteredRig {
  RigRegistrationRecord record;   // id, object, rig, version, time, JSON
  RigRegistration registration;   // decoded
};

class RigRegistrations {
 public:
  explicit RigRegistrations(Store* store) : store_(store) {}

  // Reads every stored registration (at start-up). DATA_LOSS naming the
  // registration if one cannot be read.
  absl::Status Load();
  // Stores the next version for (object_id, rig_name) and makes it the one
  // leases use. Blocks on the write: call it from a pool thread. NotFound for
  // an unknown object; INVALID_ARGUMENT for a bad rig name.
  absl::StatusOr<RegisteredRig> Register(int64_t object_id, const std::string& rig_name,
                                         const RigRegistration& registration);
  // The latest registration of the rig for the object; null if it has none.
  std::shared_ptr<const RegisteredRig> Latest(int64_t object_id, const std::string& rig_name) const;
  // Any version, by id (memory first, then the store, kept).
  absl::StatusOr<std::shared_ptr<const RegisteredRig>> Get(int64_t registration_id) const;
  // From the store: every version (history) or only the latest per rig,
  // oldest first; object_id 0: all objects.
  absl::StatusOr<std::vector<RegisteredRig>> List(int64_t object_id, bool include_history) const;

  // A stored trace's samples in the object's frame: converted with the
  // registration it was stored with when it was sent in a rig's frame. One
  // indexed read (its frame); the registration comes from memory. DATA_LOSS
  // for a stored frame or registration that cannot be read. For refits and
  // recomputed series.
  absl::StatusOr<DragTrace> StoredTraceInObjectFrame(int64_t trace_id, const DragTrace& as_stored) const;

 private:
  using Key = std::pair<int64_t, std::string>;
  void Remember(std::shared_ptr<const RegisteredRig> rig) const ABSL_LOCKS_EXCLUDED(mu_);

  Store* const store_;
  mutable Mutex mu_;
  mutable std::map<Key, std::shared_ptr<const RegisteredRig>> latest_ ABSL_GUARDED_BY(mu_);
  mutable std::map<int64_t, std::shared_ptr<const RegisteredRig>> by_id_ ABSL_GUARDED_BY(mu_);
};

absl::StatusOr<RegisteredRig> DecodeRegistration(RigRegistrationRecord record);

}  // namespace surfmap
