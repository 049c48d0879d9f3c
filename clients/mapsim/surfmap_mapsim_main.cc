// surfmap-mapsim: maps a scene entirely in-process (simulated rig -> FitTrace
// -> sampling plan -> friction map) and scores the map against the scene's
// truth. `--mode all` compares the sampling strategies at adaptive's sample
// count. Without flags a scene runs with its tuned defaults (below).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include "absl/strings/str_format.h"
#include "clients/mapsim/mapping_report.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/rig/scene.h"

namespace surfmap::mapsim {
namespace {

// Tuned per built-in scene by sweeping finest 2..3 and threshold 1..4 (seed 1).
struct SceneDefaults {
  int coarsest = 0;
  int finest = 2;
  double threshold = 2.0;
};

SceneDefaults DefaultsFor(const std::string& scene) {
  if (scene == "bottle") return {0, 1, 4.0};  // 100 samples, 99.7 % classified (L0 alone is 82)
  if (scene == "plate") return {0, 2, 1.0};   // 254 samples, 93 % classified
  return {};
}

bool WriteFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  out.close();
  if (!out) {
    std::fprintf(stderr, "error: cannot write %s\n", path.c_str());
    return false;
  }
  return true;
}

// "out.png" -> "out-adaptive.png" when several runs write files.
std::string PathFor(const std::string& path, const MappingRunResult& run, bool several) {
  if (!several) return path;
  std::filesystem::path p(path);
  return (p.parent_path() / (p.stem().string() + "-" + std::string(SamplingModeName(run.options.mode)) +
                             p.extension().string()))
      .string();
}

// The level in coarsest..finest whose vertex count is nearest `count`.
int NearestLevel(const MappingBench& bench, int coarsest, int count) {
  int best = coarsest;
  for (int k = coarsest; k <= bench.finest_level(); ++k) {
    const int n = static_cast<int>(bench.rig().surface().level(k).limit_positions.size());
    const int best_n = static_cast<int>(bench.rig().surface().level(best).limit_positions.size());
    if (std::abs(n - count) < std::abs(best_n - count)) best = k;
  }
  return best;
}

int Main(int argc, char** argv) {
  CLI::App app{"surfmap-mapsim: map a scene in-process with the simulated rig and score the map against its truth"};
  std::string scene_name = "bottle";
  std::string mode = "adaptive";
  int coarsest = 0, finest = 2, budget = 0;
  double threshold = 2.0;
  std::uint64_t seed = 1;
  std::string property = "friction";
  std::string png, ply, json_path;
  int rig_level = 3;
  app.add_option("--scene", scene_name, "scene name (clients/scenes, $SURFMAP_SCENES)")->capture_default_str();
  app.add_option("--mode", mode, "adaptive | uniform | uncertainty | uniform-spread | all")
      ->check(CLI::IsMember({"adaptive", "uniform", "uncertainty", "uniform-spread", "all"}))
      ->capture_default_str();
  auto* coarsest_opt = app.add_option("--coarsest", coarsest, "coarsest level (default: per scene)");
  auto* finest_opt = app.add_option("--finest", finest, "finest level: refinement limit and map level (default: per scene)");
  auto* threshold_opt = app.add_option("--threshold", threshold, "adaptive: refine where the texture distance exceeds this (default: per scene)");
  app.add_option("--budget", budget, "sample budget (uncertainty, uniform-spread; with --mode all: from adaptive)");
  app.add_option("--seed", seed, "plan order and rig noise")->capture_default_str();
  app.add_option("--property", property, "what the texture distance compares: friction | roughness | both")
      ->check(CLI::IsMember({"friction", "roughness", "both"}))
      ->capture_default_str();
  app.add_option("--rig-level", rig_level, "Loop level of the simulated rig's surface (at least --finest)")
      ->capture_default_str();
  app.add_option("--png", png, "map image (grey scale, samples and drag paths); with --mode all one per mode");
  app.add_option("--ply", ply, "map as PLY; with --mode all one per mode");
  app.add_option("--json", json_path, "metrics and probes as JSON");
  CLI11_PARSE(app, argc, argv);

  const SceneDefaults defaults = DefaultsFor(scene_name);
  if (!coarsest_opt->count()) coarsest = defaults.coarsest;
  if (!finest_opt->count()) finest = defaults.finest;
  if (!threshold_opt->count()) threshold = defaults.threshold;

  absl::StatusOr<Scene> scene = LoadSceneByName(scene_name);
  if (!scene.ok()) {
    std::fprintf(stderr, "error: %s\n", std::string(scene.status().message()).c_str());
    return 1;
  }
  absl::StatusOr<std::unique_ptr<MappingBench>> bench = MappingBench::Create(*std::move(scene), finest, seed, rig_level);
  if (!bench.ok()) {
    std::fprintf(stderr, "error: %s\n", std::string(bench.status().message()).c_str());
    return 1;
  }

  MappingRunOptions base;
  base.coarsest_level = coarsest;
  base.finest_level = finest;
  base.threshold = threshold;
  base.sample_budget = budget;
  base.seed = seed;
  base.property = property == "roughness" ? TextureProperty::kRoughness
                  : property == "both"    ? TextureProperty::kBoth
                                          : TextureProperty::kFriction;

  std::vector<MappingRunResult> runs;
  auto run = [&](MappingRunOptions options) -> bool {
    absl::StatusOr<MappingRunResult> result = RunMapping(**bench, options);
    if (!result.ok()) {
      std::fprintf(stderr, "error: %s run: %s\n", std::string(SamplingModeName(options.mode)).c_str(),
                   std::string(result.status().message()).c_str());
      return false;
    }
    runs.push_back(*std::move(result));
    return true;
  };
  if (mode == "all") {
    MappingRunOptions adaptive = base;
    adaptive.mode = SamplingMode::kAdaptive;
    adaptive.sample_budget = 0;
    if (!run(adaptive)) return 1;
    int measured = 0;
    for (const ProbeRecord& p : runs.front().probes) measured += p.measured;
    MappingRunOptions uncertainty = base;
    uncertainty.mode = SamplingMode::kUncertainty;
    uncertainty.sample_budget = measured;
    MappingRunOptions uniform = base;
    uniform.mode = SamplingMode::kUniformLevel;
    uniform.coarsest_level = NearestLevel(**bench, 0, measured);
    uniform.sample_budget = 0;
    MappingRunOptions spread = base;
    spread.mode = SamplingMode::kUniformSpread;
    spread.sample_budget = measured;
    if (!run(uncertainty) || !run(uniform) || !run(spread)) return 1;
  } else {
    MappingRunOptions options = base;
    options.mode = mode == "uniform"       ? SamplingMode::kUniformLevel
                   : mode == "uncertainty" ? SamplingMode::kUncertainty
                   : mode == "uniform-spread" ? SamplingMode::kUniformSpread
                                              : SamplingMode::kAdaptive;
    if (!run(options)) return 1;
  }

  std::printf("scene %s: finest level %d, %d vertices\n", (*bench)->scene().name.c_str(), finest,
              runs.front().evaluation.vertices);
  std::printf("%s", FormatComparisonTable(runs).c_str());

  const bool several = runs.size() > 1;
  nlohmann::json all = nlohmann::json::array();
  for (const MappingRunResult& r : runs) {
    all.push_back(RunToJson(r));
    if (!png.empty()) {
      absl::StatusOr<std::string> bytes = RunPng(**bench, r);
      if (!bytes.ok()) {
        std::fprintf(stderr, "error: png: %s\n", std::string(bytes.status().message()).c_str());
        return 1;
      }
      if (!WriteFile(PathFor(png, r, several), *bytes)) return 1;
    }
    if (!ply.empty()) {
      absl::StatusOr<std::string> text = RunPly(**bench, r);
      if (!text.ok()) {
        std::fprintf(stderr, "error: ply: %s\n", std::string(text.status().message()).c_str());
        return 1;
      }
      if (!WriteFile(PathFor(ply, r, several), *text)) return 1;
    }
  }
  if (!json_path.empty()) {
    nlohmann::json doc = {{"scene", (*bench)->scene().name}, {"runs", all}};
    if (!WriteFile(json_path, doc.dump(2) + "\n")) return 1;
  }
  return 0;
}

}  // namespace
}  // namespace surfmap::mapsim

int main(int argc, char** argv) { return surfmap::mapsim::Main(argc, argv); }
