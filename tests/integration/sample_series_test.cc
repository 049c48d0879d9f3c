// GetSample with include_series: the per-pair mu along the data window and
// the ACF, recomputed from the stored trace with the fit's own options, for
// the fit on arrival and for a refit with another grid step.
#include <sqlite3.h>

#include <cmath>
#include <numeric>
#include <string>

#include "gtest/gtest.h"
#include "tests/support/job_helpers.h"
#include "tests/support/rig_fleet.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

absl::StatusOr<pb::Sample> GetSample(Stubs& stubs, int64_t trace_id, int32_t version, bool series) {
  pb::GetSampleRequest request;
  request.set_trace_id(trace_id);
  request.set_fit_version(version);
  request.set_include_series(series);
  pb::GetSampleResponse response;
  grpc::Status status = stubs.maps->GetSample(Context().get(), request, &response);
  if (!status.ok()) return FromGrpc(status, "GetSample");
  return response.sample();
}

// A plate job of `budget` level-0 sites measured by one rig; its samples.
absl::StatusOr<pb::ListSamplesResponse> MeasurePlate(SceneServer& setup, int budget, int64_t* job_id) {
  absl::StatusOr<pb::JobInfo> job = CreateJob(*setup.stubs, UniformLevel0Spec(setup.object_id, budget));
  if (!job.ok()) return job.status();
  *job_id = job->job_id();
  RigFleetOptions fleet_options;
  fleet_options.rigs = 1;
  fleet_options.job_id = job->job_id();
  RigFleetRecord record = RigFleet(setup.server->address(), *setup.rig, fleet_options).Run();
  if (!record.rpc_errors.empty()) return absl::InternalError("rig: " + record.rpc_errors.front());
  return ListSamples(*setup.stubs, job->job_id());
}

TEST(SampleSeries, PerPairMuAndAcfBelongToTheStoredFit) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  Stubs& stubs = *setup.stubs;
  int64_t job_id = 0;
  ITEST_ASSERT_OK_AND_ASSIGN(samples, MeasurePlate(setup, /*budget=*/3, &job_id));
  ASSERT_EQ(samples.samples_size(), 3);
  const pb::Sample& listed = samples.samples(0);
  EXPECT_EQ(listed.fit().friction().pair_mu_size(), 0) << "lists carry no series";
  EXPECT_EQ(listed.fit().roughness().acf_size(), 0);

  ITEST_ASSERT_OK_AND_ASSIGN(plain, GetSample(stubs, listed.trace_id(), 0, false));
  EXPECT_EQ(plain.fit().friction().pair_mu_size(), 0);

  ITEST_ASSERT_OK_AND_ASSIGN(detailed, GetSample(stubs, listed.trace_id(), 0, true));
  const pb::FrictionEstimate& f = detailed.fit().friction();
  ASSERT_EQ(f.pair_mu_size(), f.pair_count());
  ASSERT_EQ(f.pair_s_mm_size(), f.pair_count());
  ASSERT_GT(f.pair_count(), 50);
  // The summary is the mean of the per-pair values, inside the window.
  const double mean = std::accumulate(f.pair_mu().begin(), f.pair_mu().end(), 0.0) / f.pair_count();
  EXPECT_NEAR(mean, f.mu(), 1e-12);
  EXPECT_EQ(f.mu(), listed.fit().friction().mu()) << "the same fit as stored";
  for (double s : f.pair_s_mm()) {
    EXPECT_GE(s, f.window_start_mm() - 1e-9);
    EXPECT_LE(s, f.window_end_mm() + 1e-9);
  }
  const pb::RoughnessEstimate& r = detailed.fit().roughness();
  ASSERT_GT(r.acf_size(), 10);
  EXPECT_DOUBLE_EQ(r.acf(0), 1.0);
  for (double a : r.acf()) EXPECT_LE(std::abs(a), 1.0 + 1e-12);
  EXPECT_DOUBLE_EQ(r.grid_step_mm(), 0.1);

  // A refit on a 0.2 mm grid: version 2's series are on that grid.
  pb::RefitJobRequest refit;
  refit.set_job_id(job_id);
  refit.mutable_settings()->set_step_mm(0.2);
  refit.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
  pb::RefitJobResponse refitted;
  GRPC_ASSERT_OK(stubs.traces->RefitJob(Context().get(), refit, &refitted));
  ASSERT_EQ(refitted.fit_version(), 2);
  ITEST_ASSERT_OK_AND_ASSIGN(v2, GetSample(stubs, listed.trace_id(), 2, true));
  EXPECT_EQ(v2.fit().version(), 2);
  EXPECT_DOUBLE_EQ(v2.fit().roughness().grid_step_mm(), 0.2);
  EXPECT_LT(v2.fit().roughness().acf_size(), r.acf_size()) << "half as many grid points, fewer lags";
  ITEST_ASSERT_OK_AND_ASSIGN(v1, GetSample(stubs, listed.trace_id(), 1, true));
  EXPECT_DOUBLE_EQ(v1.fit().roughness().grid_step_mm(), 0.1) << "the old version keeps its own options";
}

// Another connection to the server's database, as an operator's tool would
// have: the server's WAL lets it write while the server runs.
void ExecOnDatabase(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  sqlite3_busy_timeout(db, 10000);
  char* error = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error);
  EXPECT_EQ(rc, SQLITE_OK) << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close_v2(db);
}

TEST(SampleSeries, AStoredFitThatCannotBeReadIsDataLossNotAnEmptySample) {
  ITEST_ASSERT_OK_AND_ASSIGN(setup, StartServerWithScene("plate"));
  Stubs& stubs = *setup.stubs;
  int64_t job_id = 0;
  ITEST_ASSERT_OK_AND_ASSIGN(samples, MeasurePlate(setup, /*budget=*/2, &job_id));
  ASSERT_EQ(samples.samples_size(), 2);
  const int64_t broken = samples.samples(1).trace_id();
  // Valid JSON (the schema checks that), but not a fit: mu is text.
  ExecOnDatabase(setup.server->db_path(),
                 "UPDATE fits SET result_json = '{\"mu\": \"abc\"}' WHERE trace_id = " + std::to_string(broken));

  absl::StatusOr<pb::Sample> sample = GetSample(stubs, broken, 0, false);
  ASSERT_FALSE(sample.ok()) << "answered a sample with no estimates";
  EXPECT_EQ(sample.status().code(), absl::StatusCode::kDataLoss) << sample.status();
  EXPECT_NE(sample.status().message().find("trace " + std::to_string(broken)), std::string::npos)
      << sample.status();
  absl::StatusOr<pb::ListSamplesResponse> listed = ListSamples(stubs, job_id);
  ASSERT_FALSE(listed.ok());
  EXPECT_EQ(listed.status().code(), absl::StatusCode::kDataLoss) << listed.status();
  // A watch that asked for the map ends with the reason rather than sending
  // an update without it.
  pb::WatchJobRequest watch;
  watch.set_job_id(job_id);
  watch.set_include_map(true);
  auto context = Context(30);
  auto reader = stubs.jobs->WatchJob(context.get(), watch);
  pb::JobUpdate update;
  EXPECT_FALSE(reader->Read(&update)) << "an update was sent";
  const grpc::Status watch_status = reader->Finish();
  EXPECT_EQ(watch_status.error_code(), grpc::StatusCode::DATA_LOSS) << watch_status.error_message();
  // The intact trace still reads.
  ITEST_EXPECT_OK(GetSample(stubs, samples.samples(0).trace_id(), 0, false).status());
}

}  // namespace
}  // namespace surfmap::itest
