#include "server/haptics/export/simulate_drag_proto.h"

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include "server/haptics/export/texture_map_proto.h"
#include "server/codec/trace_samples_proto.h"
#include "server/estimate/fit_trace.h"

namespace surfmap::haptics {
namespace {

namespace pb = ::surfmap::v1;
using ::testing::HasSubstr;

// A 60 x 60 mm plate of 1 mm cells as GetMap would send it: rubber left of
// x = 30, masonite right, a sample fitted on a 0.1 mm grid.
pb::GetMapResponse PlateResponse() {
  pb::GetMapResponse r;
  pb::MapLevel* m = r.mutable_map();
  m->set_job_id(5);
  m->set_level(2);
  const int cells = 60, n = cells + 1;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      pb::Vec3* p = r.mutable_mesh()->add_positions();
      p->set_x(i);
      p->set_y(j);
      pb::Vec3* nn = r.mutable_mesh()->add_normals();
      nn->set_z(1);
      const bool rubber = i < 30;
      m->add_mu(rubber ? 0.305 : 0.25);
      m->add_mu_uncertainty(0.01);
      m->add_sigma(rubber ? 0.11 : 0.16);
      m->add_a1(rubber ? 0.6 : 1.61);
      m->add_a2(rubber ? 0.25 : -0.73);
      m->add_region(rubber ? 0 : 1);
      m->add_boundary_probability(0.0);
    }
  }
  for (int k = 0; k < 2; ++k) m->add_regions()->set_region(k);
  m->set_vertex_count(n * n);
  for (int j = 0; j < cells; ++j) {
    for (int i = 0; i < cells; ++i) {
      const int a = j * n + i, b = a + 1, c = a + n, d = c + 1;
      for (int v : {a, b, d, a, d, c}) r.mutable_mesh()->add_triangle_indices(v);
    }
  }
  m->add_samples()->mutable_fit()->mutable_roughness()->set_grid_step_mm(0.1);
  return r;
}

TEST(SimulateDragOnMapTest, RendersTheModelInTheTraceFormat) {
  const pb::GetMapResponse map = PlateResponse();
  EXPECT_DOUBLE_EQ(GridStepOf(map.map()), 0.1);
  pb::SimulateDragRequest request;
  request.set_job_id(5);
  request.mutable_position()->set_x(5);
  request.mutable_position()->set_y(30);
  request.mutable_direction()->set_x(1);
  request.set_length_mm(20);  // stays on rubber (x 5..25)
  absl::StatusOr<pb::SimulateDragResponse> response = SimulateDragOnMap(map, request);
  ASSERT_TRUE(response.ok()) << response.status();
  // Defaults: 10 mm/s at 100 Hz = 0.1 mm per sample, 201 per pass, a 0.5 s pause.
  EXPECT_EQ(response->samples().t_size(), 201 + 50 + 201);
  EXPECT_EQ(response->mu_size(), response->samples().t_size());
  EXPECT_EQ(response->level(), 2);
  EXPECT_DOUBLE_EQ(response->mu(0), 0.305);
  EXPECT_EQ(response->region(0), 0);
  absl::StatusOr<DragTrace> trace = DragTraceFromProto(response->samples());
  ASSERT_TRUE(trace.ok());
  // The estimator reads the model's friction back (tolerance: the rendered
  // texture riding on the friction, ~0.01 over 16 mm; see model_drag_test).
  absl::StatusOr<TraceFit> fit = FitTrace(*trace, FitOptions{});
  ASSERT_TRUE(fit.ok()) << fit.status();
  EXPECT_NEAR(fit->friction.mu, 0.305, 0.03);
  // Same request, same trace (seeded texture).
  absl::StatusOr<pb::SimulateDragResponse> again = SimulateDragOnMap(map, request);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(again->samples().fx(100), response->samples().fx(100));
}

TEST(SimulateDragOnMapTest, RejectsBadRequests) {
  const pb::GetMapResponse map = PlateResponse();
  pb::SimulateDragRequest good;
  good.mutable_position()->set_x(5);
  good.mutable_position()->set_y(30);
  good.mutable_direction()->set_x(1);
  auto code = [&](auto edit) {
    pb::SimulateDragRequest r = good;
    edit(r);
    return SimulateDragOnMap(map, r).status().code();
  };
  EXPECT_EQ(code([](auto& r) { r.set_length_mm(-1); }), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(code([](auto& r) { r.set_length_mm(501); }), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(code([](auto& r) { r.set_speed_mm_s(2000); }), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(code([](auto& r) { r.set_pause_s(-1); }), absl::StatusCode::kInvalidArgument);
  // 500 mm at 2 mm/s, 10 kHz: 5 million samples, far past what an answer carries.
  EXPECT_EQ(code([](auto& r) {
              r.set_length_mm(500);
              r.set_speed_mm_s(2);
              r.set_sample_rate_hz(10000);
            }),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(code([](auto& r) { r.clear_direction(); }), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(code([](auto& r) { r.mutable_direction()->set_x(0); r.mutable_direction()->set_z(1); }),
            absl::StatusCode::kInvalidArgument);  // along the normal
  EXPECT_EQ(code([](auto& r) { r.mutable_position()->set_z(10); }), absl::StatusCode::kFailedPrecondition);
  pb::GetMapResponse no_mesh = map;
  no_mesh.clear_mesh();
  EXPECT_EQ(SimulateDragOnMap(no_mesh, good).status().code(), absl::StatusCode::kInvalidArgument);
}

// The request's own checks, with no map: defaults filled in as surfmap.proto
// states them, and each bad field named.
TEST(ValidateSimulateDragRequestTest, FillsTheDefaultsAndNamesTheBadField) {
  pb::SimulateDragRequest request;
  request.mutable_position()->set_x(5);
  request.mutable_direction()->set_y(2);
  absl::StatusOr<SimulateDragSettings> settings = ValidateSimulateDragRequest(request);
  ASSERT_TRUE(settings.ok()) << settings.status();
  EXPECT_EQ(settings->length_mm, 20.0);
  EXPECT_EQ(settings->options.speed_mm_s, 10.0);
  EXPECT_EQ(settings->options.normal_force_n, 5.0);
  EXPECT_EQ(settings->options.sample_rate_hz, 100.0);
  EXPECT_EQ(settings->options.pause_s, 0.5);
  EXPECT_EQ(settings->seed, 1u);
  EXPECT_EQ(settings->start, Eigen::Vector3d(5, 0, 0));
  EXPECT_EQ(settings->direction, Eigen::Vector3d(0, 2, 0));
  request.set_length_mm(16);
  request.set_speed_mm_s(4);
  request.set_normal_force_n(2);
  request.set_sample_rate_hz(500);
  request.set_pause_s(0);
  request.set_seed(9);
  settings = ValidateSimulateDragRequest(request);
  ASSERT_TRUE(settings.ok()) << settings.status();
  EXPECT_EQ(settings->length_mm, 16.0);
  EXPECT_EQ(settings->options.speed_mm_s, 4.0);
  EXPECT_EQ(settings->options.normal_force_n, 2.0);
  EXPECT_EQ(settings->options.sample_rate_hz, 500.0);
  EXPECT_EQ(settings->options.pause_s, 0.0);
  EXPECT_EQ(settings->seed, 9u);

  auto message = [&](auto edit) {
    pb::SimulateDragRequest r = request;
    edit(r);
    absl::StatusOr<SimulateDragSettings> s = ValidateSimulateDragRequest(r);
    EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(s.status().message());
  };
  EXPECT_THAT(message([](auto& r) { r.set_length_mm(501); }), HasSubstr("length_mm"));
  EXPECT_THAT(message([](auto& r) { r.set_speed_mm_s(-1); }), HasSubstr("speed_mm_s"));
  EXPECT_THAT(message([](auto& r) { r.set_normal_force_n(std::nan("")); }), HasSubstr("normal_force_n"));
  EXPECT_THAT(message([](auto& r) { r.set_sample_rate_hz(20000); }), HasSubstr("sample_rate_hz"));
  EXPECT_THAT(message([](auto& r) { r.set_pause_s(11); }), HasSubstr("pause_s"));
  EXPECT_THAT(message([](auto& r) { r.mutable_position()->set_y(INFINITY); }), HasSubstr("position"));
  EXPECT_THAT(message([](auto& r) { r.clear_direction(); }), HasSubstr("direction"));
}

}  // namespace
}  // namespace surfmap::haptics
