#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include "clients/mapsim/mapping_report.h"
#include "clients/mapsim/mapping_run.h"
#include "clients/sim/rig/scene.h"
#include "server/mesh/dense_surface.h"

namespace surfmap::mapsim {
namespace {

TEST(MappingRunTest, RejectsInvalidOptions) {
  MappingRunOptions o;
  o.mode = PlanMode::kUncertainty;  // needs a budget
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("sample_budget"), std::string::npos) << why;
  o.mode = PlanMode::kAdaptive;
  o.coarsest_level = 3;
  o.finest_level = 2;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("coarsest_level"), std::string::npos) << why;
  o = MappingRunOptions{};
  o.uniform_spread = true;  // a uniform design: with kBoundary it names the mismatch
  o.sample_budget = 10;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("uniform_spread"), std::string::npos) << why;
  o.mode = PlanMode::kUniform;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  EXPECT_EQ(RunModeName(o), "uniform-spread");
  o.uniform_spread = false;
  EXPECT_EQ(RunModeName(o), "uniform");
  o = MappingRunOptions{};
  o.reach.max_angle_deg = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("reach"), std::string::npos) << why;
}

TEST(MappingRunTest, SummarisesTheMapsRegionsWithTheTruthUnderTheirPieces) {
  absl::StatusOr<Scene> scene = LoadSceneByName("plate");
  ASSERT_TRUE(scene.ok()) << scene.status();
  absl::StatusOr<std::unique_ptr<MappingBench>> bench = MappingBench::Create(*std::move(scene), 5);
  ASSERT_TRUE(bench.ok()) << bench.status();
  MappingRunOptions o;
  o.mode = PlanMode::kUniform;
  o.uniform_spread = true;
  o.sample_budget = 40;
  absl::StatusOr<MappingRunResult> run = RunMapping(**bench, o);
  ASSERT_TRUE(run.ok()) << run.status();
  ASSERT_FALSE(run->map_regions.empty());
  double share = 0.0, piece_mm = 0.0, truth_mm = 0.0;
  for (const MapRegionSummary& r : run->map_regions) {
    share += r.vertex_share;
    EXPECT_GE(r.pieces, 1);
    ASSERT_EQ(r.truth_mm.size(), (*bench)->scene().materials.size());
    for (double mm : r.truth_mm) truth_mm += mm;
    // A region's mu is one of the plate's materials' (masonite 0.25 .. wood
    // 0.42) or a blend of them, to a few standard errors; never outside.
    EXPECT_GT(r.mu, 0.25 - 4.0 * r.mu_se);
    EXPECT_LT(r.mu, 0.42 + 4.0 * r.mu_se);
  }
  for (const ProbeRecord& p : run->probes) {
    if (!p.measured) continue;
    for (const LinePiece& piece : p.line.pieces) piece_mm += piece.end_mm - piece.start_mm;
  }
  EXPECT_NEAR(share, 1.0, 1e-9);  // every vertex of the plate is reached by data
  // The truth is read along the pieces' paths: their lengths in all (the
  // polyline through the path points is as long as the arc, to rounding).
  EXPECT_NEAR(truth_mm, piece_mm, 0.01 * piece_mm);
  const std::string table = FormatMapRegions(*run, (*bench)->scene());
  EXPECT_NE(table.find("truth under its pieces"), std::string::npos) << table;
  EXPECT_NE(table.find("wood 100 %"), std::string::npos) << table;  // the plate itself
}

// A scan is mapped on the control mesh the service makes of it, not on the
// scan's own vertices: before, surfmap-mapsim planned scan_vase_m's 2,500
// scan vertices as level-0 sites (a run took over 10 minutes) and mapped
// scan_pebble_m with 122 drags where the service gives it ~250.
TEST(MappingBenchTest, PlansAScanOnTheServicesSimplifiedControlMesh) {
  absl::StatusOr<Scene> scene = LoadSceneByName("scan_pebble_m");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const ControlMesh scan = scene->mesh;
  absl::StatusOr<std::unique_ptr<MappingBench>> bench = MappingBench::Create(*std::move(scene), 5);
  ASSERT_TRUE(bench.ok()) << bench.status();
  const MappingBench& b = **bench;
  EXPECT_TRUE(b.simplified());
  // Sites ~13 mm apart over a pebble of ~28,000 mm^2: on the order of 170,
  // a fifteenth of the scan's vertices.
  EXPECT_LT(b.control_vertices(), static_cast<int>(scan.positions.size()) / 8);
  EXPECT_GT(b.control_vertices(), 50);
  EXPECT_EQ(b.map_surface().limit_positions.size(), b.surface().level(b.map_level()).limit_positions.size());
  // Every level lies on the scan (projected there), not on the control
  // mesh's chords: within the scan's own 0.05 mm noise and rounding.
  const DenseSurface dense(scan);
  for (int k : {0, b.plan_level(), b.map_level()}) {
    double worst = 0.0;
    for (const Eigen::Vector3d& p : b.level(k).limit_positions) {
      Eigen::Vector3d q = p, n = Eigen::Vector3d::UnitZ();
      dense.Project(q, n);
      worst = std::max(worst, (q - p).norm());
    }
    EXPECT_LT(worst, 1e-6) << "level " << k;
  }
}

// A CAD scene ("surface": "facets") is planned as the service plans an
// object uploaded as facets: the control mesh refined flat or coarsened from
// the facets to the site spacing, every level on the faces (not the blob a
// Loop surface of the facets would be).
TEST(MappingBenchTest, PlansACadSceneOnItsFacetsAsTheServiceDoes) {
  absl::StatusOr<Scene> scene = LoadSceneByName("cad_case_m");
  ASSERT_TRUE(scene.ok()) << scene.status();
  ASSERT_TRUE(scene->facets);
  const int facet_vertices = static_cast<int>(scene->mesh.positions.size());
  absl::StatusOr<std::unique_ptr<MappingBench>> bench = MappingBench::Create(*std::move(scene), 5);
  ASSERT_TRUE(bench.ok()) << bench.status();
  const MappingBench& b = **bench;
  EXPECT_TRUE(b.simplified());
  // 68,400 mm^2 at 13 mm: a target of ~405 sites; the 6 mm facets are
  // coarsened well below their own 1,976 vertices.
  EXPECT_LT(b.control_vertices(), facet_vertices / 2);
  EXPECT_GT(b.control_vertices(), 300);
  // The case spans +-80 x +-50 x +-35 mm: every vertex of every level is on
  // a face, to rounding.
  const Eigen::Vector3d half(80.0, 50.0, 35.0);
  for (int k : {0, b.plan_level(), b.map_level()}) {
    double worst = 0.0;
    for (const Eigen::Vector3d& p : b.level(k).limit_positions) {
      worst = std::max(worst, std::abs((p.cwiseAbs() - half).maxCoeff()));
    }
    EXPECT_LT(worst, 1e-6) << "level " << k;
  }
}

TEST(MappingBenchTest, PlansAHandMadeControlMeshAsItIs) {
  absl::StatusOr<Scene> scene = LoadSceneByName("plate");
  ASSERT_TRUE(scene.ok()) << scene.status();
  const int vertices = static_cast<int>(scene->mesh.positions.size());
  absl::StatusOr<std::unique_ptr<MappingBench>> bench = MappingBench::Create(*std::move(scene), 5);
  ASSERT_TRUE(bench.ok()) << bench.status();
  EXPECT_FALSE((*bench)->simplified());
  EXPECT_EQ((*bench)->control_vertices(), vertices);
  EXPECT_EQ(&(*bench)->surface(), &(*bench)->rig().surface());
}

}  // namespace
}  // namespace surfmap::mapsim
