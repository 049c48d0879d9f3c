#include "clients/cli/import_command.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <google/protobuf/util/time_util.h>
#include "clients/cli/provenance_options.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;
using google::protobuf::util::TimeUtil;

struct ImportArgs {
  int64_t job_id = 0;
  std::vector<std::string> files;
  std::string source = "surfmap job import";
  std::string recorded;  // RFC 3339; empty = unknown
  ProvenanceArgs provenance;
  bool json = false;
};

// Imports each file in turn; a refused file does not stop the others (the
// exit code says one failed). One line per file on stdout, or its Sample as JSON.
void RunImport(RemoteCli& cli, const ImportArgs& a) {
  pb::ImportTraceRequest base;
  base.set_job_id(a.job_id);
  base.set_source(a.source);
  std::string error;
  if (!ProvenanceFromArgs(a.provenance, base.mutable_provenance(), &error)) return FailUsage(cli, error);
  if (!a.recorded.empty() && !TimeUtil::FromString(a.recorded, base.mutable_recorded())) {
    return FailUsage(cli, "--recorded '" + a.recorded + "': expected an RFC 3339 time, e.g. 2026-11-24T09:30:00Z");
  }
  auto stub = pb::TraceService::NewStub(cli.Channel());
  for (const std::string& file : a.files) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      FailUsage(cli, file + ": cannot open file");
      continue;
    }
    std::ostringstream bytes;
    bytes << in.rdbuf();
    pb::ImportTraceRequest request = base;
    request.set_csv(bytes.str());
    request.set_file_name(std::filesystem::path(file).filename().string());
    pb::ImportTraceResponse response;
    if (!CallRpc(cli, "ImportTrace", *stub, &pb::TraceService::Stub::ImportTrace, request, &response)) continue;
    const pb::Sample& s = response.sample();
    if (a.json) {
      std::printf("%s\n", MessageToJson(response, /*pretty=*/false).c_str());
    } else {
      std::printf("%s: %s trace %lld (mu %.4f, near vertex %d, %.1f %.1f %.1f mm)\n", file.c_str(),
                  response.already_imported() ? "already imported as" : "imported as",
                  static_cast<long long>(s.trace_id()), s.fit().friction().mu(), s.site().vertex(), s.position().x(),
                  s.position().y(), s.position().z());
    }
  }
}

}  // namespace

void AddImportCommand(CLI::App* job, std::shared_ptr<RemoteCli> cli) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* cmd = job->add_subcommand(
      "import",
      "Import drags recorded elsewhere (positioned trace CSVs, docs/trace-format.md) into a job's map; each is "
      "checked like a rig's trace, and a file already imported into the job is not stored twice");
  cmd->add_option("job", a->job_id, "Job id")->required();
  cmd->add_option("files", a->files, "Trace CSV files")->required()->check(CLI::ExistingFile);
  cmd->add_option("--source", a->source, "Who or what recorded them (a rig, a program)")->capture_default_str();
  cmd->add_option("--recorded", a->recorded, "When they were recorded (RFC 3339, e.g. 2026-11-24T09:30:00Z)");
  AddProvenanceOptions(cmd, &a->provenance);
  cmd->add_flag("--json", a->json, "Print each ImportTraceResponse as one JSON line");
  cmd->callback([cli, a] { RunImport(*cli, *a); });
}

}  // namespace surfmap::cli
