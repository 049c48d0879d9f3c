// surfmap-simtrace: simulates one drag and writes its trace as CSV to stdout,
// with '#' comment lines stating the shape, material(s), options and seed.
//
//   surfmap-simtrace --shape cylinder --material masonite --seed 3 > trace.csv
//   surfmap-simtrace --shape plane --material glass --boundary sandpaper ...
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "CLI/CLI.hpp"
#include "clients/sim/dragsim/drag_simulator.h"
#include "server/estimate/trace_csv.h"

namespace {

const std::map<std::string, surfmap::Material>& Materials() {
  static const std::map<std::string, surfmap::Material> materials = {
      {"glass", surfmap::kGlass},
      {"rubber", surfmap::kRubber},
      {"masonite", surfmap::kMasonite},
      {"sandpaper", surfmap::kSandpaper}};
  return materials;
}

std::string Describe(const std::string& name, const surfmap::Material& m) {
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%s (mu %.3f, a1 %.2f, a2 %.2f, sigma %.3f N)", name.c_str(),
                m.mu, m.a1, m.a2, m.sigma);
  return buffer;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Simulate one drag measurement and write its trace as CSV to stdout"};
  std::string shape = "plane";
  std::string material_name = "glass";
  std::string boundary_name;
  double tilt_deg = 23.0, radius_mm = 40.0, polar_deg = 45.0;
  surfmap::DragSimOptions options;
  bool ideal = false;
  double disturbance = 1.0;
  double position_noise_mm = -1.0;
  app.add_option("--shape", shape, "plane | cylinder | sphere")
      ->check(CLI::IsMember({"plane", "cylinder", "sphere"}));
  app.add_option("--material", material_name, "glass | rubber | masonite | sandpaper")
      ->check(CLI::IsMember({"glass", "rubber", "masonite", "sandpaper"}));
  app.add_option("--boundary", boundary_name,
                 "second material beyond the middle of the path (a region boundary)")
      ->check(CLI::IsMember({"glass", "rubber", "masonite", "sandpaper"}));
  app.add_option("--tilt", tilt_deg, "plane tilt about y, degrees");
  app.add_option("--radius", radius_mm, "cylinder / sphere radius, mm");
  app.add_option("--polar", polar_deg, "sphere: polar angle of the latitude circle, degrees");
  app.add_option("--seed", options.seed, "random seed");
  app.add_option("--length", options.length_mm, "drag length, mm");
  app.add_option("--speed", options.speed_mm_s, "drag speed, mm/s");
  app.add_option("--force", options.normal_force_n, "commanded normal force, N");
  app.add_option("--rate", options.sample_rate_hz, "sample rate, Hz (1 to 100000: the samples are allocated at once)")
      ->check(CLI::Range(1.0, 100000.0));
  app.add_option("--disturbance", disturbance,
                 "every disturbance amplitude times this (DragSimOptions::WithDisturbancesScaled)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--position-noise", position_noise_mm,
                 "Gaussian position noise per axis, mm, after --disturbance (default: the rig's, scaled)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--ideal", ideal, "switch every disturbance off");
  // One disturbance alone (the others off), to measure what each does to a
  // fit: the rig's amplitude of it, times --disturbance.
  const std::map<std::string, double surfmap::DragSimOptions::*> kDisturbances = {
      {"speed-jitter", &surfmap::DragSimOptions::speed_jitter},
      {"contact-overshoot", &surfmap::DragSimOptions::contact_overshoot},
      {"force-tracking", &surfmap::DragSimOptions::force_tracking_error},
      {"vibration", &surfmap::DragSimOptions::vibration_n},
      {"stick-slip", &surfmap::DragSimOptions::stick_slip},
      {"pause-residual", &surfmap::DragSimOptions::pause_residual},
      {"force-noise", &surfmap::DragSimOptions::force_noise_n},
      {"position-noise", &surfmap::DragSimOptions::position_noise_mm}};
  std::string only;
  std::vector<std::string> disturbance_names;
  for (const auto& [name, member] : kDisturbances) disturbance_names.push_back(name);
  app.add_option("--only", only,
                 "switch every disturbance off but this one, at the rig's amplitude times --disturbance "
                 "(after --position-noise)")
      ->check(CLI::IsMember(disturbance_names))
      ->excludes("--ideal");
  CLI11_PARSE(app, argc, argv);
  options = options.WithDisturbancesScaled(disturbance);
  if (position_noise_mm >= 0.0) options.position_noise_mm = position_noise_mm;
  if (ideal || !only.empty()) {
    // An ideal rig running this drag (seed, length, speed, force, rate),
    // with the one disturbance of --only at its amplitude.
    surfmap::DragSimOptions quiet = surfmap::DragSimOptions::Ideal();
    quiet.seed = options.seed;
    quiet.length_mm = options.length_mm;
    quiet.speed_mm_s = options.speed_mm_s;
    quiet.normal_force_n = options.normal_force_n;
    quiet.sample_rate_hz = options.sample_rate_hz;
    if (!only.empty()) {
      const auto member = kDisturbances.at(only);
      quiet.*member = options.*member;
    }
    options = quiet;
  }

  const double geometry_length = options.length_mm;
  surfmap::DragGeometry geometry;
  if (shape == "plane") {
    geometry = surfmap::TiltedPlaneGeometry(tilt_deg, geometry_length);
  } else if (shape == "cylinder") {
    geometry = surfmap::CylinderGeometry(radius_mm, geometry_length);
  } else {
    geometry = surfmap::SphereGeometry(radius_mm, polar_deg, geometry_length);
  }
  const surfmap::Material material = Materials().at(material_name);
  surfmap::MaterialField field = surfmap::UniformMaterial(material);
  if (!boundary_name.empty()) {
    // Boundary perpendicular to the path through its midpoint.
    const std::size_t mid = geometry.points.size() / 2;
    const Eigen::Vector3d direction = geometry.points[mid + 1] - geometry.points[mid - 1];
    field = surfmap::SplitMaterial(material, Materials().at(boundary_name), geometry.points[mid],
                                   direction);
  }
  const absl::StatusOr<surfmap::DragSimResult> result =
      surfmap::SimulateDrag(geometry, field, options);
  if (!result.ok()) {
    std::cerr << "surfmap-simtrace: " << result.status().message() << "\n";
    return 1;
  }
  std::cout << "# surfmap-simtrace --shape " << shape;
  if (shape == "plane") std::cout << " --tilt " << tilt_deg;
  if (shape != "plane") std::cout << " --radius " << radius_mm;
  if (shape == "sphere") std::cout << " --polar " << polar_deg;
  std::cout << " --material " << material_name;
  if (!boundary_name.empty()) std::cout << " --boundary " << boundary_name;
  std::cout << " --seed " << options.seed << " --length " << options.length_mm << " --speed "
            << options.speed_mm_s << " --force " << options.normal_force_n << " --rate "
            << options.sample_rate_hz << " --disturbance " << disturbance << (ideal ? " --ideal" : "") << "\n";
  std::cout << "# material: " << Describe(material_name, material) << "\n";
  if (!boundary_name.empty()) {
    std::cout << "# beyond the middle of the path: "
              << Describe(boundary_name, Materials().at(boundary_name)) << "\n";
  }
  std::cout << surfmap::FormatTraceCsv(result->trace);
  return 0;
}
