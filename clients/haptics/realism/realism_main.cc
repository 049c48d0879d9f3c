// surfmap-realism [--scene NAME ...|all] [--drags N] [--seed S]: the realism
// figure (realism.h): per scene and material, drags over the truth vs over
// the mapped model vs over a model with its materials swapped. Prints a
// markdown table (the README's) and one summary line per scene.
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include "clients/haptics/realism/realism.h"

int main(int argc, char** argv) {
  CLI::App app{"surfmap-realism: does the mapped model feel like the object? (truth vs model vs wrong model)"};
  std::vector<std::string> scenes = {"bottle"};
  surfmap::haptics::RealismOptions options;
  app.add_option("--scene", scenes, "scene names or 'all'")->capture_default_str();
  app.add_option("--drags", options.drags_per_material, "test drags per material")->capture_default_str();
  app.add_option("--seed", options.seed, "mapping job, sites and directions")->capture_default_str();
  app.add_option("--budget", options.map_budget, "mapping job's sample budget (0: default)")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (scenes.size() == 1 && scenes[0] == "all") {
    scenes = {"bottle", "plate", "banded_vase", "strip_block", "dotted_egg", "torus_handle"};
  }
  std::vector<surfmap::haptics::SceneRealism> results;
  for (const std::string& name : scenes) {
    absl::StatusOr<surfmap::haptics::SceneRealism> r = surfmap::haptics::RunRealism(name, options);
    if (!r.ok()) {
      std::fprintf(stderr, "%s: %s\n", name.c_str(), std::string(r.status().message()).c_str());
      return 1;
    }
    std::fprintf(stderr, "%s: %d mapping drags, %d regions, %d test drags, %.1f s\n", name.c_str(), r->map_samples,
                 r->regions, r->test_drags, r->elapsed_s);
    for (const std::string& line : r->region_summary) std::fprintf(stderr, "  %s\n", line.c_str());
    results.push_back(*std::move(r));
  }
  std::printf("%s", surfmap::haptics::RealismTable(results).c_str());
  return 0;
}
