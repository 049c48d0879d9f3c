// surfmap-rig: a lab rig as a client of surfmapd.
//
//   surfmap-rig --server ADDR (--sim SCENE | --driver "CMD ARGS") [--job ID] [--rig-id NAME]
//               [--token T] [--ca-file CA.pem] [--spool DIR] [--retry-for 5min] [--max-commands N] [--quiet]
//   surfmap-rig simulate-drag --sim SCENE [--sim-seed N]   # the simulated rig as a driver program
//   surfmap-rig score --sim SCENE (--job JOB | --map MAP.json) [--points N] [--min-region-points N]
//                     [--json OUT.json|-]
//
// The rig leases probe commands, executes them on a RigDriver, spools each
// trace and returns it (RigLoop). `--sim SCENE` drives the simulated rig on a
// scene; `--driver` runs a lab's own driver program and talks to it in JSON
// lines (driver_protocol.h); a robot driver in C++ plugs in as another
// RigDriver (clients/sim/rig/rig_driver.h) where MakeDriver builds these, and the
// loop, spool, retries and signal handling below work unchanged.
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include "absl/strings/str_cat.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"
#include "clients/remote/map_json.h"
#include "clients/remote/progress_line.h"
#include "clients/remote/remote_call.h"
#include "clients/sim/rig/scene.h"
#include "clients/sim/rig/simulated_rig.h"
#include "clients/rig/duration_text.h"
#include "clients/rig/external_driver.h"
#include "clients/rig/map_score.h"
#include "clients/rig/served_map_score.h"
#include "clients/rig/probe_endpoint.h"
#include "clients/rig/rig_frame_driver.h"
#include "clients/rig/rig_loop.h"
#include "clients/rig/realtime_driver.h"
#include "clients/rig/scene_guard.h"
#include "clients/rig/simulated_driver.h"
#include "clients/rig/trace_spool.h"
#include "server/codec/rig_registration_proto.h"
#include "surfmap_version.h"

namespace {

namespace pb = ::surfmap::v1;

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the signal handler needs a lock-free flag");

// First SIGINT/SIGTERM: finish the current command, then leave with a summary.
// Second: leave now (the server re-issues the command when its lease expires).
extern "C" void OnStopSignal(int) {
  if (g_stop.exchange(true)) {
    constexpr char kMessage[] = "surfmap-rig: second signal, abandoning the current command\n";
    [[maybe_unused]] ssize_t n = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
    ::_exit(130);
  }
}

void InstallStopHandlers() {
  struct sigaction action {};
  action.sa_handler = OnStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking sleep wakes up
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

// The simulated rig's settings (beyond its scene).
struct SimRigArgs {
  uint64_t seed = 0;
  double disturbance = 1.0;  // DragSimOptions::WithDisturbancesScaled
  double sample_rate_hz = surfmap::DragSimOptions{}.sample_rate_hz;
};

struct RunArgs {
  surfmap::cli::RemoteOptions remote;
  std::string sim;
  SimRigArgs sim_rig;
  std::string driver;           // --driver "CMD ARGS"
  double driver_timeout_s = 120.0;
  double driver_start_timeout_s = 60.0;
  int64_t job_id = 0;
  std::string rig_id;
  std::string spool;            // empty: DefaultSpoolDir(rig id)
  std::string retry_for = "5min";
  int max_commands = 0;
  bool quiet = false;
  bool realtime = false;        // --sim: each drag takes its real duration
  std::string frame = "object";  // the frame traces are sent in (--sim converts its own)
};

absl::StatusOr<std::unique_ptr<surfmap::SimulatedRig>> MakeSimulatedRig(const std::string& scene_name,
                                                                       const SimRigArgs& args) {
  absl::StatusOr<surfmap::Scene> scene = surfmap::LoadSceneByName(scene_name);
  if (!scene.ok()) return scene.status();
  surfmap::SimulatedRigOptions options;
  options.seed = args.seed;
  options.simulation = options.simulation.WithDisturbancesScaled(args.disturbance);
  options.simulation.sample_rate_hz = args.sample_rate_hz;
  return surfmap::SimulatedRig::Create(*std::move(scene), options);  // validates both (names the bad one)
}

// --sim-seed, --sim-disturbance and --sim-rate, on the command and on simulate-drag.
void AddSimRigOptions(CLI::App* app, SimRigArgs* args) {
  app->add_option("--sim-seed", args->seed, "Seed mixed into the simulated rig's noise");
  app->add_option("--sim-disturbance", args->disturbance,
                  "With --sim: every disturbance of the simulated rig (sensor noise, vibration, speed jitter, "
                  "contact transients, stick-slip, force tracking) times this; 0 = exact physics, 2 = a rig twice as "
                  "disturbed (at most ~3.3, where the contact overshoot reaches its limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  // Bounded: a drag's samples are allocated at once (~5 s of them; 100 kHz
  // is 500,000, past any force sensor a lab drags with).
  app->add_option("--sim-rate", args->sample_rate_hz, "With --sim: the simulated rig's sample rate, Hz (1 to 100000)")
      ->check(CLI::Range(1.0, 100000.0))
      ->capture_default_str();
}

// A registration by id, for the simulated rig sending traces in a rig frame.
absl::StatusOr<surfmap::RigRegistration> FetchRegistration(const surfmap::cli::RemoteOptions& remote,
                                                           int64_t registration_id) {
  auto objects = pb::ObjectService::NewStub(surfmap::cli::ConnectChannel(remote));
  pb::GetRigRegistrationRequest request;
  request.set_registration_id(registration_id);
  pb::GetRigRegistrationResponse response;
  grpc::ClientContext context;
  surfmap::cli::PrepareContext(remote, &context);
  grpc::Status status = objects->GetRigRegistration(&context, request, &response);
  if (!status.ok()) {
    // The server's code, so RigFrameDriver tells "unreachable" (retry) from
    // "no such registration" (stop).
    return absl::Status(static_cast<absl::StatusCode>(status.error_code()),
                        absl::StrCat("GetRigRegistration: ", status.error_message()));
  }
  return surfmap::RigRegistrationFromProto(response.registration());
}

// The job's object as the server has it, for the simulated rig's scene check.
absl::StatusOr<surfmap::rig::MeshFingerprint> FetchJobObject(const surfmap::cli::RemoteOptions& remote,
                                                             int64_t job_id) {
  std::shared_ptr<grpc::Channel> channel = surfmap::cli::ConnectChannel(remote);
  auto jobs = pb::JobService::NewStub(channel);
  auto objects = pb::ObjectService::NewStub(channel);
  pb::GetJobRequest job_request;
  job_request.set_job_id(job_id);
  pb::GetJobResponse job;
  {
    grpc::ClientContext context;
    surfmap::cli::PrepareContext(remote, &context);
    grpc::Status status = jobs->GetJob(&context, job_request, &job);
    if (!status.ok()) return absl::UnavailableError(absl::StrCat("GetJob: ", status.error_message()));
  }
  pb::GetObjectRequest object_request;
  object_request.set_object_id(job.job().spec().object_id());
  pb::GetObjectResponse object;
  pb::GetMeshRequest mesh_request;
  mesh_request.set_object_id(job.job().spec().object_id());
  mesh_request.set_level(0);
  pb::GetMeshResponse mesh;
  {
    grpc::ClientContext context;
    surfmap::cli::PrepareContext(remote, &context);
    grpc::Status status = objects->GetObject(&context, object_request, &object);
    if (!status.ok()) return absl::UnavailableError(absl::StrCat("GetObject: ", status.error_message()));
  }
  {
    grpc::ClientContext context;
    surfmap::cli::PrepareContext(remote, &context);
    grpc::Status status = objects->GetMesh(&context, mesh_request, &mesh);
    if (!status.ok()) return absl::UnavailableError(absl::StrCat("GetMesh: ", status.error_message()));
  }
  surfmap::rig::MeshFingerprint out;
  out.name = absl::StrCat("job ", job_id, "'s object ", object.object().object_id(), " (\"", object.object().name(),
                          "\")");
  for (const pb::Vec3& p : mesh.positions()) out.limit_positions.emplace_back(p.x(), p.y(), p.z());
  out.triangle_indices.assign(mesh.triangle_indices().begin(), mesh.triangle_indices().end());
  return out;
}

// The drivers the loop calls through, outermost last: each layer holds a
// reference to the one before.
struct DriverStack {
  std::vector<std::unique_ptr<surfmap::RigDriver>> layers;
  surfmap::RigDriver& top() { return *layers.back(); }
};

// Where a robot's RigDriver is constructed: the simulated rig (checked
// against each job's object, optionally at real pace), or an external driver
// program (its log lines go to `log`).
absl::StatusOr<DriverStack> MakeDriver(const RunArgs& args, std::function<void(const std::string&)> log) {
  DriverStack stack;
  if (!args.driver.empty()) {
    surfmap::rig::ExternalDriverOptions options;
    options.command = args.driver;
    options.command_timeout_s = args.driver_timeout_s;
    options.start_timeout_s = args.driver_start_timeout_s;
    options.on_log = std::move(log);
    absl::StatusOr<std::unique_ptr<surfmap::rig::ExternalDriver>> driver =
        surfmap::rig::ExternalDriver::Start(std::move(options));
    if (!driver.ok()) return driver.status();
    stack.layers.push_back(std::move(*driver));
    return stack;
  }
  absl::StatusOr<std::unique_ptr<surfmap::SimulatedRig>> rig = MakeSimulatedRig(args.sim, args.sim_rig);
  if (!rig.ok()) return rig.status();
  absl::StatusOr<surfmap::rig::MeshFingerprint> scene = surfmap::rig::SceneFingerprint(**rig);
  if (!scene.ok()) return scene.status();
  stack.layers.push_back(std::move(*rig));
  stack.layers.push_back(std::make_unique<surfmap::rig::SceneGuardDriver>(
      stack.top(), *std::move(scene),
      [remote = args.remote](int64_t job_id) { return FetchJobObject(remote, job_id); }));
  if (args.realtime) stack.layers.push_back(std::make_unique<surfmap::rig::RealtimeDriver>(stack.top(), &g_stop));
  if (args.frame != "object") {
    absl::StatusOr<surfmap::TraceFrame> frame = surfmap::ParseTraceFrame(args.frame);
    if (!frame.ok()) return frame.status();
    stack.layers.push_back(std::make_unique<surfmap::rig::RigFrameDriver>(
        stack.top(), *frame, [remote = args.remote](int64_t id) { return FetchRegistration(remote, id); }));
  }
  return stack;
}

std::string HostName() {
  char name[256] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "rig";
  return name;
}

int RunRig(const RunArgs& args) {
  if (args.sim.empty() == args.driver.empty()) {
    std::cerr << "surfmap-rig: use exactly one of --sim SCENE (the simulated rig) or --driver \"CMD ARGS\" "
                 "(your robot's driver program, see clients/rig/README.md)\n";
    return 2;
  }
  surfmap::rig::RigLoopOptions options;
  // A simulated rig is named per process; a robot by its host, so its spool
  // is found again after a restart.
  options.rig_id = !args.rig_id.empty() ? args.rig_id
                   : args.sim.empty()   ? HostName()
                                        : absl::StrCat("sim-", args.sim, "-", ::getpid());
  options.job_id = args.job_id;
  options.max_commands = args.max_commands;
  if (absl::StatusOr<surfmap::TraceFrame> frame = surfmap::ParseTraceFrame(args.frame); frame.ok()) {
    options.frame = surfmap::TraceFrameToProto(*frame);
  } else {
    std::cerr << "surfmap-rig: --frame must be object, rig_base or rig_base_sensor_forces, got '" << args.frame
              << "'\n";
    return 2;
  }
  if (!args.driver.empty() && args.frame != "object") {
    // The driver protocol's trace line is in the object's frame
    // (clients/rig/README.md): stating another frame would mislabel every trace.
    std::cerr << "surfmap-rig: --frame " << args.frame << " works with --sim only: an external driver answers in "
                 "the object's frame (it gets the rig-frame command to move by)\n";
    return 2;
  }
  absl::StatusOr<double> retry_for = surfmap::rig::ParseDurationSeconds(args.retry_for);
  if (!retry_for.ok()) {
    std::cerr << "surfmap-rig: --retry-for: " << retry_for.status().message() << "\n";
    return 2;
  }
  options.retry_for_s = *retry_for;
  std::string why;
  if (!options.IsValid(&why)) {
    std::cerr << "surfmap-rig: " << why << "\n";
    return 2;
  }
  absl::StatusOr<std::filesystem::path> spool_dir =
      args.spool.empty() ? surfmap::rig::DefaultSpoolDir(options.rig_id) : std::filesystem::path(args.spool);
  if (!spool_dir.ok()) {
    std::cerr << "surfmap-rig: " << spool_dir.status().message() << "\n";
    return 2;
  }
  absl::StatusOr<std::unique_ptr<surfmap::rig::TraceSpool>> spool = surfmap::rig::TraceSpool::Open(*spool_dir);
  if (!spool.ok()) {
    std::cerr << "surfmap-rig: --spool: " << spool.status().message() << "\n";
    return 2;
  }

  const bool tty = surfmap::cli::ProgressDisplay::IsTerminal(stdout);
  surfmap::cli::ProgressDisplay display(stdout, tty);
  surfmap::rig::RigLoopHooks hooks;
  if (!args.quiet) {
    hooks.on_progress = [&](const pb::JobProgress& progress) {
      display.Show(options.rig_id + " " + surfmap::cli::FormatProgressLine(progress, tty ? 20 : 0));
    };
  }
  hooks.on_event = [&](const std::string& line) {
    display.Finish();
    std::fflush(stdout);
    std::fprintf(stderr, "%s\n", line.c_str());
  };
  // Declared after the display: destroyed first (an external driver logs how it ended).
  absl::StatusOr<DriverStack> driver =
      MakeDriver(args, [&](const std::string& line) { hooks.on_event(options.rig_id + " " + line); });
  if (!driver.ok()) {
    std::cerr << "surfmap-rig: " << (args.driver.empty() ? "--sim " + args.sim : std::string("--driver")) << ": "
              << driver.status().message() << "\n";
    return 2;
  }
  surfmap::rig::GrpcProbeEndpoint endpoint(args.remote);
  // On a terminal the wait is shown on the progress line (redrawn each retry);
  // in a log, one line per retry.
  hooks.on_retry = [&](const surfmap::rig::RetryNotice& notice) {
    const std::string line = options.rig_id + ": " + surfmap::rig::FormatRetryNotice(notice);
    if (tty && !args.quiet) {
      display.Show(line);
    } else {
      hooks.on_event(line);
    }
  };
  InstallStopHandlers();
  surfmap::rig::RigLoop loop(endpoint, driver->top(), **spool, options, &g_stop, hooks);
  surfmap::rig::RigLoopSummary summary = loop.Run();
  display.Finish();
  std::printf("%s\n", summary.Format(options.rig_id).c_str());
  std::fflush(stdout);
  if (summary.rejected > 0) {
    std::fprintf(stderr, "surfmap-rig: %d refused trace(s) kept in %s (each with a .reason file)\n", summary.rejected,
                 (*spool)->rejected_dir().c_str());
  }
  if (summary.spooled_left > 0) {
    std::fprintf(stderr,
                 "surfmap-rig: %d trace(s) not yet acknowledged are kept in %s; they are resubmitted when "
                 "surfmap-rig starts again with this spool (--rig-id %s or --spool DIR)\n",
                 summary.spooled_left, (*spool)->dir().c_str(), options.rig_id.c_str());
  }
  (*spool)->RemoveDirectoriesIfEmpty();
  if (!summary.error.ok()) {
    std::fprintf(stderr, "%s\n",
                 surfmap::cli::FormatRpcError(summary.error_rpc, summary.error, "surfmap-rig").c_str());
    return 1;
  }
  return 0;
}

struct SimulateDragArgs {
  std::string sim;
  SimRigArgs sim_rig;
};

int RunSimulateDrag(const SimulateDragArgs& args) {
  absl::StatusOr<std::unique_ptr<surfmap::SimulatedRig>> rig = MakeSimulatedRig(args.sim, args.sim_rig);
  if (!rig.ok()) {
    std::cerr << "surfmap-rig simulate-drag: --sim " << args.sim << ": " << rig.status().message() << "\n";
    return 2;
  }
  std::ios::sync_with_stdio(false);
  return surfmap::rig::ServeSimulatedDriver(
      **rig, absl::StrCat("surfmap-rig simulate-drag --sim ", args.sim, " (SimulatedRig, seed ", args.sim_rig.seed, ")"),
      std::cin, std::cout, std::cerr);
}

struct ScoreArgs {
  std::string sim;
  std::string map;
  int64_t job_id = 0;
  int points = 5000;
  int min_region_points = surfmap::SurfaceScoreOptions{}.min_region_points;
  std::uint64_t seed = 1;
  std::string json;
};

// Writes the score's JSON (to args.json, or stdout for '-') and its table.
int ReportScore(const ScoreArgs& args, const nlohmann::json& result, const std::string& table) {
  if (args.json == "-") {
    std::cout << result.dump(1) << "\n";
    return 0;
  }
  std::cout << table;
  if (!args.json.empty()) {
    std::ofstream out(args.json, std::ios::binary | std::ios::trunc);
    out << result.dump(1) << "\n";
    out.close();
    if (!out) {
      std::cerr << "surfmap-rig score: " << args.json << ": cannot write file\n";
      return 2;
    }
  }
  return 0;
}

// The job's map as the server answers QueryMap, on the scene's true surface.
int RunServedScore(const ScoreArgs& args, const surfmap::Scene& scene, const surfmap::cli::RemoteOptions& remote) {
  surfmap::SurfaceScoreOptions options;
  options.points = args.points;
  options.min_region_points = args.min_region_points;
  options.seed = args.seed;
  absl::StatusOr<surfmap::SurfaceScore> score =
      surfmap::rig::ScoreServedMap(scene, surfmap::cli::ConnectChannel(remote), remote, args.job_id, options);
  if (!score.ok()) {
    std::cerr << "surfmap-rig score: job " << args.job_id << ": " << score.status().message() << "\n";
    return 1;
  }
  nlohmann::json result = surfmap::SurfaceScoreToJson(*score);
  result["scene"] = args.sim;
  result["job_id"] = args.job_id;
  return ReportScore(args, result,
                     surfmap::FormatSurfaceScore(*score, absl::StrCat("job ", args.job_id, " vs scene '", args.sim,
                                                                      "' (QueryMap)")));
}

int RunScore(const ScoreArgs& args, const surfmap::cli::RemoteOptions& remote) {
  absl::StatusOr<surfmap::Scene> scene = surfmap::LoadSceneByName(args.sim);
  if (!scene.ok()) {
    std::cerr << "surfmap-rig score: --sim " << args.sim << ": " << scene.status().message() << "\n";
    return 2;
  }
  if (args.job_id > 0) return RunServedScore(args, *scene, remote);
  std::ifstream in(args.map, std::ios::binary);
  if (!in) {
    std::cerr << "surfmap-rig score: " << args.map << ": cannot open file\n";
    return 2;
  }
  nlohmann::json json = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (json.is_discarded()) {
    std::cerr << "surfmap-rig score: " << args.map << ": not valid JSON\n";
    return 2;
  }
  absl::StatusOr<surfmap::cli::MapDocument> map = surfmap::cli::MapDocumentFromJson(json, args.map);
  if (!map.ok()) {
    std::cerr << "surfmap-rig score: " << map.status().message() << "\n";
    return 2;
  }
  absl::StatusOr<surfmap::rig::MapScore> score = surfmap::rig::ScoreMap(*scene, *map);
  if (!score.ok()) {
    std::cerr << "surfmap-rig score: " << args.map << ": " << score.status().message() << "\n";
    return 1;
  }
  return ReportScore(args, surfmap::rig::MapScoreToJson(*score, args.sim),
                     surfmap::rig::FormatMapScore(*score, args.sim));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"surfmap-rig: a probing rig as a client of surfmapd (lease, execute, submit)"};
  app.require_subcommand(0, 1);
  app.set_version_flag("--version", std::string("surfmap-rig ") + surfmap::kSurfmapVersion);
  RunArgs run;
  run.remote.server = std::string(surfmap::cli::kDefaultServer);
  app.add_option("--server", run.remote.server, "surfmapd address host:port")
      ->envname("SURFMAP_SERVER")
      ->capture_default_str();
  app.add_option("--token", run.remote.token, "Bearer token (role probe or higher)")->envname("SURFMAP_TOKEN");
  app.add_option("--ca-file", run.remote.ca_file, "Connect with TLS, trusting the CA in this PEM file")
      ->envname("SURFMAP_CA_FILE")
      ->check(CLI::ExistingFile);
  app.add_option("--timeout", run.remote.timeout_s, "Deadline of every call, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--sim", run.sim, "Drive the simulated rig on this scene (e.g. bottle, plate)");
  app.add_option("--driver", run.driver,
                 "Run this driver program (/bin/sh -c) and talk to it in JSON lines (see README: Connect your robot)");
  app.add_option("--driver-timeout", run.driver_timeout_s, "Seconds the driver may take to answer one command")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--driver-start-timeout", run.driver_start_timeout_s,
                 "Seconds the driver may take to say it is ready")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  AddSimRigOptions(&app, &run.sim_rig);
  app.add_option("--frame", run.frame,
                 "Frame of the traces sent: object (default), rig_base or rig_base_sensor_forces (the rig must be "
                 "registered to the object; --sim converts its traces with the registration)");
  app.add_option("--job", run.job_id, "Only this job's commands (default: any running job)");
  app.add_option("--rig-id", run.rig_id,
                 "Rig name in the server's leases and logs (default sim-SCENE-PID with --sim, the host name with "
                 "--driver)");
  app.add_option("--spool", run.spool,
                 "Directory keeping each trace until the server acknowledged it "
                 "(default $XDG_STATE_HOME/surfmap/spool/RIG-ID, else ~/.local/state/...)");
  app.add_option("--retry-for", run.retry_for,
                 "How long a call is retried while the server is unavailable (e.g. 300, 90s, 5min, 1h)")
      ->capture_default_str();
  app.add_option("--max-commands", run.max_commands, "Stop after this many commands (0 = until the job ends)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--quiet", run.quiet, "No progress line (the summary line is still printed)");
  app.add_flag("--realtime", run.realtime,
               "With --sim: each drag takes as long as at the commanded speed (sleeps for the trace's duration), "
               "so a dashboard or `surfmap watch` can be followed as in a lab");

  SimulateDragArgs simulate;
  CLI::App* simulate_cmd = app.add_subcommand(
      "simulate-drag", "The simulated rig as a driver program: command lines on stdin, traces on stdout");
  simulate_cmd->add_option("--sim", simulate.sim, "Scene to simulate (e.g. bottle, plate)")->required();
  AddSimRigOptions(simulate_cmd, &simulate.sim_rig);

  ScoreArgs score;
  CLI::App* score_cmd = app.add_subcommand(
      "score", "Compare a job's map (--job: through QueryMap, on the true surface) or a map file (--map: its "
               "vertices) with the scene's truth");
  score_cmd->add_option("--sim", score.sim, "The scene the map was measured on")->required();
  CLI::Option* map_option = score_cmd->add_option("--map", score.map, "Map file from `surfmap map get --format json`")
                                ->check(CLI::ExistingFile);
  CLI::Option* job_option =
      score_cmd->add_option("--job", score.job_id, "A job on --server: its map read with QueryMap")
          ->check(CLI::PositiveNumber);
  map_option->excludes(job_option);
  score_cmd->add_option("--points", score.points, "--job: random points on the true surface")
      ->check(CLI::Range(100, 1'000'000))
      ->capture_default_str();
  score_cmd->add_option("--min-region-points", score.min_region_points,
                         "--job: each region's row is scored on at least this many of its points (extra points "
                         "drawn inside small regions; the overall share uses --points alone; 0: none)")
      ->check(CLI::Range(0, 100'000))
      ->capture_default_str();
  score_cmd->add_option("--seed", score.seed, "--job: which points")->capture_default_str();
  score_cmd->add_option("--json", score.json, "Also write the score as JSON to this file ('-': JSON on stdout only)");

  CLI11_PARSE(app, argc, argv);
  if (score_cmd->parsed()) {
    if (score.map.empty() && score.job_id == 0) {
      std::cerr << "surfmap-rig score: give --job JOB (the server's map) or --map FILE\n";
      return 2;
    }
    return RunScore(score, run.remote);
  }
  if (simulate_cmd->parsed()) return RunSimulateDrag(simulate);
  return RunRig(run);
}
