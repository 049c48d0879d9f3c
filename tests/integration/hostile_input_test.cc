// Issue 12's acceptance table: hostile and unlucky requests through the real
// surfmapd (127.0.0.1, a real SQLite file, default limits). Every row must
// come back with its status code and a message that names the problem, leave
// the measurement tables unchanged (objects, jobs, commands and their states,
// traces, fits, sites; a refused implausible trace may only add its kept copy
// and an event), and the server's peak RSS (VmHWM) must stay under 1 GB over
// the whole table. Each row was found crashing, exhausting memory, entering
// the map or answering with an internal message before the hardening.
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include <sqlite3.h>

#include <Eigen/Geometry>
#include <grpcpp/generic/generic_stub.h>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "clients/remote/remote_call.h"
#include "gtest/gtest.h"
#include "tests/support/db_snapshot.h"
#include "tests/support/job_helpers.h"
#include "tests/support/server_process.h"
#include "tests/support/status_matchers.h"

namespace surfmap::itest {
namespace {

using C = grpc::StatusCode;
constexpr int64_t kMaxRssBytes = int64_t{1} << 30;

// Tables a refused request must not touch. A refused implausible trace is
// kept for the operator (rejected_traces, at most 3 per command) and leaves
// an event: those two tables may grow, by design, and are checked apart.
bool MayGrow(const std::string& table) { return table == "events" || table == "rejected_traces"; }

// Peak resident set of `pid` in bytes (VmHWM), or -1.
int64_t PeakRssBytes(pid_t pid) {
  std::ifstream status(absl::StrCat("/proc/", pid, "/status"));
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) != 0) continue;
    std::vector<std::string> parts = absl::StrSplit(line, ' ', absl::SkipEmpty());
    int64_t kb = 0;
    if (parts.size() >= 2 && absl::SimpleAtoi(parts[1], &kb)) return kb * 1024;
  }
  return -1;
}

// PRAGMA integrity_check on a read-only connection: "ok" or what it found.
std::string IntegrityCheck(const std::string& db_path) {
  sqlite3* db = nullptr;
  std::string result;
  if (sqlite3_open_v2(db_path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_busy_timeout(db, 10'000);
    sqlite3_stmt* stmt = nullptr;
    if (sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &stmt, nullptr) == SQLITE_OK) {
      while (sqlite3_step(stmt) == SQLITE_ROW) {
        absl::StrAppend(&result, result.empty() ? "" : "; ", reinterpret_cast<const char*>(sqlite3_column_text(stmt, 0)));
      }
      sqlite3_finalize(stmt);
    }
  }
  if (result.empty()) result = absl::StrCat("cannot check: ", db ? sqlite3_errmsg(db) : "no connection");
  sqlite3_close_v2(db);
  return result;
}

struct Row {
  std::string name;
  std::function<grpc::Status()> call;
  C code;
  std::vector<std::string> any_of;  // the message contains one of these (case-insensitive)
};

Eigen::Vector3d V(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }

// Applies `edit(position, force)` to every sample.
pb::TraceSamples EditSamples(pb::TraceSamples s, const std::function<void(Eigen::Vector3d&, Eigen::Vector3d&)>& edit) {
  for (int i = 0; i < s.t_size(); ++i) {
    Eigen::Vector3d p(s.x(i), s.y(i), s.z(i)), f(s.fx(i), s.fy(i), s.fz(i));
    edit(p, f);
    s.set_x(i, p.x());
    s.set_y(i, p.y());
    s.set_z(i, p.z());
    s.set_fx(i, f.x());
    s.set_fy(i, f.y());
    s.set_fz(i, f.z());
  }
  return s;
}

std::string RepeatUtf8(const std::string& character, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += character;
  return out;
}

// A valid closed mesh, for rows about the name.
const char kTetra[] = "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n";

// A flat regular polygon with `n` vertices as one OBJ face.
std::string PolygonObj(int n) {
  std::string obj;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    absl::StrAppend(&obj, "v ", 40 * std::cos(a), " ", 40 * std::sin(a), " 0\n");
  }
  obj += "f";
  for (int i = 1; i <= n; ++i) absl::StrAppend(&obj, " ", i);
  obj += "\n";
  return obj;
}

class HostileInputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ServerOptions options;
    options.extra_args = {"--log-level", "debug"};  // refusals are logged too: the log must stay one line each
    auto server = ServerProcess::Start(options);
    ASSERT_TRUE(server.ok()) << server.status();
    server_ = std::move(*server);
    stubs_ = std::make_unique<Stubs>(server_->channel());

    auto bottle = MakeSceneRig("bottle");
    ASSERT_TRUE(bottle.ok()) << bottle.status();
    bottle_ = std::move(*bottle);
    auto object = UploadSceneMesh(*stubs_, *bottle_);
    ASSERT_TRUE(object.ok()) << object.status();
    auto job = CreateJob(*stubs_, UniformLevel0Spec(object->object_id()));
    ASSERT_TRUE(job.ok()) << job.status();
    job_id_ = job->job_id();
    auto command = LeaseOne(*stubs_, job_id_, kRig);
    ASSERT_TRUE(command.ok()) << command.status();
    command_ = *command;
    auto good = ExecuteOnRig(*bottle_, command_, kRig);
    ASSERT_TRUE(good.ok()) << good.status();
    good_ = good->samples();

    // A plate, its job and one of its commands: its trace is "a trace of a
    // different object's site" when submitted for the bottle's command.
    auto plate = MakeSceneRig("plate");
    ASSERT_TRUE(plate.ok()) << plate.status();
    auto plate_object = UploadSceneMesh(*stubs_, **plate);
    ASSERT_TRUE(plate_object.ok()) << plate_object.status();
    auto plate_job = CreateJob(*stubs_, UniformLevel0Spec(plate_object->object_id()));
    ASSERT_TRUE(plate_job.ok()) << plate_job.status();
    auto plate_command = LeaseOne(*stubs_, plate_job->job_id(), kRig);
    ASSERT_TRUE(plate_command.ok()) << plate_command.status();
    auto plate_trace = ExecuteOnRig(**plate, *plate_command, kRig);
    ASSERT_TRUE(plate_trace.ok()) << plate_trace.status();
    plate_trace_ = plate_trace->samples();
  }

  grpc::Status Submit(const pb::TraceSamples& samples, const std::string& rig = kRig) {
    pb::SubmitTraceRequest request;
    request.set_command_id(command_.command_id());
    request.set_rig_id(rig);
    *request.mutable_samples() = samples;
    pb::SubmitTraceResponse response;
    return stubs_->probe->SubmitTrace(Context().get(), request, &response);
  }

  // A stream whose chunks carry `values` x values each and nothing else,
  // written until the server ends it (or `chunks` were sent).
  grpc::Status StreamHugeX(int values, int chunks) {
    auto context = Context(120);
    pb::SubmitTraceResponse response;
    std::unique_ptr<grpc::ClientWriter<pb::SubmitTraceChunk>> writer =
        stubs_->probe->SubmitTraceStream(context.get(), &response);
    pb::SubmitTraceChunk chunk;
    chunk.set_command_id(command_.command_id());
    chunk.set_rig_id(kRig);
    for (int i = 0; i < values; ++i) chunk.mutable_samples()->add_x(1.0 + i * 1e-6);
    for (int c = 0; c < chunks; ++c) {
      if (!writer->Write(chunk)) break;  // the server finished the call
    }
    writer->WritesDone();
    return writer->Finish();
  }

  grpc::Status Refit(double step_mm, int ar_order) {
    pb::RefitJobRequest r;
    r.set_job_id(job_id_);
    r.mutable_settings()->set_ar_method(pb::AR_METHOD_BURG);
    r.mutable_settings()->set_step_mm(step_mm);
    r.mutable_settings()->set_ar_order(ar_order);
    pb::RefitJobResponse out;
    return stubs_->traces->RefitJob(Context().get(), r, &out);
  }

  grpc::Status Upload(const std::string& name, const std::string& mesh) {
    pb::UploadObjectRequest r;
    r.set_name(name);
    r.set_format(pb::MESH_FORMAT_OBJ);
    r.set_mesh(mesh);
    pb::UploadObjectResponse out;
    return stubs_->objects->UploadObject(Context().get(), r, &out);
  }

  grpc::Status CreateWithLease(int64_t seconds, int32_t nanos) {
    pb::CreateJobRequest r;
    *r.mutable_spec() = UniformLevel0Spec(1);
    r.mutable_spec()->mutable_lease()->set_seconds(seconds);
    r.mutable_spec()->mutable_lease()->set_nanos(nanos);
    pb::CreateJobResponse out;
    return stubs_->jobs->CreateJob(Context().get(), r, &out);
  }

  grpc::Status Lease(const std::string& rig) {
    pb::LeaseCommandRequest r;
    r.set_rig_id(rig);
    r.set_job_id(job_id_);
    pb::LeaseCommandResponse out;
    return stubs_->probe->LeaseCommand(Context().get(), r, &out);
  }

  // Raw bytes to `method`, as a client with another proto (or none) would.
  grpc::Status RawCall(const std::string& method, const std::string& bytes) {
    grpc::GenericStub stub(server_->channel());
    grpc::Slice slice(bytes);
    grpc::ByteBuffer request(&slice, 1), response;
    auto context = Context();
    grpc::CompletionQueue queue;
    std::unique_ptr<grpc::GenericClientAsyncResponseReader> call =
        stub.PrepareUnaryCall(context.get(), method, request, &queue);
    call->StartCall();
    grpc::Status status;
    call->Finish(&response, &status, reinterpret_cast<void*>(1));
    void* tag = nullptr;
    bool ok = false;
    queue.Next(&tag, &ok);
    queue.Shutdown();
    while (queue.Next(&tag, &ok)) {
    }
    return status;
  }

  static constexpr char kRig[] = "rig-hostile";
  std::unique_ptr<ServerProcess> server_;
  std::unique_ptr<Stubs> stubs_;
  std::unique_ptr<SimulatedRig> bottle_;
  int64_t job_id_ = 0;
  pb::ProbeCommand command_;
  pb::TraceSamples good_;
  pb::TraceSamples plate_trace_;
};

TEST_F(HostileInputTest, EveryRowIsRefusedClearlyChangesNothingAndMemoryStaysBounded) {
  const Eigen::Vector3d site = V(command_.position()), normal = V(command_.normal()).normalized(),
                        drag = V(command_.drag_direction()).normalized();
  const std::vector<Row> rows = {
      // Traces that are physically not the answer to their command.
      {"SubmitTrace: positions x, y, z scaled by 1e6",
       [&] { return Submit(EditSamples(good_, [](Eigen::Vector3d& p, Eigen::Vector3d&) { p *= 1e6; })); },
       C::INVALID_ARGUMENT, {"implausible trace: offset"}},
      {"SubmitTrace: force sign inverted",
       [&] { return Submit(EditSamples(good_, [](Eigen::Vector3d&, Eigen::Vector3d& f) { f = -f; })); },
       C::INVALID_ARGUMENT, {"implausible trace"}},
      {"SubmitTrace: friction 20x the normal force",
       [&] {
         return Submit(EditSamples(good_, [&](Eigen::Vector3d&, Eigen::Vector3d& f) {
           const Eigen::Vector3d fn = f.dot(normal) * normal, ft = f - fn;
           if (ft.norm() > 1e-9) f = fn + ft.normalized() * 20.0 * fn.norm();
         }));
       },
       // Its pair normals are swamped by the tangential force: the normal
       // check (near the site), or the normal force along them, refuses it.
       C::INVALID_ARGUMENT, {"implausible trace: friction", "implausible trace: normal", "implausible trace: force"}},
      {"SubmitTrace: trace 150 mm from the commanded site",
       [&] {
         return Submit(EditSamples(good_, [&](Eigen::Vector3d& p, Eigen::Vector3d&) { p += 150.0 * normal; }));
       },
       C::INVALID_ARGUMENT, {"implausible trace: offset"}},
      {"SubmitTrace: a trace measured at another object's site (plate for a bottle command)",
       [&] { return Submit(plate_trace_); }, C::INVALID_ARGUMENT, {"implausible trace"}},
      {"SubmitTrace: a 2 km drag",
       [&] {
         return Submit(EditSamples(good_, [&](Eigen::Vector3d& p, Eigen::Vector3d&) {
           p += (1e5 - 1.0) * (p - site).dot(drag) * drag;  // 20 mm -> 2 km along the drag
         }));
       },
       C::INVALID_ARGUMENT, {"implausible trace: offset", "implausible trace: length"}},
      {"SubmitTrace: time scaled by 1e300",
       [&] {
         pb::TraceSamples s = good_;
         for (int i = 0; i < s.t_size(); ++i) s.set_t(i, s.t(i) * 1e300);
         return Submit(s);
       },
       C::INVALID_ARGUMENT, {"implausible trace: time"}},
      // Resources a request claims before it is looked at.
      {"SubmitTraceStream: 40 chunks of 500,000 x values with an empty t",
       [&] { return StreamHugeX(500'000, 40); }, C::RESOURCE_EXHAUSTED, {"column x would hold"}},
      {"SubmitTrace: 2,000,000 x values with an empty t",
       [&] {
         pb::TraceSamples s;
         for (int i = 0; i < 2'000'000; ++i) s.add_x(i);
         return Submit(s);
       },
       C::RESOURCE_EXHAUSTED, {"column 'x' has 2000000 values"}},
      {"RefitJob: step_mm 2e-8", [&] { return Refit(2e-8, 0); }, C::INVALID_ARGUMENT, {"step_mm must be in 0.001..10 mm"}},
      {"RefitJob: ar_order 50", [&] { return Refit(0, 50); }, C::INVALID_ARGUMENT, {"ar_order must be in 1..20"}},
      {"QueryMap: point (1e155, 0, 0)",
       [&] {
         pb::QueryMapRequest r;
         r.set_job_id(job_id_);
         r.add_points()->set_x(1e155);
         pb::QueryMapResponse out;
         return stubs_->maps->QueryMap(Context().get(), r, &out);
       },
       C::INVALID_ARGUMENT, {"points[0].x = 1e+155 mm is outside"}},
      {"UploadObject: one 1000-gon face", [&] { return Upload("disk", PolygonObj(1000)); }, C::INVALID_ARGUMENT,
       {"the limit is 255 vertices per polygon"}},
      // Durations: nanos outside 0..999,999,999 or against the seconds' sign.
      {"CreateJob: lease nanos 2^31-1", [&] { return CreateWithLease(1, 2147483647); }, C::INVALID_ARGUMENT,
       {"lease.nanos"}},
      {"CreateJob: lease nanos -1", [&] { return CreateWithLease(0, -1); }, C::INVALID_ARGUMENT, {"lease.nanos"}},
      {"CreateJob: lease seconds -5", [&] { return CreateWithLease(-5, 0); }, C::INVALID_ARGUMENT, {"lease must be"}},
      // Names: UTF-8, counted in characters, one line.
      {"UploadObject: name with a byte that is not UTF-8", [&] { return Upload("bottle\xff", kTetra); },
       C::INVALID_ARGUMENT, {"utf-8"}},
      {"UploadObject: name of 201 characters (603 bytes)", [&] { return Upload(RepeatUtf8("瓶", 201), kTetra); },
       C::INVALID_ARGUMENT, {"1..200 characters, got 201"}},
      {"UploadObject: name with a newline", [&] { return Upload("bottle\nFORGED rpc=CancelJob", kTetra); },
       C::INVALID_ARGUMENT, {"control character U+000A"}},
      {"LeaseCommand: rig_id with a newline", [&] { return Lease("rig\nFORGED auth refused"); }, C::INVALID_ARGUMENT,
       {"rig_id contains the control character"}},
      {"LeaseCommand: rig_id of 101 characters", [&] { return Lease(RepeatUtf8("é", 101)); }, C::INVALID_ARGUMENT,
       {"rig_id must have 1..100 characters, got 101"}},
      {"SubmitTrace: rig_id that is not UTF-8", [&] { return Submit(good_, "rig\xc0\xaf"); }, C::INVALID_ARGUMENT,
       {"utf-8"}},
      // Requests gRPC itself cannot hand to a handler.
      {"GetObject: bytes that are not a GetObjectRequest",
       [&] { return RawCall("/surfmap.v1.ObjectService/GetObject", std::string("\x0a\xff\xff\xff\xff\x0f", 6)); },
       C::INVALID_ARGUMENT, {"could not be parsed"}},
      {"a method the server does not have", [&] { return RawCall("/surfmap.v1.ObjectService/DropTables", ""); },
       C::UNIMPLEMENTED, {}},
  };

  int64_t peak = 0;
  for (const Row& row : rows) {
    SCOPED_TRACE(row.name);
    auto before = TakeDbSnapshot(server_->db_path());
    ASSERT_TRUE(before.ok()) << before.status();
    const grpc::Status status = row.call();
    const int64_t rss = PeakRssBytes(server_->pid());
    peak = std::max(peak, rss);
    std::cout << "  " << row.name << " -> " << Describe(status).substr(0, 200) << "  [VmHWM " << rss / (1 << 20)
              << " MiB]\n";
    EXPECT_EQ(status.error_code(), row.code) << "expected " << cli::StatusCodeName(row.code) << ", got " << Describe(status);
    EXPECT_TRUE(MessageNames(status.error_message(), row.any_of))
        << "the message should contain one of: " << absl::StrJoin(row.any_of, " | ") << "; got " << Describe(status);
    EXPECT_FALSE(status.error_code() == C::UNIMPLEMENTED && status.error_message().empty()) << "an empty UNIMPLEMENTED";
    auto after = TakeDbSnapshot(server_->db_path());
    ASSERT_TRUE(after.ok()) << after.status();
    for (const auto& [table, count] : before->row_counts) {
      const int64_t now = after->row_counts.count(table) ? after->row_counts.at(table) : -1;
      if (MayGrow(table)) {
        EXPECT_LE(count, now) << table;
        if (table == "rejected_traces") {
          EXPECT_LE(now, count + 1) << "one refused trace keeps at most one copy";
        }
      } else {
        EXPECT_EQ(count, now) << "table " << table << " changed: " << count << " -> " << now << " rows";
      }
    }
    EXPECT_EQ(before->command_and_job_states, after->command_and_job_states) << "command or job states changed";
    ASSERT_TRUE(server_->running());
  }
  EXPECT_EQ(IntegrityCheck(server_->db_path()), "ok");
  std::cout << "  peak RSS (VmHWM) over the table: " << peak / (1 << 20) << " MiB\n";
  EXPECT_GT(peak, 0) << "VmHWM could not be read";
  EXPECT_LT(peak, kMaxRssBytes) << "the server's peak RSS passed 1 GB";

  // The command survived every row: the rig's real trace is accepted.
  pb::SubmitTraceRequest request;
  request.set_command_id(command_.command_id());
  request.set_rig_id(kRig);
  *request.mutable_samples() = good_;
  pb::SubmitTraceResponse response;
  GRPC_EXPECT_OK(stubs_->probe->SubmitTrace(Context().get(), request, &response));
  EXPECT_GT(response.sample().trace_id(), 0);
  // Characters, not bytes: 200 three-byte characters is a valid name.
  GRPC_EXPECT_OK(Upload(RepeatUtf8("瓶", 200), kTetra));

  // No client text started a line of the log of its own.
  for (absl::string_view line : absl::StrSplit(server_->Log(), '\n')) {
    EXPECT_FALSE(absl::StartsWith(line, "FORGED")) << "forged log line: " << line;
  }
}

}  // namespace
}  // namespace surfmap::itest
