// Test support for the plan tests (header-only, not part of the library): a
// two-material plate and a driver that answers probe commands with fits
// synthesised from the truth at the site.
#pragma once

#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include "server/map/testing/flat_grid_levels.h"
#include "server/plan/sampling_plan.h"
#include "server/plan/site_order.h"

namespace surfmap::testing {

// Left of x = 0: glass-like (mu 0.13), right: sandpaper-like (mu 0.5).
inline double TruthMu(const Eigen::Vector3d& p) { return p.x() < 0.0 ? 0.13 : 0.5; }

// The plate: 9 x 5 coarse cells of 100/9 mm over x in [-47, 53], levels 0..3
// ((9*2^k + 1) x (5*2^k + 1) vertices at level k: 60, 209, 777, 2993). The
// 3 mm offset keeps the boundary x = 0 off the vertices of every level, so no
// level is favoured by a lucky alignment.
inline std::vector<SurfaceLevel> TwoMaterialPlate(int max_level = 3) {
  return MakeFlatGridLevels(9, 5, 100.0 / 9.0, max_level, -47.0, 0.0);
}

// A fit of the truth at `position` with noise seeded by the vertex (so the
// answer for a site does not depend on the order in which sites are measured).
inline TextureParams SynthesiseFit(const Eigen::Vector3d& position, int vertex, double mu_noise = 0.005) {
  std::mt19937_64 rng(SiteShuffleKey(12345, vertex));
  std::normal_distribution<double> noise(0.0, mu_noise);
  TextureParams fit;
  fit.mu = TruthMu(position) + noise(rng);
  fit.mu_std = mu_noise;
  fit.reflection = {0.6, -0.25};
  fit.sigma = 0.11;
  return fit;
}

struct IssuedRecord {
  std::uint64_t sequence;
  SiteId site;
  int attempt;
  bool operator==(const IssuedRecord&) const = default;
};

// Runs a plan with `rigs` commands outstanding at most, answering the oldest
// first, until it issues nothing more or `max_answers` answers were given.
// `outstanding` carries the rigs' queue across calls (for save/restore tests).
inline std::vector<IssuedRecord> Drive(SamplingPlan& plan, const SurfaceLevel& finest, int rigs,
                                       std::deque<ProbeCommand>& outstanding, int max_answers = 1 << 30) {
  std::vector<IssuedRecord> issued;
  int answers = 0;
  while (answers < max_answers) {
    while (static_cast<int>(outstanding.size()) < rigs) {
      auto command = plan.NextCommand();
      if (!command) break;
      issued.push_back({command->sequence, command->site, command->attempt});
      outstanding.push_back(*command);
    }
    if (outstanding.empty()) break;
    const ProbeCommand c = outstanding.front();
    outstanding.pop_front();
    const auto status =
        plan.RecordFit(c.sequence, SynthesiseFit(finest.limit_positions[c.site.vertex], c.site.vertex));
    if (!status.ok()) ADD_FAILURE() << status;
    ++answers;
  }
  return issued;
}

inline std::vector<IssuedRecord> DriveToEnd(SamplingPlan& plan, const SurfaceLevel& finest, int rigs = 1) {
  std::deque<ProbeCommand> outstanding;
  return Drive(plan, finest, rigs, outstanding);
}

}  // namespace surfmap::testing
