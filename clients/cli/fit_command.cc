#include "clients/cli/fit_command.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>
#include "clients/cli/number_text.h"
#include "server/codec/fit_json.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/trace_csv.h"

namespace surfmap::cli {
namespace {

struct FitArgs {
  std::vector<std::string> files;
  bool json = false;
  bool series = false;
  double step_mm = 0.1;
  int order = 2;
  std::string method = "burg";
  bool no_noise_correction = false;
  double series_normal_mm = FitOptions{}.series.halfwidth_mm;
  bool series_follow_samples = FitOptions{}.series.follow_samples;
};

// "-" is standard input (named "stdin" in messages), as in most Unix tools.
constexpr std::string_view kStdinName = "stdin";

std::string_view DisplayName(const std::string& path) { return path == "-" ? kStdinName : std::string_view(path); }

absl::StatusOr<std::string> ReadWholeFile(const std::string& path) {
  if (path == "-") {
    std::ostringstream buffer;
    buffer << std::cin.rdbuf();
    if (std::cin.bad()) return absl::DataLossError("stdin: read error");
    return buffer.str();
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return absl::NotFoundError(path + ": cannot open file");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return absl::DataLossError(path + ": read error");
  return buffer.str();
}

absl::StatusOr<TraceFit> FitFile(const std::string& path, const FitOptions& options) {
  absl::StatusOr<std::string> text = ReadWholeFile(path);
  if (!text.ok()) return text.status();
  const std::string name(DisplayName(path));
  absl::StatusOr<DragTrace> trace = ParseTraceCsv(*text, name);
  if (!trace.ok()) return trace.status();
  absl::StatusOr<TraceFit> fit = FitTrace(*trace, options);
  if (!fit.ok()) return absl::Status(fit.status().code(), name + ": " + std::string(fit.status().message()));
  return fit;
}

// The file column is as wide as the longest name (at least 4): names are
// shown whole, never cut, since the start of a path is often what tells two
// traces apart.
int FileColumnWidth(const std::vector<std::string>& files) {
  std::size_t width = 4;
  for (const std::string& f : files) width = std::max(width, DisplayName(f).size());
  return static_cast<int>(width);
}

void PrintTableHeader(int file_width) {
  std::printf("%-*s %7s %7s %7s %5s %13s %7s %7s %7s %4s %7s %7s\n", file_width, "file", "mu", "std", "median", "pairs",
              "window_mm", "a1", "a2", "sigma", "stat", "acf_mm", "wave_mm");
}

void PrintTableRow(int file_width, std::string_view file, const TraceFit& fit) {
  const FrictionFit& f = fit.friction;
  const ArFit& r = fit.roughness;
  char window[32];
  std::snprintf(window, sizeof window, "%.1f-%.1f", Shown(f.window_start_mm, 1), Shown(f.window_end_mm, 1));
  char wave[16] = "-";
  if (r.dominant_wavelength_mm) std::snprintf(wave, sizeof wave, "%.2f", Shown(*r.dominant_wavelength_mm, 2));
  const std::string shown(file);
  std::printf("%-*s %7.4f %7.4f %7.4f %5d %13s %7.3f %7.3f %7.4f %4s %7.2f %7s%s\n", file_width, shown.c_str(),
              Shown(f.mu, 4), Shown(f.mu_std, 4), Shown(f.mu_median, 4), f.n_pairs, window,
              Shown(r.a.size() > 0 ? r.a[0] : 0.0, 3), Shown(r.a.size() > 1 ? r.a[1] : 0.0, 3), Shown(r.sigma, 4),
              r.stationary ? "yes" : "no", Shown(r.acf_decay_mm, 2), wave,
              r.below_noise_floor ? "  (below noise floor)" : "");
}

int RunFit(const FitArgs& args) {
  FitOptions options;
  options.step_mm = args.step_mm;
  options.ar_order = args.order;
  options.ar_method = args.method == "ls" ? ArMethod::kLeastSquares : ArMethod::kBurg;
  options.noise_aware = !args.no_noise_correction;
  options.series.halfwidth_mm = args.series_normal_mm;
  options.series.follow_samples = args.series_follow_samples;
  std::string why;
  if (!options.IsValid(&why)) {
    std::cerr << "surfmap fit: invalid options: " << why << "\n";
    return 2;
  }
  int failures = 0;
  const int file_width = FileColumnWidth(args.files);
  if (!args.json) PrintTableHeader(file_width);
  for (const std::string& path : args.files) {
    absl::StatusOr<TraceFit> fit = FitFile(path, options);
    if (args.json) {
      nlohmann::json line = fit.ok() ? TraceFitToJson(*fit, args.series) : nlohmann::json::object();
      line["file"] = std::string(DisplayName(path));
      if (!fit.ok()) line["error"] = std::string(fit.status().message());
      std::cout << line.dump() << "\n";
    } else if (fit.ok()) {
      PrintTableRow(file_width, DisplayName(path), *fit);
    } else {
      std::fflush(stdout);
      std::cerr << "error: " << fit.status().message() << "\n";
    }
    if (!fit.ok()) ++failures;
  }
  std::cout.flush();
  return failures == 0 ? 0 : 1;
}

}  // namespace

void AddFitCommand(CLI::App& app, int* exit_code) {
  auto args = std::make_shared<FitArgs>();
  CLI::App* fit = app.add_subcommand("fit", "Fit friction and roughness to drag-trace CSV files (offline)");
  fit->add_option("traces", args->files, "Drag trace CSV files (t,x,y,z,fx,fy,fz,phase); - reads standard input")
      ->required();
  // --help shows each option's default (set after the positional, whose
  // empty default says nothing).
  fit->option_defaults()->always_capture_default();
  fit->add_flag("--json", args->json, "One JSON object per input per line (JSON Lines)");
  fit->add_flag("--series", args->series,
                "With --json: each pair's arc length and mu (pair_s_mm, pair_mu) and the roughness autocorrelation (acf)");
  fit->add_option("--step-mm", args->step_mm, "Roughness arc-length grid step L in mm")->check(CLI::PositiveNumber);
  fit->add_option("--order", args->order, "AR model order p")->check(CLI::Range(1, 20));
  fit->add_option("--method", args->method, "AR estimator")->check(CLI::IsMember({"burg", "ls"}));
  fit->add_flag("--no-noise-correction", args->no_noise_correction,
                "Do not use the pause's noise floor to de-bias the roughness fit");
  fit->add_option("--series-normal-mm", args->series_normal_mm,
                  "The roughness series reads each force against the pair normals averaged over +- this many mm "
                  "(0: each pair's own normal, estimator version 8)")
      ->check(CLI::Range(0.0, 10.0));
  fit->add_option("--series-follow-samples", args->series_follow_samples,
                  "Each pass's roughness series is its own samples one step apart (false: the nearest sample to each "
                  "point of a fixed grid, estimator version 8)");
  fit->callback([args, exit_code] { *exit_code = RunFit(*args); });
}

}  // namespace surfmap::cli
