#include "tests/chaos/chaos_actors.h"

#include <chrono>
#include <optional>
#include <thread>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "server/codec/trace_samples_proto.h"
#include "tests/support/server_process.h"

namespace surfmap::chaos {
namespace {

using std::chrono::milliseconds;

int64_t NowMs() {
  return std::chrono::duration_cast<milliseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

int64_t ToMs(const google::protobuf::Timestamp& t) { return t.seconds() * 1000 + t.nanos() / 1'000'000; }

// Stubs on the current server, rebuilt when it moved (restarted).
class Connection {
 public:
  explicit Connection(const ActorEnv& env) : env_(env) {}
  itest::Stubs& stubs() {
    const std::string address = env_.server->Get();
    if (address != address_ || !stubs_) {
      address_ = address;
      stubs_ = std::make_unique<itest::Stubs>(itest::MakeChannel(address, /*own_subchannel=*/true));
    }
    return *stubs_;
  }

 private:
  const ActorEnv& env_;
  std::string address_;
  std::unique_ptr<itest::Stubs> stubs_;
};

bool IsNeverAcceptable(grpc::StatusCode code) {
  return code == grpc::StatusCode::INTERNAL || code == grpc::StatusCode::DATA_LOSS ||
         code == grpc::StatusCode::UNKNOWN || code == grpc::StatusCode::UNIMPLEMENTED;
}

// One RPC with the soak's deadline; records it, and flags a missed deadline
// (unless the server was killed meanwhile) and every answer no request may get.
template <typename Call>
grpc::Status Rpc(const ActorEnv& env, const std::string& what, Call call) {
  const int64_t epoch = env.ledger->kill_epoch();
  env.ledger->AddCall();
  grpc::Status status = call(itest::Context(env.deadline_s).get());
  const bool killed_meanwhile = env.ledger->kill_epoch() != epoch;
  if (status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED && !killed_meanwhile) {
    env.ledger->Violation(absl::StrCat(what, ": no answer within ", env.deadline_s, " s"));
  }
  if (IsNeverAcceptable(status.error_code())) env.ledger->Violation(absl::StrCat(what, ": ", itest::Describe(status)));
  return status;
}

void Pause(std::mt19937_64& random, int min_ms, int max_ms) {
  std::this_thread::sleep_for(milliseconds(std::uniform_int_distribution<int>(min_ms, max_ms)(random)));
}

void NoteLease(const ActorEnv& env, const std::string& rig, const pb::ProbeCommand& command) {
  env.ledger->AddLease({rig, command.command_id(), NowMs(), ToMs(command.lease_deadline())});
}

// A rig's trace for a command; `variant` != 0 gives other samples.
absl::StatusOr<pb::TraceSamples> Measure(const ActorEnv& env, const pb::ProbeCommand& command, int64_t variant) {
  absl::StatusOr<ProbeRequest> request = itest::SeededProbeRequest(command, command.command_id() * 7 + variant);
  if (!request.ok()) return request.status();
  absl::StatusOr<ProbeExecution> execution = env.rig->ExecuteDetailed(*request);
  if (!execution.ok()) return execution.status();
  return DragTraceToProto(execution->trace);
}

enum class Habit { kNormal, kIdenticalRetry, kConflictingRetry, kLate, kFailure };

Habit DrawHabit(std::mt19937_64& random) {
  const int r = std::uniform_int_distribution<int>(0, 99)(random);
  if (r < 65) return Habit::kNormal;
  if (r < 77) return Habit::kIdenticalRetry;
  if (r < 84) return Habit::kConflictingRetry;
  if (r < 90) return Habit::kLate;
  return Habit::kFailure;
}

}  // namespace

void RunRig(const ActorEnv& env, const std::string& rig_id, uint64_t seed) {
  std::mt19937_64 random(seed);
  Connection connection(env);
  std::optional<pb::ProbeCommand> next;  // leased with the previous submission
  while (!env.stop->load()) {
    pb::ProbeCommand command;
    if (next) {
      command = *next;
      next.reset();
    } else {
      pb::LeaseCommandRequest lease_request;
      lease_request.set_rig_id(rig_id);
      lease_request.set_job_id(env.job_id);
      pb::LeaseCommandResponse lease;
      grpc::Status status = Rpc(env, rig_id + " LeaseCommand", [&](grpc::ClientContext* c) {
        return connection.stubs().probe->LeaseCommand(c, lease_request, &lease);
      });
      if (!status.ok() || lease.job_finished() || lease.command().command_id() == 0) {
        Pause(random, 5, 60);
        continue;
      }
      command = lease.command();
      NoteLease(env, rig_id, command);
    }
    const Habit habit = DrawHabit(random);
    if (habit == Habit::kFailure) {
      pb::ReportFailureRequest failure;
      failure.set_command_id(command.command_id());
      failure.set_rig_id(rig_id);
      failure.set_reason("chaos: the rig could not reach the site");
      failure.set_kind(pb::FAILURE_KIND_TRANSIENT);
      pb::ReportFailureResponse answer;
      Rpc(env, rig_id + " ReportFailure", [&](grpc::ClientContext* c) {
        return connection.stubs().probe->ReportFailure(c, failure, &answer);
      });
      continue;
    }
    absl::StatusOr<pb::TraceSamples> samples = Measure(env, command, 0);
    if (!samples.ok()) continue;  // off an open edge: the simulator refuses; the lease expires
    if (habit == Habit::kLate) {
      const int64_t past = ToMs(command.lease_deadline()) - NowMs() + 150;
      if (past > 0) std::this_thread::sleep_for(milliseconds(past));
    }
    pb::SubmitTraceRequest submit;
    submit.set_command_id(command.command_id());
    submit.set_rig_id(rig_id);
    *submit.mutable_samples() = *samples;
    submit.set_lease_next(habit == Habit::kNormal && std::uniform_int_distribution<int>(0, 1)(random) == 1);
    // Retried while the server is unavailable (restarting, busy, re-reading a job).
    pb::SubmitTraceResponse answer;
    grpc::Status status(grpc::StatusCode::UNAVAILABLE, "not sent: the round ended");
    const int64_t epoch = env.ledger->kill_epoch();
    int64_t last_sent_ms = 0;
    for (int attempt = 0; attempt < 100 && !env.stop->load(); ++attempt) {
      answer.Clear();
      last_sent_ms = NowMs();
      status = Rpc(env, absl::StrCat(rig_id, " SubmitTrace(", command.command_id(), ")"),
                   [&](grpc::ClientContext* c) { return connection.stubs().probe->SubmitTrace(c, submit, &answer); });
      if (status.error_code() != grpc::StatusCode::UNAVAILABLE &&
          status.error_code() != grpc::StatusCode::DEADLINE_EXCEEDED) {
        break;
      }
      Pause(random, 20, 100);
    }
    if (status.ok()) {
      env.ledger->AddAck({rig_id, env.job_id, command.command_id(), answer.sample().trace_id(), submit.samples()});
      if (answer.next().command().command_id() != 0) {
        next = answer.next().command();
        NoteLease(env, rig_id, *next);
      }
    } else {
      // A rig whose measuring outlasted its lease (a loaded machine: the
      // lease is 1 s) is refused by design; one that sent in time must not be.
      // The margin covers the call's way to the server on this host.
      constexpr int64_t kSendMarginMs = 100;
      const bool sent_late = last_sent_ms > ToMs(command.lease_deadline()) - kSendMarginMs;
      const bool excused = env.job_cancelled->load() || habit == Habit::kLate || sent_late ||
                           env.ledger->kill_epoch() != epoch;
      const bool refusal = status.error_code() == grpc::StatusCode::FAILED_PRECONDITION ||
                           status.error_code() == grpc::StatusCode::ALREADY_EXISTS;
      if (!(refusal && excused) && status.error_code() != grpc::StatusCode::UNAVAILABLE) {
        env.ledger->Violation(absl::StrCat(rig_id, " SubmitTrace(", command.command_id(), ") refused: ",
                                           itest::Describe(status)));
      }
      continue;
    }
    if (habit == Habit::kIdenticalRetry || habit == Habit::kConflictingRetry) {
      if (habit == Habit::kConflictingRetry) {
        absl::StatusOr<pb::TraceSamples> other = Measure(env, command, 1);
        if (!other.ok()) continue;
        *submit.mutable_samples() = *other;
      }
      submit.set_lease_next(false);
      pb::SubmitTraceResponse again;
      grpc::Status retried = Rpc(env, absl::StrCat(rig_id, " SubmitTrace retry(", command.command_id(), ")"),
                                 [&](grpc::ClientContext* c) { return connection.stubs().probe->SubmitTrace(c, submit, &again); });
      if (habit == Habit::kIdenticalRetry) {
        if (retried.ok() && !again.already_accepted()) {
          env.ledger->Violation(absl::StrCat("identical retry of command ", command.command_id(), " stored again"));
        } else if (!retried.ok() && retried.error_code() != grpc::StatusCode::UNAVAILABLE) {
          env.ledger->Violation(absl::StrCat("identical retry of command ", command.command_id(),
                                             " not acknowledged: ", itest::Describe(retried)));
        }
      } else if (retried.ok()) {
        env.ledger->Violation(absl::StrCat("a retry with other samples for command ", command.command_id(),
                                           " was acknowledged (its samples are not stored)"));
      }
    }
  }
}

void RunOperator(const ActorEnv& env, uint64_t seed) {
  std::mt19937_64 random(seed);
  Connection connection(env);
  bool paused = false;
  while (!env.stop->load()) {
    Pause(random, 40, 250);
    pb::SetJobStateRequest request;
    request.set_job_id(env.job_id);
    pb::SetJobStateResponse response;
    grpc::Status status = Rpc(env, paused ? "ResumeJob" : "PauseJob", [&](grpc::ClientContext* c) {
      return paused ? connection.stubs().jobs->ResumeJob(c, request, &response)
                    : connection.stubs().jobs->PauseJob(c, request, &response);
    });
    if (status.ok()) {
      paused = !paused;
    } else if (status.error_code() == grpc::StatusCode::UNAVAILABLE &&
               absl::StrContains(status.error_message(), "re-read")) {
      // The server is up: an operator's change waits out a job's re-read.
      env.ledger->Violation(absl::StrCat(paused ? "ResumeJob" : "PauseJob", ": ", itest::Describe(status)));
    } else if (status.error_code() == grpc::StatusCode::FAILED_PRECONDITION) {
      // The job completed (or our view is stale after a failed call): re-read it.
      pb::GetJobRequest get;
      get.set_job_id(env.job_id);
      pb::GetJobResponse job;
      if (Rpc(env, "GetJob", [&](grpc::ClientContext* c) { return connection.stubs().jobs->GetJob(c, get, &job); }).ok()) {
        paused = job.job().state() == pb::JOB_STATE_PAUSED;
      }
    }
  }
  if (paused) {  // leave the job running for the next round's checks
    pb::SetJobStateRequest request;
    request.set_job_id(env.job_id);
    pb::SetJobStateResponse response;
    Rpc(env, "ResumeJob", [&](grpc::ClientContext* c) { return connection.stubs().jobs->ResumeJob(c, request, &response); });
  }
}

void RunWatcher(const ActorEnv& env, uint64_t seed) {
  std::mt19937_64 random(seed);
  Connection connection(env);
  while (!env.stop->load()) {
    pb::WatchJobRequest request;
    request.set_job_id(env.job_id);
    request.set_include_map(std::uniform_int_distribution<int>(0, 1)(random) == 1);
    auto context = itest::Context(60);
    const int64_t epoch = env.ledger->kill_epoch();
    env.ledger->AddCall();
    auto reader = connection.stubs().jobs->WatchJob(context.get(), request);
    const int updates_wanted = std::uniform_int_distribution<int>(1, 8)(random);
    pb::JobUpdate update;
    int updates = 0;
    while (updates < updates_wanted && !env.stop->load() && reader->Read(&update)) ++updates;
    context->TryCancel();
    while (reader->Read(&update)) {
    }
    grpc::Status status = reader->Finish();
    if (IsNeverAcceptable(status.error_code()) ||
        (status.error_code() == grpc::StatusCode::DEADLINE_EXCEEDED && env.ledger->kill_epoch() == epoch)) {
      env.ledger->Violation(absl::StrCat("WatchJob(include_map=", request.include_map(), "): ", itest::Describe(status)));
    }
    Pause(random, 10, 100);
  }
}

void RunReader(const ActorEnv& env, uint64_t seed) {
  std::mt19937_64 random(seed);
  Connection connection(env);
  int64_t some_trace = 0;
  while (!env.stop->load()) {
    Pause(random, 5, 40);
    itest::Stubs& stubs = connection.stubs();
    switch (std::uniform_int_distribution<int>(0, 8)(random)) {
      case 0: {
        pb::GetJobRequest r;
        r.set_job_id(env.job_id);
        pb::GetJobResponse o;
        Rpc(env, "GetJob", [&](grpc::ClientContext* c) { return stubs.jobs->GetJob(c, r, &o); });
        break;
      }
      case 1: {
        pb::GetPlanRequest r;
        r.set_job_id(env.job_id);
        pb::GetPlanResponse o;
        Rpc(env, "GetPlan", [&](grpc::ClientContext* c) { return stubs.jobs->GetPlan(c, r, &o); });
        break;
      }
      case 2: {
        pb::GetMapRequest r;
        r.set_job_id(env.job_id);
        r.set_level(-1);
        pb::GetMapResponse o;
        Rpc(env, "GetMap", [&](grpc::ClientContext* c) { return stubs.maps->GetMap(c, r, &o); });
        break;
      }
      case 3: {
        pb::QueryMapRequest r;
        r.set_job_id(env.job_id);
        for (int i = 0; i < 3; ++i) {
          pb::Vec3* p = r.add_points();
          p->set_x(std::uniform_real_distribution<double>(-100, 100)(random));
          p->set_y(std::uniform_real_distribution<double>(-75, 75)(random));
          p->set_z(1);
        }
        pb::QueryMapResponse o;
        Rpc(env, "QueryMap", [&](grpc::ClientContext* c) { return stubs.maps->QueryMap(c, r, &o); });
        break;
      }
      case 4: {
        pb::ListSamplesRequest r;
        r.set_job_id(env.job_id);
        pb::ListSamplesResponse o;
        if (Rpc(env, "ListSamples", [&](grpc::ClientContext* c) { return stubs.maps->ListSamples(c, r, &o); }).ok() &&
            o.samples_size() > 0) {
          some_trace = o.samples(std::uniform_int_distribution<int>(0, o.samples_size() - 1)(random)).trace_id();
        }
        break;
      }
      case 5: {
        if (some_trace == 0) break;
        pb::GetSampleRequest r;
        r.set_trace_id(some_trace);
        r.set_include_series(true);
        pb::GetSampleResponse o;
        Rpc(env, "GetSample(include_series)", [&](grpc::ClientContext* c) { return stubs.maps->GetSample(c, r, &o); });
        break;
      }
      case 6: {
        pb::ListJobEventsRequest r;
        r.set_job_id(env.job_id);
        pb::ListJobEventsResponse o;
        Rpc(env, "ListJobEvents", [&](grpc::ClientContext* c) { return stubs.jobs->ListJobEvents(c, r, &o); });
        break;
      }
      case 7: {
        if (std::uniform_int_distribution<int>(0, 9)(random) != 0) break;  // refits are rare
        pb::RefitJobRequest r;
        r.set_job_id(env.job_id);
        r.mutable_settings()->set_ar_order(3);
        pb::RefitJobResponse o;
        Rpc(env, "RefitJob", [&](grpc::ClientContext* c) { return stubs.traces->RefitJob(c, r, &o); });
        break;
      }
      default: {
        pb::ListJobsRequest r;
        pb::ListJobsResponse o;
        Rpc(env, "ListJobs", [&](grpc::ClientContext* c) { return stubs.jobs->ListJobs(c, r, &o); });
        break;
      }
    }
  }
}

}  // namespace surfmap::chaos
