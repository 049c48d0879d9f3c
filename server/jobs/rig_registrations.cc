#include "server/jobs/rig_registrations.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "server/base/status_macros.h"
#include "server/base/utf8_text.h"

namespace surfmap {

absl::StatusOr<RegisteredRig> DecodeRegistration(RigRegistrationRecord record) {
  absl::StatusOr<RigRegistration> decoded = RigRegistrationFromJson(record.registration_json);
  if (!decoded.ok()) {
    return absl::DataLossError(
        absl::StrCat("stored rig registration ", record.id, " cannot be read: ", decoded.status().message()));
  }
  return RegisteredRig{std::move(record), *decoded};
}

absl::Status RigRegistrations::Load() {
  SURFMAP_ASSIGN_OR_RETURN(std::vector<RigRegistrationRecord> all, store_->ListRigRegistrations(0));
  for (RigRegistrationRecord& record : all) {
    SURFMAP_ASSIGN_OR_RETURN(RegisteredRig rig, DecodeRegistration(std::move(record)));
    Remember(std::make_shared<const RegisteredRig>(std::move(rig)));
  }
  return absl::OkStatus();
}

void RigRegistrations::Remember(std::shared_ptr<const RegisteredRig> rig) const {
  MutexLock lock(&mu_);
  by_id_.emplace(rig->record.id, rig);
  std::shared_ptr<const RegisteredRig>& slot = latest_[Key{rig->record.object_id, rig->record.rig_name}];
  // Two registrations stored concurrently may arrive here out of order.
  if (!slot || slot->record.version < rig->record.version) slot = std::move(rig);
}

absl::StatusOr<RegisteredRig> RigRegistrations::Register(int64_t object_id, const std::string& rig_name,
                                                         const RigRegistration& registration) {
  if (object_id <= 0) return absl::InvalidArgumentError("object_id must be a positive object id");
  SURFMAP_RETURN_IF_ERROR(ValidateName("rig_name", rig_name, 1, 100));  // the rule for rig_id
  NewRigRegistration row{object_id, rig_name, RigRegistrationToJson(registration)};
  SURFMAP_ASSIGN_OR_RETURN(RigRegistrationRecord stored, store_->AddRigRegistration(row));
  SURFMAP_ASSIGN_OR_RETURN(RegisteredRig rig, DecodeRegistration(std::move(stored)));
  Remember(std::make_shared<const RegisteredRig>(rig));
  return rig;
}

std::shared_ptr<const RegisteredRig> RigRegistrations::Latest(int64_t object_id, const std::string& rig_name) const {
  MutexLock lock(&mu_);
  auto it = latest_.find(Key{object_id, rig_name});
  return it == latest_.end() ? nullptr : it->second;
}

absl::StatusOr<std::shared_ptr<const RegisteredRig>> RigRegistrations::Get(int64_t registration_id) const {
  if (registration_id <= 0) return absl::InvalidArgumentError("registration_id must be a positive id");
  {
    MutexLock lock(&mu_);
    auto it = by_id_.find(registration_id);
    if (it != by_id_.end()) return it->second;
  }
  SURFMAP_ASSIGN_OR_RETURN(RigRegistrationRecord record, store_->GetRigRegistration(registration_id));
  SURFMAP_ASSIGN_OR_RETURN(RegisteredRig rig, DecodeRegistration(std::move(record)));
  auto shared = std::make_shared<const RegisteredRig>(std::move(rig));
  Remember(shared);
  return shared;
}

absl::StatusOr<std::vector<RegisteredRig>> RigRegistrations::List(int64_t object_id, bool include_history) const {
  if (object_id < 0) return absl::InvalidArgumentError("object_id must be >= 0 (0 = all objects)");
  if (object_id > 0) SURFMAP_RETURN_IF_ERROR(store_->GetObject(object_id, false).status());
  SURFMAP_ASSIGN_OR_RETURN(std::vector<RigRegistrationRecord> all, store_->ListRigRegistrations(object_id));
  std::map<Key, int32_t> newest;
  for (const RigRegistrationRecord& r : all) {
    int32_t& v = newest[Key{r.object_id, r.rig_name}];
    v = std::max(v, r.version);
  }
  std::vector<RegisteredRig> out;
  for (RigRegistrationRecord& r : all) {
    if (!include_history && newest[Key{r.object_id, r.rig_name}] != r.version) continue;
    SURFMAP_ASSIGN_OR_RETURN(RegisteredRig rig, DecodeRegistration(std::move(r)));
    out.push_back(std::move(rig));
  }
  return out;
}

absl::StatusOr<DragTrace> RigRegistrations::StoredTraceInObjectFrame(int64_t trace_id,
                                                                      const DragTrace& as_stored) const {
  SURFMAP_ASSIGN_OR_RETURN(TraceFrameRecord frame_record, store_->GetTraceFrame(trace_id));
  absl::StatusOr<TraceFrame> frame = ParseTraceFrame(frame_record.frame);
  if (!frame.ok()) {
    return absl::DataLossError(absl::StrCat("trace ", trace_id, ": stored frame: ", frame.status().message()));
  }
  if (*frame == TraceFrame::kObject) return as_stored;
  SURFMAP_ASSIGN_OR_RETURN(std::shared_ptr<const RegisteredRig> rig, Get(frame_record.registration_id));
  return TraceToObjectFrame(as_stored, *frame, rig->registration);
}

}  // namespace surfmap
