#include "clients/cli/watch_command.h"

#include <cstdio>

#include "absl/strings/str_format.h"
#include "clients/remote/progress_line.h"
#include "clients/cli/number_text.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

std::string LatestSampleNote(const pb::JobUpdate& update) {
  if (!update.has_latest_sample()) return "";
  const pb::Sample& s = update.latest_sample();
  return absl::StrFormat("  (last: L%d v%d mu %.3f)", s.site().level(), s.site().vertex(), Shown(s.fit().friction().mu(), 3));
}

void RunWatch(RemoteCli& cli, int64_t job_id, bool plain) {
  auto stub = pb::JobService::NewStub(cli.Channel());
  grpc::ClientContext context;
  // The stream lasts as long as the job: no deadline (keepalive notices a dead server).
  PrepareContext(cli.options, &context, /*with_deadline=*/false);
  pb::WatchJobRequest request;
  request.set_job_id(job_id);
  std::unique_ptr<grpc::ClientReader<pb::JobUpdate>> reader = stub->WatchJob(&context, request);
  const bool tty = !plain && ProgressDisplay::IsTerminal(stdout);
  ProgressDisplay display(stdout, tty);
  pb::JobUpdate update;
  pb::JobInfo last;
  bool any = false;
  while (reader->Read(&update)) {
    last = update.job();
    any = true;
    const std::string prefix = absl::StrFormat("job %d %-9s ", last.job_id(), JobStateName(last.state()));
    // Terminal lines are redrawn in place, so they can afford the bar; the
    // latest sample would make every plain line unique, which is the point.
    display.Show(prefix + FormatProgressLine(last.progress(), tty ? 20 : 0) + (tty ? "" : LatestSampleNote(update)));
  }
  grpc::Status status = reader->Finish();
  display.Finish();
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", FormatRpcError("WatchJob", status).c_str());
    *cli.exit_code = kExitRpcError;
    return;
  }
  if (any) {
    std::printf("job %lld %s: %d samples\n", static_cast<long long>(last.job_id()),
                std::string(JobStateName(last.state())).c_str(), last.progress().measured());
  }
}

}  // namespace

void AddWatchCommand(CLI::App& app, std::shared_ptr<RemoteCli> cli) {
  auto job_id = std::make_shared<int64_t>(0);
  auto plain = std::make_shared<bool>(false);
  CLI::App* watch = app.add_subcommand("watch", "Follow a job's progress until it ends");
  watch->add_option("job", *job_id, "Job id")->required();
  watch->add_flag("--plain", *plain, "Plain lines even on a terminal");
  watch->callback([cli, job_id, plain] { RunWatch(*cli, *job_id, *plain); });
}

}  // namespace surfmap::cli
