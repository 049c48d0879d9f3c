#include "clients/cli/map_commands.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "absl/strings/ascii.h"
#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "clients/remote/map_json.h"
#include "clients/cli/map_overlay.h"
#include "clients/cli/map_regions_command.h"
#include "server/haptics/export/simulate_drag_proto.h"
#include "server/haptics/export/texture_map_proto.h"
#include "server/haptics/map_quantity.h"
#include "server/haptics/texture_map_gltf.h"
#include "server/haptics/texture_map_ply.h"
#include "server/haptics/texture_model_json.h"
#include "clients/cli/number_text.h"
#include "clients/render/map_ply.h"
#include "clients/render/map_render.h"
#include "proto/surfmap/v1/surfmap.grpc.pb.h"
#include "server/codec/trace_samples_proto.h"
#include "server/estimate/drag_trace.h"
#include "server/estimate/trace_csv.h"

namespace surfmap::cli {
namespace {

namespace pb = ::surfmap::v1;

struct MapGetArgs {
  int64_t job_id = 0;
  std::string format;
  std::string output;
  int level = -1;
  std::string view = "0,1,0";
  std::string color_map = "grey";
  int width = 480;
  std::vector<double> mu_range;
  bool one_view = false;
  std::string quantity = "mu";
};

// Writes `bytes` to `path` via a temporary file and rename, so a reader never
// sees half a map.
bool WriteFileAtomically(RemoteCli& cli, const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      FailUsage(cli, path + ": cannot write file");
      return false;
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    FailUsage(cli, path + ": cannot write file: " + ec.message());
    return false;
  }
  return true;
}

void RunMapGet(RemoteCli& cli, const MapGetArgs& args) {
  absl::StatusOr<std::string> format = ResolveMapFormat(args.format, args.output);
  if (!format.ok()) return FailUsage(cli, std::string(format.status().message()));
  if (args.output.empty()) return FailUsage(cli, "map get: -o FILE is required");
  MapRenderOptions render;
  absl::StatusOr<haptics::MapQuantity> quantity = haptics::ParseMapQuantity(args.quantity);
  if (!quantity.ok()) return FailUsage(cli, absl::StrCat("--quantity: ", quantity.status().message()));
  if (*format == "png") {
    absl::StatusOr<Eigen::Vector3d> view = ParsePoint(args.view);
    if (!view.ok()) return FailUsage(cli, absl::StrCat("--view: ", view.status().message()));
    render.view_direction = *view;
    absl::StatusOr<ColorMap> map = ParseColorMap(args.color_map);
    if (!map.ok()) return FailUsage(cli, absl::StrCat("--color-map: ", map.status().message()));
    render.color_map = *map;
    render.view_width = render.view_height = args.width;
    render.two_views = !args.one_view;
    if (args.mu_range.size() == 2) {
      render.value_min = args.mu_range[0];
      render.value_max = args.mu_range[1];
    }
    std::string why;
    if (!render.IsValid(&why)) return FailUsage(cli, "map get: " + why);
  }

  auto map_stub = pb::MapService::NewStub(cli.Channel());
  pb::GetMapRequest request;
  request.set_job_id(args.job_id);
  request.set_level(args.level);
  request.set_include_mesh(true);
  pb::GetMapResponse response;
  if (!CallRpc(cli, "GetMap", *map_stub, &pb::MapService::Stub::GetMap, request, &response)) return;

  std::string bytes;
  if (*format == "json") {
    auto job_stub = pb::JobService::NewStub(cli.Channel());
    pb::GetJobRequest job_request;
    job_request.set_job_id(args.job_id);
    pb::GetJobResponse job;
    if (!CallRpc(cli, "GetJob", *job_stub, &pb::JobService::Stub::GetJob, job_request, &job)) return;
    bytes = MapToJson(response, &job.job()).dump(1) + "\n";
  } else if (*format == "png") {
    MapMesh mesh = MapMeshFromResponse(response);
    // Any per-vertex quantity, from the same TextureMap the exports write.
    absl::StatusOr<haptics::TextureMap> texture = haptics::TextureMapFromResponse(response);
    if (!texture.ok()) return FailUsage(cli, absl::StrCat("map get: ", texture.status().message()));
    absl::StatusOr<std::vector<double>> values = haptics::MapQuantityValues(*texture, *quantity);
    if (!values.ok()) return FailUsage(cli, absl::StrCat("map get: --quantity: ", values.status().message()));
    mesh.values = *std::move(values);
    render.color_bar_title = std::string(haptics::MapQuantityTitle(*quantity));
    MapOverlay overlay = SampleOverlay(mesh, response.map());
    absl::StatusOr<std::string> png = RenderMapPng(mesh, overlay, render);
    if (!png.ok()) return FailUsage(cli, absl::StrCat("map get: rendering: ", png.status().message()));
    bytes = *std::move(png);
  } else {
    // The renderer exports: every per-vertex attribute (PLY, glTF) or the
    // texture model per region (texture-json); see docs/texture-model.md.
    absl::StatusOr<haptics::TextureMap> texture = haptics::TextureMapFromResponse(response);
    if (!texture.ok()) return FailUsage(cli, absl::StrCat("map get: ", texture.status().message()));
    absl::StatusOr<std::string> out;
    if (*format == "ply") {
      out = haptics::WriteTexturePly(*texture);
    } else if (*format == "gltf" || *format == "glb") {
      out = haptics::WriteTextureGltf(*texture, *format == "glb");
    } else {
      absl::StatusOr<nlohmann::json> json = haptics::TextureModelToJson(*texture);
      if (json.ok()) out = json->dump(1) + "\n";
      else out = json.status();
    }
    if (!out.ok()) return FailUsage(cli, absl::StrCat("map get: ", *format, ": ", out.status().message()));
    bytes = *std::move(out);
  }
  if (!WriteFileAtomically(cli, args.output, bytes)) return;
  std::printf("%s: level %d, %d vertices, %d samples\n", args.output.c_str(), response.map().level(),
              response.map().vertex_count(), response.map().samples_size());
}

struct MapQueryArgs {
  int64_t job_id = 0;
  std::vector<std::string> points;
  bool json = false;
};

void RunMapQuery(RemoteCli& cli, const MapQueryArgs& args) {
  pb::QueryMapRequest request;
  request.set_job_id(args.job_id);
  for (const std::string& text : args.points) {
    absl::StatusOr<Eigen::Vector3d> p = ParsePoint(text);
    if (!p.ok()) return FailUsage(cli, std::string(p.status().message()));
    pb::Vec3* v = request.add_points();
    v->set_x(p->x());
    v->set_y(p->y());
    v->set_z(p->z());
  }
  auto stub = pb::MapService::NewStub(cli.Channel());
  pb::QueryMapResponse response;
  if (!CallRpc(cli, "QueryMap", *stub, &pb::MapService::Stub::QueryMap, request, &response)) return;
  if (args.json) {
    std::printf("%s\n", MessageToJson(response).c_str());
    return;
  }
  std::printf("%-24s %-26s %8s %8s %8s %8s %7s %7s\n", "query", "surface point", "dist_mm", "mu", "mu_std",
              "sigma", "a1", "a2");
  for (int i = 0; i < response.values_size(); ++i) {
    const pb::MapValue& v = response.values(i);
    const std::string query = i < static_cast<int>(args.points.size()) ? args.points[i] : "?";
    std::printf("%-24s %8.2f %8.2f %8.2f %8.3f %8.4f %8.4f %8.4f %7.3f %7.3f\n", query.c_str(),
                Shown(v.surface_point().x(), 2), Shown(v.surface_point().y(), 2), Shown(v.surface_point().z(), 2),
                Shown(v.distance_mm(), 3), Shown(v.mu(), 4), Shown(v.mu_uncertainty(), 4), Shown(v.sigma(), 4),
                Shown(v.a1(), 3), Shown(v.a2(), 3));
  }
}

struct SimulateDragArgs {
  int64_t job_id = 0;
  std::string at;
  std::string direction;
  double length_mm = 20.0;
  double speed_mm_s = 10.0;
  double normal_force_n = 5.0;
  double sample_rate_hz = 100.0;
  double pause_s = 0.5;
  int level = -1;
  uint64_t seed = 1;
  std::string output;
};

// A drag over the job's model (SimulateDrag), written as a drag-trace CSV
// that `surfmap fit` and plotting scripts read like a measured trace.
void RunSimulateDrag(RemoteCli& cli, const SimulateDragArgs& args) {
  absl::StatusOr<Eigen::Vector3d> at = ParsePoint(args.at);
  if (!at.ok()) return FailUsage(cli, absl::StrCat("--at: ", at.status().message()));
  absl::StatusOr<Eigen::Vector3d> direction = ParsePoint(args.direction);
  if (!direction.ok()) return FailUsage(cli, absl::StrCat("--direction: ", direction.status().message()));
  pb::SimulateDragRequest request;
  request.set_job_id(args.job_id);
  for (auto [v, out] : {std::pair{*at, request.mutable_position()}, std::pair{*direction, request.mutable_direction()}}) {
    out->set_x(v.x());
    out->set_y(v.y());
    out->set_z(v.z());
  }
  request.set_length_mm(args.length_mm);
  request.set_speed_mm_s(args.speed_mm_s);
  request.set_normal_force_n(args.normal_force_n);
  request.set_sample_rate_hz(args.sample_rate_hz);
  request.set_pause_s(args.pause_s);
  if (args.level >= 0) request.set_level(args.level);
  request.set_seed(args.seed);
  auto stub = pb::MapService::NewStub(cli.Channel());
  pb::SimulateDragResponse response;
  if (!CallRpc(cli, "SimulateDrag", *stub, &pb::MapService::Stub::SimulateDrag, request, &response)) return;
  absl::StatusOr<DragTrace> trace = DragTraceFromProto(response.samples());
  if (!trace.ok()) return FailUsage(cli, absl::StrCat("SimulateDrag: ", trace.status().message()));
  const std::string csv =
      absl::StrCat("# surfmap map simulate-drag: job ", args.job_id, " level ", response.level(), ", the model (map) ",
                   "rendered at ", args.speed_mm_s, " mm/s, ", args.normal_force_n, " N, grid ", response.grid_step_mm(),
                   " mm, seed ", args.seed, "\n", FormatTraceCsv(*trace));
  if (args.output.empty() || args.output == "-") {
    std::fwrite(csv.data(), 1, csv.size(), stdout);
    return;
  }
  if (!WriteFileAtomically(cli, args.output, csv)) return;
  std::printf("%s: %zu samples over the model of job %lld (level %d)\n", args.output.c_str(), trace->samples.size(),
              static_cast<long long>(args.job_id), response.level());
}

}  // namespace

// (absl::string_view is not std::string_view in this abseil build: work on std::string copies.)
absl::StatusOr<Eigen::Vector3d> ParsePoint(std::string_view text_view) {
  const std::string text(text_view);
  std::vector<std::string> parts = absl::StrSplit(text, ',');
  Eigen::Vector3d p;
  if (parts.size() != 3) {
    return absl::InvalidArgumentError(absl::StrCat("'", text, "': expected X,Y,Z (three numbers)"));
  }
  for (int k = 0; k < 3; ++k) {
    if (!absl::SimpleAtod(absl::StripAsciiWhitespace(parts[k]), &p[k]) || !std::isfinite(p[k])) {
      return absl::InvalidArgumentError(absl::StrCat("'", text, "': coordinate ", k + 1, " is not a finite number"));
    }
  }
  return p;
}

absl::StatusOr<std::string> ResolveMapFormat(std::string_view format_view, std::string_view output_view) {
  const std::string format(format_view), output_path(output_view);
  std::string f = absl::AsciiStrToLower(format);
  if (f.empty()) {
    f = absl::AsciiStrToLower(std::filesystem::path(output_path).extension().string());
    if (!f.empty() && f[0] == '.') f.erase(0, 1);
    // "x.texture.json" is the texture model, any other ".json" the map file.
    if (f == "json" && absl::EndsWith(absl::AsciiStrToLower(output_path), ".texture.json")) f = "texture-json";
    if (f != "json" && f != "png" && f != "ply" && f != "gltf" && f != "glb" && f != "texture-json") {
      return absl::InvalidArgumentError(absl::StrCat("map get: cannot tell the format from '", output_path,
                                                     "': use --format json|png|ply|gltf|glb|texture-json"));
    }
  }
  if (f != "json" && f != "png" && f != "ply" && f != "gltf" && f != "glb" && f != "texture-json") {
    return absl::InvalidArgumentError(
        absl::StrCat("map get: unknown format '", format, "' (json, png, ply, gltf, glb or texture-json)"));
  }
  return f;
}

void AddMapCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli) {
  CLI::App* map = app.add_subcommand("map", "The friction/roughness map of a job: get, regions, query, simulate-drag");
  map->require_subcommand(1);

  auto g = std::make_shared<MapGetArgs>();
  CLI::App* get = map->add_subcommand("get", "Write a job's map as JSON, PNG, PLY, glTF/GLB or a texture model");
  get->add_option("job", g->job_id, "Job id")->required();
  get->add_option("--format", g->format,
                  "json, png, ply, gltf, glb or texture-json (default: from the -o extension; "
                  "*.texture.json = texture-json)");
  get->add_option("--quantity", g->quantity,
                  "png: what to colour by: mu, mu_std, sigma, a1, a2, region, boundary_probability")
      ->capture_default_str();
  get->add_option("-o,--output", g->output, "Output file")->required();
  get->add_option("--level", g->level, "Subdivision level (-1 = the job's finest)")->capture_default_str();
  get->add_option("--view", g->view, "png: the direction the first camera looks, X,Y,Z")->capture_default_str();
  get->add_flag("--one-view", g->one_view, "png: only the first view (default: also from the opposite side)");
  get->add_option("--color-map", g->color_map, "png: grey (whiter = more friction) or viridis")
      ->capture_default_str();
  get->add_option("--width", g->width, "png: pixels per view")->check(CLI::Range(16, 8192))->capture_default_str();
  get->add_option("--mu-range", g->mu_range, "png: colour scale LO HI of the quantity (default: its range)")
      ->expected(2);
  get->callback([cli, g] { RunMapGet(*cli, *g); });

  AddMapRegionsCommand(*map, cli);

  auto d = std::make_shared<SimulateDragArgs>();
  CLI::App* drag = map->add_subcommand(
      "simulate-drag", "Render a drag over the job's model (its map) as a drag-trace CSV, to compare with a measured one");
  drag->add_option("job", d->job_id, "Job id")->required();
  drag->add_option("--at", d->at, "Start X,Y,Z in mm (projected onto the surface; within 2 mm)")->required();
  drag->add_option("--direction", d->direction, "Drag direction X,Y,Z (projected onto the tangent plane)")->required();
  drag->add_option("--length", d->length_mm, "Drag length, mm")->capture_default_str();
  drag->add_option("--speed", d->speed_mm_s, "Sliding speed, mm/s")->capture_default_str();
  drag->add_option("--force", d->normal_force_n, "Normal force, N")->capture_default_str();
  drag->add_option("--rate", d->sample_rate_hz, "Sample rate, Hz")->capture_default_str();
  drag->add_option("--pause", d->pause_s, "Pause between the passes, s")->capture_default_str();
  drag->add_option("--level", d->level, "Map level (-1 = the finest)")->capture_default_str();
  drag->add_option("--seed", d->seed, "Texture realisation")->capture_default_str();
  drag->add_option("-o,--output", d->output, "Output CSV file (default: stdout)");
  drag->callback([cli, d] { RunSimulateDrag(*cli, *d); });

  auto q = std::make_shared<MapQueryArgs>();
  CLI::App* query = map->add_subcommand("query", "The map at points (projected onto the surface)");
  query->add_option("job", q->job_id, "Job id")->required();
  query->add_option("points", q->points, "Points X,Y,Z in mm")->required();
  query->add_flag("--json", q->json, "Print the response as JSON");
  query->callback([cli, q] { RunMapQuery(*cli, *q); });
}

void AddTraceCommands(CLI::App& app, std::shared_ptr<RemoteCli> cli) {
  auto sample_id = std::make_shared<int64_t>(0);
  auto fit_version = std::make_shared<int>(0);
  CLI::App* sample = app.add_subcommand("sample", "Fitted samples: get");
  sample->require_subcommand(1);
  CLI::App* sample_get = sample->add_subcommand("get", "A sample (site, position, fit) as JSON");
  sample_get->add_option("trace_id", *sample_id, "Trace id")->required();
  sample_get->add_option("--fit-version", *fit_version, "Fit version (0 = latest)");
  sample_get->callback([cli, sample_id, fit_version] {
    auto stub = pb::MapService::NewStub(cli->Channel());
    pb::GetSampleRequest request;
    request.set_trace_id(*sample_id);
    request.set_fit_version(*fit_version);
    pb::GetSampleResponse response;
    if (!CallRpc(*cli, "GetSample", *stub, &pb::MapService::Stub::GetSample, request, &response)) return;
    std::printf("%s\n", MessageToJson(response.sample()).c_str());
  });

  auto trace_id = std::make_shared<int64_t>(0);
  auto trace_out = std::make_shared<std::string>();
  CLI::App* trace = app.add_subcommand("trace", "Raw drag traces: get");
  trace->require_subcommand(1);
  CLI::App* trace_get = trace->add_subcommand("get", "A raw trace as CSV (t,x,y,z,fx,fy,fz,phase)");
  trace_get->add_option("trace_id", *trace_id, "Trace id")->required();
  trace_get->add_option("-o,--output", *trace_out, "Output CSV file (default: stdout)");
  trace_get->callback([cli, trace_id, trace_out] {
    auto stub = pb::TraceService::NewStub(cli->Channel());
    pb::GetTraceRequest request;
    request.set_trace_id(*trace_id);
    pb::GetTraceResponse response;
    if (!CallRpc(*cli, "GetTrace", *stub, &pb::TraceService::Stub::GetTrace, request, &response)) return;
    absl::StatusOr<DragTrace> trace = DragTraceFromProto(response.samples());
    if (!trace.ok()) return FailUsage(*cli, absl::StrCat("trace ", *trace_id, ": ", trace.status().message()));
    const std::string csv = absl::StrCat("# surfmap trace ", response.trace_id(), " (command ", response.command_id(),
                                         ", job ", response.job_id(), ")\n", FormatTraceCsv(*trace));
    if (trace_out->empty()) {
      std::fwrite(csv.data(), 1, csv.size(), stdout);
    } else {
      std::ofstream out(*trace_out, std::ios::binary | std::ios::trunc);
      out << csv;
      out.close();
      if (!out) return FailUsage(*cli, *trace_out + ": cannot write file");
    }
  });

  struct RefitArgs {
    int64_t job_id = 0;
    std::string method = "burg";
    int order = 2;
    double step_mm = 0.1;
    bool no_noise_correction = false;
  };
  auto r = std::make_shared<RefitArgs>();
  CLI::App* refit = app.add_subcommand("refit", "Re-estimate every trace of a job with other estimator settings");
  refit->add_option("job", r->job_id, "Job id")->required();
  refit->add_option("--method", r->method, "AR estimator")->check(CLI::IsMember({"burg", "ls"}))->capture_default_str();
  refit->add_option("--order", r->order, "AR model order p")->check(CLI::Range(1, 20))->capture_default_str();
  refit->add_option("--step-mm", r->step_mm, "Roughness arc-length grid step L in mm")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  refit->add_flag("--no-noise-correction", r->no_noise_correction,
                  "Do not use the pause's noise floor to de-bias the roughness fit");
  refit->callback([cli, r] {
    auto stub = pb::TraceService::NewStub(cli->Channel());
    pb::RefitJobRequest request;
    request.set_job_id(r->job_id);
    pb::EstimatorSettings* s = request.mutable_settings();
    s->set_step_mm(r->step_mm);
    s->set_ar_order(r->order);
    s->set_ar_method(r->method == "ls" ? pb::AR_METHOD_LEAST_SQUARES : pb::AR_METHOD_BURG);
    s->set_noise_aware(!r->no_noise_correction);
    pb::RefitJobResponse response;
    if (!CallRpc(*cli, "RefitJob", *stub, &pb::TraceService::Stub::RefitJob, request, &response)) return;
    std::printf("job %lld: fit version %d, %d traces refitted, %d failed\n", static_cast<long long>(r->job_id),
                response.fit_version(), response.refitted(), response.failed());
  });
}

}  // namespace surfmap::cli
