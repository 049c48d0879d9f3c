#include "clients/cli/fit_command.h"

#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include "server/codec/fit_json.h"
#include "server/estimate/fit_trace.h"
#include "server/estimate/trace_csv.h"

namespace surfmap::cli {
namespace {

struct FitArgs {
  std::vector<std::string> files;
  bool json = false;
  double step_mm = 0.1;
  int order = 2;
  std::string method = "burg";
  bool no_noise_correction = false;
};

absl::StatusOr<std::string> ReadWholeFile(const std::string& path) {
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
  absl::StatusOr<DragTrace> trace = ParseTraceCsv(*text, path);
  if (!trace.ok()) return trace.status();
  absl::StatusOr<TraceFit> fit = FitTrace(*trace, options);
  if (!fit.ok()) return absl::Status(fit.status().code(), path + ": " + std::string(fit.status().message()));
  return fit;
}

void PrintTableHeader() {
  std::printf("%-32s %7s %7s %7s %5s %13s %7s %7s %7s %4s %7s %7s\n", "file", "mu", "std", "median", "pairs",
              "window_mm", "a1", "a2", "sigma", "stat", "acf_mm", "wave_mm");
}

void PrintTableRow(const std::string& file, const TraceFit& fit) {
  const FrictionFit& f = fit.friction;
  const ArFit& r = fit.roughness;
  char window[32];
  std::snprintf(window, sizeof window, "%.1f-%.1f", f.window_start_mm, f.window_end_mm);
  char wave[16] = "-";
  if (r.dominant_wavelength_mm) std::snprintf(wave, sizeof wave, "%.2f", *r.dominant_wavelength_mm);
  std::string shown = file.size() > 32 ? "..." + file.substr(file.size() - 29) : file;
  std::printf("%-32s %7.4f %7.4f %7.4f %5d %13s %7.3f %7.3f %7.4f %4s %7.2f %7s%s\n", shown.c_str(), f.mu, f.mu_std,
              f.mu_median, f.n_pairs, window, r.a.size() > 0 ? r.a[0] : 0.0, r.a.size() > 1 ? r.a[1] : 0.0, r.sigma,
              r.stationary ? "yes" : "no", r.acf_decay_mm, wave, r.below_noise_floor ? "  (below noise floor)" : "");
}

int RunFit(const FitArgs& args) {
  FitOptions options;
  options.step_mm = args.step_mm;
  options.ar_order = args.order;
  options.ar_method = args.method == "ls" ? ArMethod::kLeastSquares : ArMethod::kBurg;
  options.noise_aware = !args.no_noise_correction;
  std::string why;
  if (!options.IsValid(&why)) {
    std::cerr << "surfmap fit: invalid options: " << why << "\n";
    return 2;
  }
  int failures = 0;
  if (!args.json) PrintTableHeader();
  for (const std::string& path : args.files) {
    absl::StatusOr<TraceFit> fit = FitFile(path, options);
    if (args.json) {
      nlohmann::json line = fit.ok() ? TraceFitToJson(*fit) : nlohmann::json::object();
      line["file"] = path;
      if (!fit.ok()) line["error"] = std::string(fit.status().message());
      std::cout << line.dump() << "\n";
    } else if (fit.ok()) {
      PrintTableRow(path, *fit);
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
  fit->add_option("traces", args->files, "Drag trace CSV files (t,x,y,z,fx,fy,fz,phase)")->required();
  fit->add_flag("--json", args->json, "One JSON object per input per line (JSON Lines)");
  fit->add_option("--step-mm", args->step_mm, "Roughness arc-length grid step L in mm")->check(CLI::PositiveNumber);
  fit->add_option("--order", args->order, "AR model order p")->check(CLI::Range(1, 20));
  fit->add_option("--method", args->method, "AR estimator")->check(CLI::IsMember({"burg", "ls"}));
  fit->add_flag("--no-noise-correction", args->no_noise_correction,
                "Do not use the pause's noise floor to de-bias the roughness fit");
  fit->callback([args, exit_code] { *exit_code = RunFit(*args); });
}

}  // namespace surfmap::cli
