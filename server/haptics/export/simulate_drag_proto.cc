#include "server/haptics/export/simulate_drag_proto.h"

#include <cmath>
#include <cstdint>

#include "absl/strings/str_cat.h"
#include "server/haptics/export/texture_map_proto.h"
#include "server/haptics/model_drag.h"
#include "server/codec/trace_samples_proto.h"

namespace surfmap::haptics {

namespace pb = ::surfmap::v1;

namespace {

// `value` or its default when 0; INVALID_ARGUMENT outside (0, max].
absl::StatusOr<double> InRange(const char* name, double value, double fallback, double max) {
  if (value == 0) return fallback;
  if (!std::isfinite(value) || value < 0 || value > max) {
    return absl::InvalidArgumentError(absl::StrCat(name, " must be in (0, ", max, "] (0 = ", fallback, "), got ", value));
  }
  return value;
}

Eigen::Vector3d FromVec3(const pb::Vec3& v) { return {v.x(), v.y(), v.z()}; }

constexpr int64_t kMaxSimulatedSamples = 500'000;  // ~37 MB of answer

}  // namespace

absl::StatusOr<SimulateDragSettings> ValidateSimulateDragRequest(const pb::SimulateDragRequest& request) {
  SimulateDragSettings settings;
  absl::StatusOr<double> length = InRange("length_mm", request.length_mm(), 20.0, 500.0);
  if (!length.ok()) return length.status();
  settings.length_mm = *length;
  ModelDragOptions& options = settings.options;
  for (auto [name, value, fallback, max, out] :
       {std::tuple{"speed_mm_s", request.speed_mm_s(), 10.0, 1000.0, &options.speed_mm_s},
        std::tuple{"normal_force_n", request.normal_force_n(), 5.0, 100.0, &options.normal_force_n},
        std::tuple{"sample_rate_hz", request.sample_rate_hz(), 100.0, 10000.0, &options.sample_rate_hz}}) {
    absl::StatusOr<double> v = InRange(name, value, fallback, max);
    if (!v.ok()) return v.status();
    *out = *v;
  }
  options.pause_s = request.has_pause_s() ? request.pause_s() : 0.5;
  if (!std::isfinite(options.pause_s) || options.pause_s < 0 || options.pause_s > 10) {
    return absl::InvalidArgumentError(absl::StrCat("pause_s must be in [0, 10] (unset = 0.5), got ", options.pause_s));
  }
  // Checked before any work: each sample is ~74 bytes of the answer (seven
  // trace columns, phase, mu, roughness, region), and an answer must fit the
  // server's 64 MB message limit with room to spare.
  const double samples =
      (2.0 * settings.length_mm / options.speed_mm_s + options.pause_s) * options.sample_rate_hz;
  if (samples > kMaxSimulatedSamples) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the drag would have ", static_cast<int64_t>(samples), " samples ((2 length_mm / speed_mm_s + pause_s) * "
        "sample_rate_hz); the limit is ", kMaxSimulatedSamples, ": shorten it, drag faster or sample slower"));
  }
  settings.start = FromVec3(request.position());
  settings.direction = FromVec3(request.direction());
  if (!settings.start.allFinite()) return absl::InvalidArgumentError("position is not finite");
  if (!settings.direction.allFinite() || settings.direction.norm() == 0) {
    return absl::InvalidArgumentError("direction must be finite and non-zero");
  }
  settings.seed = request.seed() == 0 ? 1 : request.seed();
  return settings;
}

absl::StatusOr<pb::SimulateDragResponse> SimulateDragOnMap(const pb::GetMapResponse& map,
                                                           const pb::SimulateDragRequest& request) {
  absl::StatusOr<SimulateDragSettings> settings = ValidateSimulateDragRequest(request);
  if (!settings.ok()) return settings.status();
  if (map.map().mu_size() == 0) {
    return absl::FailedPreconditionError(absl::StrCat("job ", map.map().job_id(), " has no measured sample yet"));
  }
  absl::StatusOr<TextureMap> model = TextureMapFromResponse(map);
  if (!model.ok()) return model.status();
  const double grid_step = model->grid_step_mm;
  TextureRendererOptions renderer_options;
  renderer_options.seed = settings->seed;
  absl::StatusOr<std::unique_ptr<TextureRenderer>> renderer =
      TextureRenderer::Create(*std::move(model), renderer_options);
  if (!renderer.ok()) return renderer.status();
  absl::StatusOr<std::vector<Eigen::Vector3d>> path =
      TraceModelPath(**renderer, settings->start, settings->direction, settings->length_mm);
  if (!path.ok()) return path.status();
  absl::StatusOr<ModelDrag> drag = RenderDragAlongPath(**renderer, *path, settings->options);
  if (!drag.ok()) return drag.status();
  pb::SimulateDragResponse response;
  *response.mutable_samples() = DragTraceToProto(drag->trace);
  response.mutable_mu()->Add(drag->mu.begin(), drag->mu.end());
  response.mutable_roughness_n()->Add(drag->roughness_n.begin(), drag->roughness_n.end());
  response.mutable_region()->Add(drag->region.begin(), drag->region.end());
  response.set_level(map.map().level());
  response.set_grid_step_mm(grid_step);
  return response;
}

}  // namespace surfmap::haptics
