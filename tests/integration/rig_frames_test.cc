// Frames and calibration through a real surfmapd: a rig registers its pose
// to the bottle (rotated, translated, a 3 mm tip, a turned F/T sensor),
// leases commands that carry the rig-frame command, submits traces in its own
// frame (accepted, fitted like the same drag in the object's frame, stored as
// sent) and in the wrong frame (refused, saying which frame it looks like,
// and kept as a rejected trace).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <sqlite3.h>

#include "absl/strings/match.h"
#include "server/codec/rig_registration_proto.h"
#include "gtest/gtest.h"
#include "server/codec/trace_samples_proto.h"
#include "server/frames/rig_frames.h"
#include "tests/support/job_helpers.h"
#include "server/base/testing/status_matchers.h"

namespace surfmap::itest {
namespace {

using status_matchers::IsOk;
using status_matchers::StatusIs;
using ::testing::HasSubstr;

constexpr char kRig[] = "arm-1";
constexpr double kPi = 3.14159265358979323846;

Eigen::Vector3d V(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }

// The rig's calibration: the bottle stands 450 mm in front of the base,
// turned 35 deg about a tilted axis; the sensor is turned 90 deg about z.
RigRegistration TheRegistration() {
  RigRegistration r;
  r.object_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(35.0 * kPi / 180, Eigen::Vector3d(0.2, 0.3, 1).normalized()));
  r.object_translation_mm = {450.0, -120.0, 75.0};
  r.tip_radius_mm = 3.0;
  r.sensor_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, Eigen::Vector3d::UnitZ()));
  return r;
}

pb::RigRegistration ToRequest(int64_t object_id, const RigRegistration& r) {
  pb::RigRegistration out;
  out.set_object_id(object_id);
  out.set_rig_name(kRig);
  *out.mutable_object_pose()->mutable_rotation() = QuaternionToProto(r.object_rotation);
  out.mutable_object_pose()->mutable_translation_mm()->set_x(r.object_translation_mm.x());
  out.mutable_object_pose()->mutable_translation_mm()->set_y(r.object_translation_mm.y());
  out.mutable_object_pose()->mutable_translation_mm()->set_z(r.object_translation_mm.z());
  out.set_tip_radius_mm(r.tip_radius_mm);
  *out.mutable_sensor_rotation() = QuaternionToProto(r.sensor_rotation);
  return out;
}

absl::Status Register(Stubs& stubs, const pb::RigRegistration& registration, pb::SetRigRegistrationResponse* out) {
  pb::SetRigRegistrationRequest request;
  *request.mutable_registration() = registration;
  return FromGrpc(stubs.objects->SetRigRegistration(Context().get(), request, out), "SetRigRegistration");
}

// The object-frame trace `request` re-expressed in `frame` with `r`.
pb::SubmitTraceRequest InFrame(pb::SubmitTraceRequest request, TraceFrame frame, const RigRegistration& r,
                               pb::TraceFrame stated) {
  absl::StatusOr<DragTrace> trace = DragTraceFromProto(request.samples(), 10'000'000);
  EXPECT_TRUE(trace.ok()) << trace.status();
  *request.mutable_samples() = DragTraceToProto(TraceFromObjectFrame(*trace, frame, r));
  request.set_frame(stated);
  return request;
}

absl::Status Submit(Stubs& stubs, const pb::SubmitTraceRequest& request, pb::SubmitTraceResponse* out) {
  return FromGrpc(stubs.probe->SubmitTrace(Context().get(), request, out), "SubmitTrace");
}

TEST(RigFramesTest, RegisterLeaseInBothFramesSubmitInRigFrameAndRefuseTheWrongFrame) {
  absl::StatusOr<SceneServer> setup = StartServerWithScene("bottle");
  ASSERT_THAT(setup, IsOk());
  Stubs& stubs = *setup->stubs;
  const RigRegistration registration = TheRegistration();

  // ---- Registration: validation, versions, history.
  pb::SetRigRegistrationResponse set;
  {
    pb::RigRegistration bad = ToRequest(setup->object_id, registration);
    bad.mutable_object_pose()->mutable_rotation()->set_w(0.5);
    EXPECT_THAT(Register(stubs, bad, &set), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("not a unit quaternion")));
    bad = ToRequest(setup->object_id, registration);
    bad.set_tip_radius_mm(80);
    EXPECT_THAT(Register(stubs, bad, &set), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("tip_radius_mm")));
    bad = ToRequest(setup->object_id, registration);
    bad.mutable_object_pose()->mutable_translation_mm()->set_x(NAN);
    EXPECT_THAT(Register(stubs, bad, &set), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("not finite")));
    bad = ToRequest(setup->object_id, registration);
    bad.mutable_object_pose()->clear_translation_mm();
    EXPECT_THAT(Register(stubs, bad, &set),
                StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("object_pose.translation_mm is required")));
    EXPECT_THAT(Register(stubs, ToRequest(999, registration), &set),
                StatusIs(absl::StatusCode::kNotFound, HasSubstr("object 999 does not exist")));
  }
  // Version 1: a 1 mm tip, the sensor aligned with the base.
  RigRegistration first = registration;
  first.tip_radius_mm = 1.0;
  first.sensor_rotation = Eigen::Quaterniond::Identity();
  ASSERT_THAT(Register(stubs, ToRequest(setup->object_id, first), &set), IsOk());
  const int64_t first_id = set.registration().registration_id();
  EXPECT_EQ(set.registration().version(), 1);

  // ---- Two identical jobs: the same drag goes to one in the object's frame
  // and to the other in the rig's.
  absl::StatusOr<pb::JobInfo> rig_job = CreateJob(stubs, UniformLevel0Spec(setup->object_id));
  absl::StatusOr<pb::JobInfo> object_job = CreateJob(stubs, UniformLevel0Spec(setup->object_id));
  ASSERT_THAT(rig_job, IsOk());
  ASSERT_THAT(object_job, IsOk());
  absl::StatusOr<pb::ProbeCommand> command = LeaseOne(stubs, rig_job->job_id(), kRig);
  absl::StatusOr<pb::ProbeCommand> twin = LeaseOne(stubs, object_job->job_id(), kRig);
  ASSERT_THAT(command, IsOk());
  ASSERT_THAT(twin, IsOk());
  ASSERT_EQ(V(command->position()), V(twin->position()));

  // The command in both frames, with version 1.
  ASSERT_TRUE(command->has_rig_frame());
  {
    const pb::RigFrameCommand& rf = command->rig_frame();
    EXPECT_EQ(rf.registration_id(), first_id);
    EXPECT_EQ(rf.registration_version(), 1);
    EXPECT_LT((V(rf.position()) - ObjectPointToBase(first, V(command->position()))).norm(), 1e-9);
    EXPECT_LT((V(rf.normal()) - ObjectVectorToBase(first, V(command->normal()))).norm(), 1e-9);
    EXPECT_LT((V(rf.drag_direction()) - ObjectVectorToBase(first, V(command->drag_direction()))).norm(), 1e-9);
    ASSERT_GE(rf.tool_centre_path_size(), 15);  // ~1 mm apart over 20 mm
    EXPECT_NEAR((V(rf.tool_centre_path(0)) - V(rf.start())).norm(), 1.0, 1e-6);
    EXPECT_NEAR((V(rf.tool_centre_path(rf.tool_centre_path_size() - 1)) - V(rf.end())).norm(), 1.0, 1e-6);
    EXPECT_NEAR((V(rf.end()) - V(rf.start())).norm(), 20.0, 1.0);  // a 20 mm drag on a gently curved bottle
    // The tool centre passes over the site, along its normal.
    const Eigen::Vector3d over_site = V(rf.position()) + 1.0 * V(rf.normal());
    double nearest = 1e9;
    for (const pb::Vec3& p : rf.tool_centre_path()) nearest = std::min(nearest, (V(p) - over_site).norm());
    EXPECT_LT(nearest, 0.6);
  }

  // Version 2: a 3 mm tip and the sensor turned 90 deg about an axis across
  // this site's normal (a turn about the normal itself would not show in a
  // drag's forces, so nothing could tell the frames apart).
  RigRegistration registration_v2 = registration;
  {
    const Eigen::Vector3d n = ObjectVectorToBase(registration, V(command->normal()));
    const Eigen::Vector3d across = n.unitOrthogonal();
    registration_v2.sensor_rotation = Eigen::Quaterniond(Eigen::AngleAxisd(kPi / 2, across));
  }
  ASSERT_THAT(Register(stubs, ToRequest(setup->object_id, registration_v2), &set), IsOk());
  const int64_t registration_id = set.registration().registration_id();
  EXPECT_EQ(set.registration().version(), 2);
  {
    pb::GetRigRegistrationRequest get;
    get.set_registration_id(first_id);
    pb::GetRigRegistrationResponse got;
    ASSERT_THAT(FromGrpc(stubs.objects->GetRigRegistration(Context().get(), get, &got), "GetRigRegistration"), IsOk());
    EXPECT_EQ(got.registration().tip_radius_mm(), 1.0);  // an older version stays readable
    pb::ListRigRegistrationsRequest list;
    list.set_object_id(setup->object_id);
    list.set_include_history(true);
    pb::ListRigRegistrationsResponse listed;
    ASSERT_THAT(FromGrpc(stubs.objects->ListRigRegistrations(Context().get(), list, &listed), "ListRigRegistrations"),
                IsOk());
    EXPECT_EQ(listed.registrations_size(), 2);
    list.set_include_history(false);
    ASSERT_THAT(FromGrpc(stubs.objects->ListRigRegistrations(Context().get(), list, &listed), "ListRigRegistrations"),
                IsOk());
    ASSERT_EQ(listed.registrations_size(), 1);
    EXPECT_EQ(listed.registrations(0).registration_id(), registration_id);
  }
  // The next command is computed with version 2.
  absl::StatusOr<pb::ProbeCommand> next = LeaseOne(stubs, rig_job->job_id(), kRig);
  ASSERT_THAT(next, IsOk());
  ASSERT_TRUE(next->has_rig_frame());
  EXPECT_EQ(next->rig_frame().registration_id(), registration_id);
  EXPECT_EQ(next->rig_frame().tip_radius_mm(), 3.0);
  ASSERT_GE(next->rig_frame().tool_centre_path_size(), 2);
  EXPECT_NEAR((V(next->rig_frame().tool_centre_path(0)) - V(next->rig_frame().start())).norm(), 3.0, 1e-6);
  // A rig without a registration gets the object frame only.
  absl::StatusOr<pb::ProbeCommand> unregistered = LeaseOne(stubs, rig_job->job_id(), "arm-2");
  ASSERT_THAT(unregistered, IsOk());
  EXPECT_FALSE(unregistered->has_rig_frame());

  // ---- The same drag: object frame to the twin job, rig frame (sensor
  // forces) to the other.
  absl::StatusOr<pb::SubmitTraceRequest> drag = ExecuteOnRig(*setup->rig, *command, kRig);
  ASSERT_THAT(drag, IsOk());
  pb::SubmitTraceRequest object_request = *drag;
  object_request.set_command_id(twin->command_id());
  pb::SubmitTraceResponse object_answer, rig_answer, refused;
  ASSERT_THAT(Submit(stubs, object_request, &object_answer), IsOk());

  // Wrong frames first (the command stays leased after a refusal).
  const pb::SubmitTraceRequest rig_as_object =
      InFrame(*drag, TraceFrame::kRigBase, registration_v2, pb::TRACE_FRAME_OBJECT);
  EXPECT_THAT(Submit(stubs, rig_as_object, &refused),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr("implausible trace: frame: the trace looks like it is in the rig's base frame")));
  const pb::SubmitTraceRequest sensor_as_base =
      InFrame(*drag, TraceFrame::kRigBaseSensorForces, registration_v2, pb::TRACE_FRAME_RIG_BASE);
  EXPECT_THAT(Submit(stubs, sensor_as_base, &refused),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       HasSubstr("looks like it is in the rig's base frame with forces in the F/T sensor's frame")));
  // A trace with an unrelated fault keeps its own message.
  pb::SubmitTraceRequest far = rig_as_object;
  far.set_frame(pb::TRACE_FRAME_RIG_BASE);
  for (int i = 0; i < far.samples().x_size(); ++i) far.mutable_samples()->set_x(i, far.samples().x(i) + 500.0);
  EXPECT_THAT(Submit(stubs, far, &refused), StatusIs(absl::StatusCode::kInvalidArgument, HasSubstr("implausible trace: offset")));

  const pb::SubmitTraceRequest rig_request =
      InFrame(*drag, TraceFrame::kRigBaseSensorForces, registration_v2, pb::TRACE_FRAME_RIG_BASE_SENSOR_FORCES);
  ASSERT_THAT(Submit(stubs, rig_request, &rig_answer), IsOk());
  // The same fit as the object-frame submission (the transforms round to 1e-13).
  const pb::FrictionEstimate& a = object_answer.sample().fit().friction();
  const pb::FrictionEstimate& b = rig_answer.sample().fit().friction();
  EXPECT_NEAR(a.mu(), b.mu(), 1e-9);
  EXPECT_LT((V(a.normal()) - V(b.normal())).norm(), 1e-9);  // the fit is in the object's frame
  EXPECT_EQ(a.pair_count(), b.pair_count());
  EXPECT_NEAR(object_answer.sample().fit().roughness().sigma(), rig_answer.sample().fit().roughness().sigma(), 1e-9);

  // Stored exactly as sent, with its frame and registration.
  pb::GetTraceRequest get_trace;
  get_trace.set_trace_id(rig_answer.sample().trace_id());
  pb::GetTraceResponse stored;
  ASSERT_THAT(FromGrpc(stubs.traces->GetTrace(Context().get(), get_trace, &stored), "GetTrace"), IsOk());
  EXPECT_EQ(stored.frame(), pb::TRACE_FRAME_RIG_BASE_SENSOR_FORCES);
  EXPECT_EQ(stored.registration_id(), registration_id);
  EXPECT_EQ(stored.samples().SerializeAsString(), rig_request.samples().SerializeAsString());
  get_trace.set_trace_id(object_answer.sample().trace_id());
  ASSERT_THAT(FromGrpc(stubs.traces->GetTrace(Context().get(), get_trace, &stored), "GetTrace"), IsOk());
  EXPECT_EQ(stored.frame(), pb::TRACE_FRAME_OBJECT);
  EXPECT_EQ(stored.registration_id(), 0);

  // The recomputed series (from the stored trace) reads it in the object's frame.
  pb::GetSampleRequest sample_request;
  sample_request.set_trace_id(rig_answer.sample().trace_id());
  sample_request.set_include_series(true);
  pb::GetSampleResponse sample;
  ASSERT_THAT(FromGrpc(stubs.maps->GetSample(Context().get(), sample_request, &sample), "GetSample"), IsOk());
  EXPECT_GT(sample.sample().fit().friction().pair_mu_size(), 0);

  // The refused traces were kept, with the frame check named.
  pb::ListRejectedTracesRequest list_rejected;
  list_rejected.set_job_id(rig_job->job_id());
  pb::ListRejectedTracesResponse rejected;
  ASSERT_THAT(FromGrpc(stubs.traces->ListRejectedTraces(Context().get(), list_rejected, &rejected), "ListRejectedTraces"), IsOk());
  ASSERT_EQ(rejected.rejected_traces_size(), 3);
  EXPECT_EQ(rejected.rejected_traces(0).check(), "frame");
  EXPECT_EQ(rejected.rejected_traces(1).check(), "frame");
  EXPECT_EQ(rejected.rejected_traces(2).check(), "offset");
  // Each with the frame it was sent in and its registration (its samples are
  // kept as sent): in the trace_rejected events, and stored with it.
  pb::ListJobEventsRequest list_events;
  list_events.set_job_id(rig_job->job_id());
  pb::ListJobEventsResponse events;
  ASSERT_THAT(FromGrpc(stubs.jobs->ListJobEvents(Context().get(), list_events, &events), "ListJobEvents"), IsOk());
  std::vector<std::pair<std::string, int64_t>> rejected_frames;
  for (const pb::JobEvent& event : events.events()) {
    if (event.kind() != "trace_rejected") continue;
    const nlohmann::json detail = nlohmann::json::parse(event.detail_json());
    rejected_frames.emplace_back(detail.at("frame").get<std::string>(), detail.at("registration_id").get<int64_t>());
  }
  const std::vector<std::pair<std::string, int64_t>> sent_in = {
      {"object", 0}, {"rig_base", registration_id}, {"rig_base", registration_id}};
  EXPECT_EQ(rejected_frames, sent_in);
  const std::vector<std::pair<pb::TraceFrame, int64_t>> listed_frames = {
      {rejected.rejected_traces(0).frame(), rejected.rejected_traces(0).registration_id()},
      {rejected.rejected_traces(1).frame(), rejected.rejected_traces(1).registration_id()},
      {rejected.rejected_traces(2).frame(), rejected.rejected_traces(2).registration_id()}};
  const std::vector<std::pair<pb::TraceFrame, int64_t>> listed_sent_in = {
      {pb::TRACE_FRAME_OBJECT, 0}, {pb::TRACE_FRAME_RIG_BASE, registration_id},
      {pb::TRACE_FRAME_RIG_BASE, registration_id}};
  EXPECT_EQ(listed_frames, listed_sent_in);

  // A rig-frame trace from a rig without a registration is refused as such.
  absl::StatusOr<pb::SubmitTraceRequest> other = ExecuteOnRig(*setup->rig, *unregistered, "arm-2");
  ASSERT_THAT(other, IsOk());
  other->set_frame(pb::TRACE_FRAME_RIG_BASE);
  EXPECT_THAT(Submit(stubs, *other, &refused),
              StatusIs(absl::StatusCode::kFailedPrecondition, HasSubstr("rig 'arm-2' has no registration for object")));

  // Refits read rig-frame traces through their registration, too.
  pb::RefitJobRequest refit;
  refit.set_job_id(rig_job->job_id());
  refit.mutable_settings()->set_step_mm(0.2);
  refit.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
  refit.mutable_settings()->set_ar_order(2);
  pb::RefitJobResponse refit_answer;
  ASSERT_THAT(FromGrpc(stubs.traces->RefitJob(Context().get(), refit, &refit_answer), "RefitJob"), IsOk());
  EXPECT_EQ(refit_answer.refitted(), 1);
  EXPECT_EQ(refit_answer.failed(), 0);

  // Registrations survive a restart (leases use them at once).
  ASSERT_THAT(setup->server->Stop(std::chrono::seconds(30)), IsOk());
  ASSERT_THAT(setup->server->Restart(), IsOk());
  Stubs restarted(setup->server->channel());
  absl::StatusOr<pb::ProbeCommand> after = LeaseOne(restarted, rig_job->job_id(), kRig);
  ASSERT_THAT(after, IsOk());
  ASSERT_TRUE(after->has_rig_frame());
  EXPECT_EQ(after->rig_frame().registration_id(), registration_id);

  // A stored frame this build does not know (written by a newer server, or
  // damaged) is DATA_LOSS, as a refit says for it, never the object's frame.
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(setup->server->db_path().c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
    sqlite3_busy_timeout(db, 10000);
    const std::string sql = "PRAGMA ignore_check_constraints = ON; UPDATE trace_frames SET frame = 'rig_tool' "
                            "WHERE trace_id = " + std::to_string(rig_answer.sample().trace_id());
    char* error = nullptr;
    EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
    sqlite3_free(error);
    sqlite3_close_v2(db);
  }
  get_trace.set_trace_id(rig_answer.sample().trace_id());
  EXPECT_THAT(FromGrpc(restarted.traces->GetTrace(Context().get(), get_trace, &stored), "GetTrace"),
              StatusIs(absl::StatusCode::kDataLoss, HasSubstr("stored frame")));
}

}  // namespace
}  // namespace surfmap::itest
