// Importing drags recorded elsewhere into a job, through the coordinator over
// a real SQLite store: the drag joins the plan's map pieces (not its measured
// sites), keeps its provenance, survives a restart, is stored once per file,
// and a drag off the surface is refused and kept naming its source.
#include "server/jobs/trace_import.h"

#include <chrono>
#include <thread>

#include <nlohmann/json.hpp>

#include "gtest/gtest.h"
#include "server/base/testing/status_matchers.h"
#include "server/estimate/trace_csv.h"
#include "server/jobs/coordinator_fixture_for_test.h"

namespace surfmap::testing {
namespace {

using ::surfmap::status_matchers::IsOk;
using ::surfmap::status_matchers::StatusIs;

class TraceImportTest : public CoordinatorFixture {
 protected:
  // A seeded glass drag on the plate (z = 0, normal +z) as trace CSV, `lift` mm above it.
  static std::string PlateDragCsv(const Eigen::Vector3d& start, const Eigen::Vector3d& direction, uint64_t seed,
                                  double lift = 0.0) {
    DragGeometry geometry = PlaneGeometry(start, direction, Eigen::Vector3d::UnitZ(), 20.0);
    DragSimOptions options;
    options.seed = seed;
    absl::StatusOr<DragSimResult> result = SimulateDrag(geometry, UniformMaterial(kGlass), options);
    EXPECT_TRUE(result.ok()) << result.status();
    for (DragSample& s : result->trace.samples) s.position.z() += lift;
    return "# recorded by hand\n" + FormatTraceCsv(result->trace);
  }

  absl::StatusOr<TraceImportOutcome> Import(int64_t job_id, const std::string& csv, const std::string& file_name,
                                            const Provenance& provenance = {}) {
    TraceImportRequest request;
    request.job_id = job_id;
    request.source = "hand-rig";
    request.file_name = file_name;
    request.recorded_unix_ms = 1'790'000'000'000;
    request.provenance = provenance;
    Awaited<absl::StatusOr<TraceImportOutcome>> answer;
    coordinator_->imports().Import(request, std::make_shared<const std::string>(csv), 1'000'000, answer.Callback());
    std::optional<absl::StatusOr<TraceImportOutcome>> got = answer.Get("ImportTrace");
    if (!got) return absl::DeadlineExceededError("ImportTrace timed out");
    return *got;
  }

  // Starts an import; the answer comes in `answer`.
  void StartImport(int64_t job_id, const std::string& csv, const std::string& file_name,
                   Awaited<absl::StatusOr<TraceImportOutcome>>& answer) {
    TraceImportRequest request;
    request.job_id = job_id;
    request.source = "hand-rig";
    request.file_name = file_name;
    coordinator_->imports().Import(request, std::make_shared<const std::string>(csv), 1'000'000, answer.Callback());
  }

  // The plan's pieces of imported drags (drag ids past every vertex of the plan's finest level) and its measured
  // sites.
  std::pair<int, int> ImportedPiecesAndMeasured(int64_t job_id) {
    absl::StatusOr<std::shared_ptr<JobRuntime>> runtime = coordinator_->registry().Get(job_id);
    EXPECT_TRUE(runtime.ok()) << runtime.status();
    const int vertices = static_cast<int>(
        JobPlanLevels(*(*runtime)->surface, (*runtime)->params).back()->limit_positions.size());
    MutexLock lock(&(*runtime)->mu);
    int imported = 0;
    for (const MapPiece& p : (*runtime)->plan.MeasuredPieces()) imported += p.drag >= vertices;
    return {imported, (*runtime)->plan.Progress().measured};
  }
};

TEST_F(TraceImportTest, AnImportedDragJoinsTheMapWithItsProvenanceAndSurvivesARestart) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  Provenance provenance;
  provenance.operator_name = "A. Lloyd";
  provenance.specimen = "plate #3";
  provenance.extra["humidity_pct"] = "41";
  absl::StatusOr<TraceImportOutcome> imported =
      Import(job.record.id, PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3), "hand_01.csv", provenance);
  ASSERT_THAT(imported.status(), IsOk());
  EXPECT_FALSE(imported->already_imported);
  EXPECT_EQ(imported->command.lease_owner, "hand-rig");
  EXPECT_NEAR(imported->probe.position.x(), -20.0, 0.5);
  EXPECT_NEAR(imported->probe.position.y(), 10.0, 0.5);
  EXPECT_NEAR(*imported->fit.mu, kGlass.mu, 0.03);
  auto [pieces, measured] = ImportedPiecesAndMeasured(job.record.id);
  EXPECT_GE(pieces, 1);
  EXPECT_EQ(measured, 0);  // an import marks no planned site measured

  // A sample like any other, with where it came from and who made it.
  absl::StatusOr<std::vector<SampleRecord>> samples = coordinator_->reads().ListSamples(job.record.id, 0);
  ASSERT_THAT(samples.status(), IsOk());
  ASSERT_EQ(samples->size(), 1u);
  const SampleRecord& s = samples->front();
  EXPECT_EQ(s.trace.id, imported->trace_id);
  EXPECT_EQ(s.command.state, CommandState::kDone);
  EXPECT_EQ(s.trace.import_sha256, Sha256Hex(PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3)));
  const nlohmann::json meta = nlohmann::json::parse(s.trace.metadata_json);
  EXPECT_EQ(meta["import"]["file_name"], "hand_01.csv");
  EXPECT_EQ(meta["import"]["source"], "hand-rig");
  EXPECT_EQ(meta["import"]["recorded_unix_ms"], 1'790'000'000'000);
  absl::StatusOr<Provenance> stored = ProvenanceOfMetadata(s.trace.metadata_json);
  ASSERT_THAT(stored.status(), IsOk());
  EXPECT_EQ(*stored, provenance);
  // The map is built from the import.
  absl::StatusOr<MapSnapshot> map = coordinator_->Map(job.record.id);
  ASSERT_THAT(map.status(), IsOk());
  EXPECT_NE(map->map, nullptr);

  Reopen();  // the plan's journal carries the import
  auto [pieces_after, measured_after] = ImportedPiecesAndMeasured(job.record.id);
  EXPECT_EQ(pieces_after, pieces);
  EXPECT_EQ(measured_after, 0);
  // And a checkpoint carries it too: measuring the rest of the plan writes one at completion.
  EXPECT_GT(MeasureUntilDone(job.record.id, "rig-1"), 0);
  Reopen();
  EXPECT_EQ(ImportedPiecesAndMeasured(job.record.id).first, pieces);
}

TEST_F(TraceImportTest, TheSameFileTwiceIsStoredOnce) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  const std::string csv = PlateDragCsv({0, -30, 0}, {0, 1, 0}, 5);
  absl::StatusOr<TraceImportOutcome> first = Import(job.record.id, csv, "a.csv");
  ASSERT_THAT(first.status(), IsOk());
  const int pieces = ImportedPiecesAndMeasured(job.record.id).first;
  absl::StatusOr<TraceImportOutcome> again = Import(job.record.id, csv, "renamed.csv");
  ASSERT_THAT(again.status(), IsOk());
  EXPECT_TRUE(again->already_imported);
  EXPECT_EQ(again->trace_id, first->trace_id);
  EXPECT_EQ(again->fit.id, first->fit.id);
  EXPECT_EQ(ImportedPiecesAndMeasured(job.record.id).first, pieces);  // the plan did not take it twice
  absl::StatusOr<std::vector<SampleRecord>> samples = coordinator_->reads().ListSamples(job.record.id, 0);
  ASSERT_THAT(samples.status(), IsOk());
  EXPECT_EQ(samples->size(), 1u);
  // Another file is another drag.
  absl::StatusOr<TraceImportOutcome> other = Import(job.record.id, PlateDragCsv({0, -30, 0}, {0, 1, 0}, 6), "b.csv");
  ASSERT_THAT(other.status(), IsOk());
  EXPECT_NE(other->trace_id, first->trace_id);
}

TEST_F(TraceImportTest, ADragOffTheSurfaceIsRefusedAndKeptNamingItsSource) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  absl::StatusOr<TraceImportOutcome> refused =
      Import(job.record.id, PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3, /*lift=*/15.0), "lifted.csv");
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(refused.status().message().find("implausible trace: surface"), std::string_view::npos) << refused.status();
  EXPECT_NE(refused.status().message().find("lifted.csv"), std::string_view::npos) << refused.status();
  absl::StatusOr<std::vector<RejectedTraceRecord>> rejected = coordinator_->reads().ListRejectedTraces(job.record.id);
  ASSERT_THAT(rejected.status(), IsOk());
  ASSERT_EQ(rejected->size(), 1u);
  EXPECT_EQ(rejected->front().rig_id, "hand-rig");
  EXPECT_EQ(rejected->front().check_name, "surface");
  EXPECT_GT(rejected->front().command_id, 0);
  EXPECT_EQ(rejected->front().import_sha256, Sha256Hex(PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3, 15.0)));
  EXPECT_EQ(ImportedPiecesAndMeasured(job.record.id).first, 0);
  absl::StatusOr<std::vector<SampleRecord>> samples = coordinator_->reads().ListSamples(job.record.id, 0);
  ASSERT_THAT(samples.status(), IsOk());
  EXPECT_TRUE(samples->empty());
  // The same refused file again: the same refusal, nothing more kept.
  absl::StatusOr<TraceImportOutcome> again =
      Import(job.record.id, PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3, /*lift=*/15.0), "lifted_again.csv");
  EXPECT_THAT(again.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  rejected = coordinator_->reads().ListRejectedTraces(job.record.id);
  ASSERT_THAT(rejected.status(), IsOk());
  EXPECT_EQ(rejected->size(), 1u);
}

// A file too short to be a drag, whatever else is wrong with it, is refused
// as malformed and not kept: the cheap command checks run before the
// surface-distance check (which would have kept it as "surface").
// The same file imported twice at once: the second is refused UNAVAILABLE
// before it changes the plan, so memory never runs ahead of the database and
// a write queued behind both (another file) is stored, not failed by a reload.
TEST_F(TraceImportTest, TheSameFileTwiceAtOnceIsRefusedWhileTheFirstIsStored) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  const std::string csv = PlateDragCsv({0, -30, 0}, {0, 1, 0}, 5);
  const int64_t held = faults_->writes_submitted() + 1;
  faults_->HoldWrite(held);
  Awaited<absl::StatusOr<TraceImportOutcome>> first, second, other;
  StartImport(job.record.id, csv, "a.csv", first);
  ASSERT_TRUE(faults_->WaitUntilHeld(held, absl::Seconds(10)));
  StartImport(job.record.id, csv, "a_again.csv", second);
  std::optional<absl::StatusOr<TraceImportOutcome>> second_answer = second.Get("second import");
  ASSERT_TRUE(second_answer.has_value());
  EXPECT_THAT(second_answer->status(), StatusIs(absl::StatusCode::kUnavailable));
  EXPECT_NE(second_answer->status().message().find("being stored; retry"), std::string_view::npos)
      << second_answer->status();
  StartImport(job.record.id, PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3), "b.csv", other);  // queued behind
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  faults_->ReleaseWrite(held);
  std::optional<absl::StatusOr<TraceImportOutcome>> first_answer = first.Get("first import");
  std::optional<absl::StatusOr<TraceImportOutcome>> other_answer = other.Get("other import");
  ASSERT_TRUE(first_answer.has_value() && other_answer.has_value());
  ASSERT_THAT(first_answer->status(), IsOk());
  EXPECT_FALSE((*first_answer)->already_imported);
  ASSERT_THAT(other_answer->status(), IsOk());
  EXPECT_FALSE((*other_answer)->already_imported);
  // Once durable, the same file answers the stored import.
  absl::StatusOr<TraceImportOutcome> retried = Import(job.record.id, csv, "a_again.csv");
  ASSERT_THAT(retried.status(), IsOk());
  EXPECT_TRUE(retried->already_imported);
  EXPECT_EQ(retried->trace_id, (*first_answer)->trace_id);
  // Memory matches the database: two imported drags, after a reload too.
  const int pieces = ImportedPiecesAndMeasured(job.record.id).first;
  Reopen();
  EXPECT_EQ(ImportedPiecesAndMeasured(job.record.id).first, pieces);
  absl::StatusOr<std::vector<SampleRecord>> samples = coordinator_->reads().ListSamples(job.record.id, 0);
  ASSERT_THAT(samples.status(), IsOk());
  EXPECT_EQ(samples->size(), 2u);
}

TEST_F(TraceImportTest, AnImportWaitsOutTheJobsReReadInsteadOfBeingToldToRetry) {
  // A rig's trace refused by the store (its lease taken over) sends the job
  // to be re-read. An import is an operator's call, like a cancel: it is
  // stored once the job is re-read, not answered UNAVAILABLE.
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  const int64_t reread_barrier = HoldJobInReRead(job.record.id);
  ASSERT_NE(reread_barrier, 0);

  Awaited<absl::StatusOr<TraceImportOutcome>> imported;
  StartImport(job.record.id, PlateDragCsv({0, -30, 0}, {0, 1, 0}, 5), "during_reread.csv", imported);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  EXPECT_FALSE(imported.Ready()) << "answered while the job was still waiting to be re-read";

  faults_->ReleaseWrite(reread_barrier);
  std::optional<absl::StatusOr<TraceImportOutcome>> answer = imported.Get("import behind the re-read");
  ASSERT_TRUE(answer.has_value());
  ASSERT_THAT(answer->status(), IsOk());
  EXPECT_FALSE((*answer)->already_imported);
  // In memory and in the database: the import, and not the refused trace.
  EXPECT_EQ(ImportedPiecesAndMeasured(job.record.id), std::make_pair(1, 0));
  Reopen();
  EXPECT_EQ(ImportedPiecesAndMeasured(job.record.id), std::make_pair(1, 0));
}

TEST_F(TraceImportTest, ATwoSampleFileAboveTheSurfaceIsMalformedNotKept) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  const std::string csv = "t,x,y,z,fx,fy,fz,phase\n0,-10,0,15,1,0,5,fwd\n1,10,0,15,-1,0,5,rev\n";
  absl::StatusOr<TraceImportOutcome> refused = Import(job.record.id, csv, "two.csv");
  EXPECT_THAT(refused.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(refused.status().message().find("malformed trace"), std::string_view::npos) << refused.status();
  absl::StatusOr<std::vector<RejectedTraceRecord>> rejected = coordinator_->reads().ListRejectedTraces(job.record.id);
  ASSERT_THAT(rejected.status(), IsOk());
  EXPECT_TRUE(rejected->empty());
}

TEST_F(TraceImportTest, AFinishedJobTakesNoImportRefusedOrNot) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  ASSERT_THAT(SetState(job.record.id, JobState::kCancelled).status(), IsOk());
  // A good drag and one off the surface get the same answer, and nothing is
  // kept in the cancelled job.
  EXPECT_THAT(Import(job.record.id, PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 3), "good.csv").status(),
              StatusIs(absl::StatusCode::kFailedPrecondition));
  absl::StatusOr<TraceImportOutcome> lifted =
      Import(job.record.id, PlateDragCsv({-30, 10, 0}, {1, 0, 0}, 4, /*lift=*/15.0), "lifted.csv");
  EXPECT_THAT(lifted.status(), StatusIs(absl::StatusCode::kFailedPrecondition));
  EXPECT_NE(lifted.status().message().find("cancelled: it takes no more traces"), std::string_view::npos)
      << lifted.status();
  absl::StatusOr<std::vector<RejectedTraceRecord>> rejected = coordinator_->reads().ListRejectedTraces(job.record.id);
  ASSERT_THAT(rejected.status(), IsOk());
  EXPECT_TRUE(rejected->empty());
}

TEST_F(TraceImportTest, BadRequestsAreRefusedNamingTheField) {
  const int64_t object = UploadPlate();
  const JobSnapshot job = CreateUniformJob(object);
  Provenance too_many;
  for (int i = 0; i < 40; ++i) too_many.extra[absl::StrCat("k", i)] = "v";
  EXPECT_THAT(Import(job.record.id, PlateDragCsv({0, 0, 0}, {1, 0, 0}, 1), "x.csv", too_many).status(),
              StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_THAT(Import(job.record.id, "t,x,y,z,fx,fy,fz,phase\n0,0,0,0,0,0,5,fwd\n", "short.csv").status(),
              StatusIs(absl::StatusCode::kInvalidArgument));
  absl::StatusOr<TraceImportOutcome> not_csv = Import(job.record.id, "hello\n", "hello.csv");
  EXPECT_THAT(not_csv.status(), StatusIs(absl::StatusCode::kInvalidArgument));
  EXPECT_NE(not_csv.status().message().find("hello.csv:1:"), std::string_view::npos) << not_csv.status();
  EXPECT_THAT(Import(job.record.id + 100, PlateDragCsv({0, 0, 0}, {1, 0, 0}, 1), "x.csv").status(),
              StatusIs(absl::StatusCode::kNotFound));
  // More lines than a trace may have: refused before the reader allocates.
  std::string huge = "t,x,y,z,fx,fy,fz,phase\n";
  for (int i = 0; i < 300; ++i) huge += "0,0,0,0,0,0,5,fwd\n";
  TraceImportRequest request;
  request.job_id = job.record.id;
  request.source = "hand-rig";
  Awaited<absl::StatusOr<TraceImportOutcome>> answer;
  coordinator_->imports().Import(request, std::make_shared<const std::string>(huge), 100, answer.Callback());
  std::optional<absl::StatusOr<TraceImportOutcome>> got = answer.Get("ImportTrace");
  ASSERT_TRUE(got.has_value());
  EXPECT_THAT(got->status(), StatusIs(absl::StatusCode::kResourceExhausted));
}

// The size bound counts the lines the reader reads: blank ones (which it
// skips) do not count, so a double-spaced file of max_samples rows passes and
// one row more is still refused.
TEST(CheckCsvSizeTest, BlankLinesDoNotCount) {
  std::string spaced = "t,x,y,z,fx,fy,fz,phase\n\n";
  for (int i = 0; i < 100 + 100; ++i) spaced += "0,0,0,0,0,0,5,fwd\r\n \t\n";  // 200 rows: max + the 100 comment lines
  EXPECT_THAT(CheckCsvSize(spaced, 100), IsOk());
  spaced += "0,0,0,0,0,0,5,fwd\n\n";
  EXPECT_THAT(CheckCsvSize(spaced, 100), StatusIs(absl::StatusCode::kResourceExhausted));
  EXPECT_THAT(CheckCsvSize("", 0), IsOk());
  EXPECT_THAT(CheckCsvSize("a\nb", 0), IsOk());  // header + one comment-sized line, no final newline
}

}  // namespace
}  // namespace surfmap::testing
