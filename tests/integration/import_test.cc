// Import and provenance through the real server (issues 13, 14): a drag made
// by the simulated rig outside any leased command, imported as a CSV file,
// becomes a sample with its provenance, is in ListSamples and the map, is
// stored once per file, survives a restart and a refit; a drag above the
// surface is refused naming why and kept; provenance round-trips on objects,
// jobs and submitted traces; the map's regions name the pieces of leased and
// imported drags alike behind their estimates.
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>

#include "gtest/gtest.h"
#include "server/estimate/trace_csv.h"
#include "tests/support/job_helpers.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

pb::Provenance LabProvenance(const std::string& operator_name) {
  pb::Provenance p;
  p.set_operator_name(operator_name);
  p.set_specimen("plate #7");
  p.set_probe_tip("steel ball 3 mm");
  p.set_sensor("Nano17 FT12345");
  p.set_notes("after cleaning\nwith ethanol");
  (*p.mutable_extra())["humidity_pct"] = "41";
  return p;
}

void ExpectSameProvenance(const pb::Provenance& got, const pb::Provenance& want) {
  EXPECT_EQ(got.operator_name(), want.operator_name());
  EXPECT_EQ(got.specimen(), want.specimen());
  EXPECT_EQ(got.probe_tip(), want.probe_tip());
  EXPECT_EQ(got.sensor(), want.sensor());
  EXPECT_EQ(got.notes(), want.notes());
  ASSERT_EQ(got.extra_size(), want.extra_size());
  for (const auto& [key, value] : want.extra()) EXPECT_EQ(got.extra().at(key), value) << key;
}

// The simulated rig's drag centred on `at` (on the plate, z = 0), as a trace CSV, `lift` mm above the surface.
std::string RigDragCsv(const SimulatedRig& rig, const Eigen::Vector3d& at, const Eigen::Vector3d& direction,
                       int64_t seed, double lift = 0.0) {
  ProbeRequest request;
  const SurfacePoint p = rig.surface().ClosestPoint(at);
  request.position = p.position;
  request.normal = p.normal;
  request.drag_direction = (direction - direction.dot(p.normal) * p.normal).normalized();
  request.command_id = seed;
  absl::StatusOr<ProbeExecution> executed = rig.ExecuteDetailed(request);
  EXPECT_TRUE(executed.ok()) << executed.status();
  for (DragSample& s : executed->trace.samples) s.position += lift * p.normal;
  return "# a hand drag, not a leased command\n" + FormatTraceCsv(executed->trace);
}

absl::StatusOr<pb::ImportTraceResponse> Import(Stubs& stubs, int64_t job_id, const std::string& csv,
                                               const std::string& file_name, const pb::Provenance& provenance) {
  pb::ImportTraceRequest request;
  request.set_job_id(job_id);
  request.set_csv(csv);
  request.set_file_name(file_name);
  request.set_source("bench-rig-2");
  request.mutable_recorded()->set_seconds(1'790'000'000);
  *request.mutable_provenance() = provenance;
  pb::ImportTraceResponse response;
  grpc::Status status = stubs.traces->ImportTrace(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "ImportTrace");
  return response;
}

const pb::Sample* FindSample(const pb::ListSamplesResponse& samples, int64_t trace_id) {
  for (const pb::Sample& s : samples.samples()) {
    if (s.trace_id() == trace_id) return &s;
  }
  return nullptr;
}

TEST(ImportTrace, AnImportedDragIsASampleOfTheMapAndSurvivesARestartAndARefit) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id, /*budget=*/3)));
  const pb::Provenance provenance = LabProvenance("A. Lloyd");
  // On the masonite square (mu 0.25), well inside it.
  const std::string csv = RigDragCsv(*setup.rig, {31, 0, 0}, {0, 1, 0}, 4242);
  ITEST_ASSERT_OK_AND_ASSIGN(imported, Import(*setup.stubs, job.job_id(), csv, "hand_017.csv", provenance));
  EXPECT_FALSE(imported.already_imported());
  const pb::Sample& sample = imported.sample();
  EXPECT_GT(sample.trace_id(), 0);
  EXPECT_EQ(sample.rig_id(), "bench-rig-2");
  EXPECT_NEAR(sample.position().x(), 31.0, 0.5);
  EXPECT_NEAR(sample.position().y(), 0.0, 0.5);
  // Masonite's rough texture spreads one drag's mu: 0.25 +- 0.07 (wood, around it, is 0.42).
  EXPECT_NEAR(sample.fit().friction().mu(), 0.25, 0.07);
  ASSERT_TRUE(sample.has_import());
  EXPECT_EQ(sample.import().source(), "bench-rig-2");
  EXPECT_EQ(sample.import().file_name(), "hand_017.csv");
  EXPECT_EQ(sample.import().file_sha256().size(), 64u);
  EXPECT_EQ(sample.import().recorded().seconds(), 1'790'000'000);
  EXPECT_GT(sample.import().imported().seconds(), 1'700'000'000);
  ExpectSameProvenance(sample.provenance(), provenance);

  // In ListSamples, GetTrace and the map; no planned site is marked measured by it.
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(*setup.stubs, job.job_id()));
  const pb::Sample* listed = FindSample(samples, sample.trace_id());
  ASSERT_NE(listed, nullptr);
  ExpectSameProvenance(listed->provenance(), provenance);
  EXPECT_EQ(listed->import().file_sha256(), sample.import().file_sha256());
  pb::GetTraceRequest get_trace;
  get_trace.set_trace_id(sample.trace_id());
  pb::GetTraceResponse trace;
  GRPC_ASSERT_OK(setup.stubs->traces->GetTrace(Context().get(), get_trace, &trace));
  EXPECT_EQ(trace.import().file_name(), "hand_017.csv");
  ExpectSameProvenance(trace.provenance(), provenance);
  ITEST_ASSERT_OK_AND_ASSIGN(j, GetJob(*setup.stubs, job.job_id()));
  EXPECT_EQ(j.progress().measured(), 0);
  auto query_mu = [&](Stubs& stubs) -> double {
    pb::QueryMapRequest query;
    query.set_job_id(job.job_id());
    pb::Vec3* point = query.add_points();
    point->set_x(31);
    pb::QueryMapResponse answer;
    grpc::Status status = stubs.maps->QueryMap(Context().get(), query, &answer);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return status.ok() && answer.values_size() == 1 ? answer.values(0).mu() : NAN;
  };
  // The map holds only this drag: its mu is the map's there.
  EXPECT_NEAR(query_mu(*setup.stubs), sample.fit().friction().mu(), 0.01);
  ITEST_ASSERT_OK_AND_ASSIGN(map, GetMap(*setup.stubs, job.job_id(), -1, false));
  bool in_map = false;
  for (const pb::Sample& s : map.map().samples()) in_map |= s.trace_id() == sample.trace_id();
  EXPECT_TRUE(in_map);

  // The same file again: the same sample, nothing stored twice.
  ITEST_ASSERT_OK_AND_ASSIGN(again, Import(*setup.stubs, job.job_id(), csv, "copy_of_hand_017.csv", provenance));
  EXPECT_TRUE(again.already_imported());
  EXPECT_EQ(again.sample().trace_id(), sample.trace_id());
  EXPECT_EQ(again.sample().import().file_name(), "hand_017.csv");  // what the first import stored

  ITEST_ASSERT_OK(setup.server->Stop(std::chrono::seconds(30)).status());
  ITEST_ASSERT_OK(setup.server->Restart());
  Stubs stubs(setup.server->channel());
  ITEST_ASSERT_OK_AND_ASSIGN(after, ListSamples(stubs, job.job_id()));
  ASSERT_EQ(after.samples_size(), 1);
  EXPECT_EQ(after.samples(0).trace_id(), sample.trace_id());
  ExpectSameProvenance(after.samples(0).provenance(), provenance);
  EXPECT_NEAR(query_mu(stubs), sample.fit().friction().mu(), 0.01);
  ITEST_ASSERT_OK_AND_ASSIGN(still_once, Import(stubs, job.job_id(), csv, "hand_017.csv", provenance));
  EXPECT_TRUE(still_once.already_imported());

  pb::RefitJobRequest refit;
  refit.set_job_id(job.job_id());
  refit.mutable_settings()->set_step_mm(0.2);
  refit.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
  pb::RefitJobResponse refitted;
  GRPC_ASSERT_OK(stubs.traces->RefitJob(Context().get(), refit, &refitted));
  EXPECT_EQ(refitted.refitted(), 1);
  ITEST_ASSERT_OK_AND_ASSIGN(refit_samples, ListSamples(stubs, job.job_id()));
  ASSERT_EQ(refit_samples.samples_size(), 1);
  EXPECT_EQ(refit_samples.samples(0).fit().version(), 2);
  EXPECT_TRUE(refit_samples.samples(0).has_import());
  EXPECT_NEAR(query_mu(stubs), sample.fit().friction().mu(), 0.01);
}

TEST(ImportTrace, ADragAboveTheSurfaceIsRefusedNamingWhyAndKept) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id, /*budget=*/3)));
  const std::string lifted = RigDragCsv(*setup.rig, {-20, 20, 0}, {1, 0, 0}, 77, /*lift=*/15.0);
  absl::StatusOr<pb::ImportTraceResponse> refused =
      Import(*setup.stubs, job.job_id(), lifted, "lifted.csv", pb::Provenance());
  ASSERT_EQ(refused.status().code(), absl::StatusCode::kInvalidArgument) << refused.status();
  EXPECT_NE(refused.status().message().find("implausible trace: surface: "), std::string::npos) << refused.status();
  EXPECT_NE(refused.status().message().find("lifted.csv"), std::string::npos) << refused.status();
  pb::ListRejectedTracesRequest list;
  list.set_job_id(job.job_id());
  pb::ListRejectedTracesResponse rejected;
  GRPC_ASSERT_OK(setup.stubs->traces->ListRejectedTraces(Context().get(), list, &rejected));
  ASSERT_EQ(rejected.rejected_traces_size(), 1);
  EXPECT_EQ(rejected.rejected_traces(0).rig_id(), "bench-rig-2");
  EXPECT_EQ(rejected.rejected_traces(0).check(), "surface");
  EXPECT_NE(rejected.rejected_traces(0).message().find("lifted.csv"), std::string::npos);
  ITEST_ASSERT_OK_AND_ASSIGN(samples, ListSamples(*setup.stubs, job.job_id()));
  EXPECT_EQ(samples.samples_size(), 0);

  // Not a trace CSV at all: the reader's line-numbered message.
  absl::StatusOr<pb::ImportTraceResponse> garbage =
      Import(*setup.stubs, job.job_id(), "t,x,y\n1,2,3\n", "garbage.csv", pb::Provenance());
  ASSERT_EQ(garbage.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(garbage.status().message().find("garbage.csv:1:"), std::string::npos) << garbage.status();
  // Provenance out of bounds: named.
  pb::Provenance long_operator;
  long_operator.set_operator_name(std::string(300, 'x'));
  absl::StatusOr<pb::ImportTraceResponse> too_long =
      Import(*setup.stubs, job.job_id(), RigDragCsv(*setup.rig, {-20, 20, 0}, {1, 0, 0}, 78), "x.csv", long_operator);
  ASSERT_EQ(too_long.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(too_long.status().message().find("provenance operator"), std::string::npos) << too_long.status();
}

TEST(Provenance, RoundTripsOnObjectsJobsAndSubmittedTraces) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  Stubs& stubs = *setup.stubs;
  const pb::Provenance lab = LabProvenance("D. Pai");

  pb::GetObjectRequest get_object;
  get_object.set_object_id(setup.object_id);
  pb::GetObjectResponse plain_object;
  GRPC_ASSERT_OK(stubs.objects->GetObject(Context().get(), get_object, &plain_object));
  EXPECT_EQ(plain_object.object().provenance().operator_name(), "");  // none given

  pb::UploadObjectRequest upload;
  upload.set_name("plate with provenance");
  upload.set_format(pb::MESH_FORMAT_OBJ);
  // The regular tetrahedron of the test data, 2x: 40 mm across.
  upload.set_mesh("v 20 20 20\nv 20 -20 -20\nv -20 20 -20\nv -20 -20 20\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n");
  *upload.mutable_provenance() = lab;
  pb::UploadObjectResponse uploaded;
  GRPC_ASSERT_OK(stubs.objects->UploadObject(Context().get(), upload, &uploaded));
  ExpectSameProvenance(uploaded.object().provenance(), lab);
  get_object.set_object_id(uploaded.object().object_id());
  pb::GetObjectResponse got_object;
  GRPC_ASSERT_OK(stubs.objects->GetObject(Context().get(), get_object, &got_object));
  ExpectSameProvenance(got_object.object().provenance(), lab);
  pb::ListObjectsResponse objects;
  GRPC_ASSERT_OK(stubs.objects->ListObjects(Context().get(), pb::ListObjectsRequest(), &objects));
  ASSERT_EQ(objects.objects_size(), 2);
  ExpectSameProvenance(objects.objects(1).provenance(), lab);

  pb::CreateJobRequest create;
  *create.mutable_spec() = UniformLevel0Spec(setup.object_id, /*budget=*/2);
  *create.mutable_provenance() = lab;
  pb::CreateJobResponse created;
  GRPC_ASSERT_OK(stubs.jobs->CreateJob(Context().get(), create, &created));
  ExpectSameProvenance(created.job().provenance(), lab);
  ITEST_ASSERT_OK_AND_ASSIGN(job, GetJob(stubs, created.job().job_id()));
  ExpectSameProvenance(job.provenance(), lab);
  pb::ListJobsResponse jobs;
  GRPC_ASSERT_OK(stubs.jobs->ListJobs(Context().get(), pb::ListJobsRequest(), &jobs));
  ASSERT_EQ(jobs.jobs_size(), 1);
  ExpectSameProvenance(jobs.jobs(0).provenance(), lab);

  // A rig's trace with provenance: kept with the sample.
  ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(stubs, created.job().job_id(), "rig-a"));
  ITEST_ASSERT_OK_AND_ASSIGN(submit, ExecuteOnRig(*setup.rig, command, "rig-a"));
  *submit.mutable_provenance() = LabProvenance("rig operator");
  pb::SubmitTraceResponse submitted;
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), submit, &submitted));
  ExpectSameProvenance(submitted.sample().provenance(), LabProvenance("rig operator"));
  EXPECT_FALSE(submitted.sample().has_import());
  pb::GetSampleRequest get_sample;
  get_sample.set_trace_id(submitted.sample().trace_id());
  pb::GetSampleResponse got_sample;
  GRPC_ASSERT_OK(stubs.maps->GetSample(Context().get(), get_sample, &got_sample));
  ExpectSameProvenance(got_sample.sample().provenance(), LabProvenance("rig operator"));
  // A retry of the same trace with other provenance: acknowledged as already
  // stored, and the answer shows what was stored (the first provenance), not
  // what the retry sent.
  *submit.mutable_provenance() = LabProvenance("someone else");
  pb::SubmitTraceResponse retried;
  GRPC_ASSERT_OK(stubs.probe->SubmitTrace(Context().get(), submit, &retried));
  EXPECT_TRUE(retried.already_accepted());
  ExpectSameProvenance(retried.sample().provenance(), LabProvenance("rig operator"));

  // Out of bounds: named, nothing created.
  pb::CreateJobRequest bad = create;
  for (int i = 0; i < 33; ++i) (*bad.mutable_provenance()->mutable_extra())["key" + std::to_string(i)] = "v";
  ASSERT_EQ(bad.provenance().extra_size(), 34);  // and humidity_pct
  pb::CreateJobResponse refused;
  grpc::Status status = stubs.jobs->CreateJob(Context().get(), bad, &refused);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_NE(status.error_message().find("provenance extra: 34 keys; the limit is 32"), std::string::npos)
      << status.error_message();
}

}  // namespace
}  // namespace surfmap::itest

namespace surfmap::itest {
namespace {

// GetMap's regions name the drag pieces behind their estimates: every piece
// of every drag, leased or imported, once in its region (or as the parts the
// map cut it into), with the trace it came from, and the weights that make
// the region's mu.
TEST(MapRegions, EachNamesTheDragPiecesBehindItsMuLeasedAndImportedAlike) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  pb::JobSpec spec;
  spec.set_object_id(setup.object_id);
  spec.set_property(pb::PROPERTY_FRICTION);
  ITEST_ASSERT_OK_AND_ASSIGN(job, CreateJob(*setup.stubs, spec));
  for (int i = 0; i < 24; ++i) {
    ITEST_ASSERT_OK_AND_ASSIGN(command, LeaseOne(*setup.stubs, job.job_id(), "rig-a"));
    ITEST_ASSERT_OK_AND_ASSIGN(request, ExecuteOnRig(*setup.rig, command, "rig-a"));
    pb::SubmitTraceResponse response;
    GRPC_ASSERT_OK(setup.stubs->probe->SubmitTrace(Context().get(), request, &response));
  }
  // Two hand drags: one inside the masonite square, one across the plate.
  ITEST_ASSERT_OK_AND_ASSIGN(
      first, Import(*setup.stubs, job.job_id(), RigDragCsv(*setup.rig, {31, 0, 0}, {0, 1, 0}, 4242), "a.csv", {}));
  ITEST_ASSERT_OK_AND_ASSIGN(
      second, Import(*setup.stubs, job.job_id(), RigDragCsv(*setup.rig, {-20, 20, 0}, {1, 0, 0}, 78), "b.csv", {}));

  ITEST_ASSERT_OK_AND_ASSIGN(map, GetMap(*setup.stubs, job.job_id(), -1, false));
  std::map<int64_t, const pb::Sample*> samples;
  for (const pb::Sample& s : map.map().samples()) samples[s.trace_id()] = &s;
  ASSERT_EQ(samples.size(), 26u);
  ASSERT_GE(map.map().regions_size(), 2);
  std::set<std::pair<int64_t, int>> seen;  // (trace, fit piece)
  std::map<int, double> weight_of_material, mu_of_material;
  for (const pb::MapRegion& region : map.map().regions()) {
    ASSERT_EQ(region.pieces_size(), region.piece_count()) << "region " << region.region();
    for (const pb::MapRegionPiece& p : region.pieces()) {
      ASSERT_TRUE(samples.count(p.trace_id())) << "region " << region.region() << ": trace " << p.trace_id();
      const pb::Fit& fit = samples.at(p.trace_id())->fit();
      ASSERT_GE(p.fit_piece(), 0);
      ASSERT_LT(p.fit_piece(), fit.pieces_size()) << "trace " << p.trace_id();
      const pb::DragPiece& of_fit = fit.pieces(p.fit_piece());
      seen.insert({p.trace_id(), p.fit_piece()});
      if (p.split_by_map()) {
        EXPECT_GE(p.start_mm(), of_fit.start_mm() - 1e-9);
        EXPECT_LE(p.end_mm(), of_fit.end_mm() + 1e-9);
      } else {
        // The fit's piece as stored: the map reads the same numbers.
        EXPECT_NEAR(p.start_mm(), of_fit.start_mm(), 1e-9);
        EXPECT_NEAR(p.end_mm(), of_fit.end_mm(), 1e-9);
        EXPECT_NEAR(p.mu(), of_fit.mu(), 1e-9);
        EXPECT_GE(p.mu_se(), of_fit.mu_se() - 1e-12) << "the map only widens a piece's error";
      }
      EXPECT_EQ(p.in_mu(), p.mu_weight() > 0.0);
      weight_of_material[region.material()] += p.mu_weight();
      mu_of_material[region.material()] += p.mu_weight() * p.mu();
    }
  }
  // Every piece of every drag is in the map, imports included.
  for (const auto& [trace, sample] : samples) {
    for (int k = 0; k < sample->fit().pieces_size(); ++k) EXPECT_TRUE(seen.count({trace, k})) << trace << " " << k;
  }
  EXPECT_TRUE(seen.count({first.sample().trace_id(), 0}));
  EXPECT_TRUE(seen.count({second.sample().trace_id(), 0}));
  // A material's weights sum to one over its regions, and weigh its pieces to its mu.
  for (const pb::MapRegion& region : map.map().regions()) {
    EXPECT_NEAR(weight_of_material.at(region.material()), 1.0, 1e-9) << "region " << region.region();
    EXPECT_NEAR(mu_of_material.at(region.material()), region.mu(), 1e-9) << "region " << region.region();
  }
}

}  // namespace
}  // namespace surfmap::itest
