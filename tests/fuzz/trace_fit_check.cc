#include "tests/fuzz/trace_fit_check.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"
#include "server/estimate/fit_trace.h"
#include "tests/fuzz/fuzz_check.h"

namespace surfmap::fuzz {
namespace {

bool Finite(double v) { return std::isfinite(v); }

bool AllFinite(const std::vector<double>& v) {
  for (double x : v) {
    if (!Finite(x)) return false;
  }
  return true;
}

void CheckFit(const absl::StatusOr<TraceFit>& fit, const char* method) {
  if (!fit.ok()) {
    FUZZ_CHECK(fit.status().code() == absl::StatusCode::kInvalidArgument,
               absl::StrCat(method, ": FitTrace must reject bad traces with INVALID_ARGUMENT, got ",
                            Describe(fit.status())));
    FUZZ_CHECK(!fit.status().message().empty(), absl::StrCat(method, ": rejection without a message"));
    return;
  }
  const FrictionFit& f = fit->friction;
  const std::string where = absl::StrCat(method, ": mu ", f.mu, " mu_std ", f.mu_std, " median ", f.mu_median,
                                         " normal (", f.normal.x(), ", ", f.normal.y(), ", ", f.normal.z(), ")");
  FUZZ_CHECK(Finite(f.mu) && Finite(f.mu_std) && Finite(f.mu_median), where);
  FUZZ_CHECK(f.normal.allFinite() && std::abs(f.normal.norm() - 1.0) < 1e-9, where);
  FUZZ_CHECK(f.n_pairs >= 2 && static_cast<std::size_t>(f.n_pairs) == f.pair_mu.size(), where);
  FUZZ_CHECK(AllFinite(f.pair_mu), where);
  FUZZ_CHECK(Finite(fit->noise_std) && Finite(fit->path_length_mm) && Finite(fit->max_retrace_offset_mm),
             absl::StrCat(method, ": noise_std ", fit->noise_std, " path ", fit->path_length_mm, " offset ",
                          fit->max_retrace_offset_mm));
  const ArFit& r = fit->roughness;
  FUZZ_CHECK(AllFinite(r.a) && AllFinite(r.a_stderr) && Finite(r.sigma) && Finite(r.variance) && AllFinite(r.acf) &&
                 Finite(r.acf_decay_mm),
             absl::StrCat(method, ": roughness sigma ", r.sigma, " variance ", r.variance, " decay ", r.acf_decay_mm));
  FUZZ_CHECK(!r.dominant_wavelength_mm || Finite(*r.dominant_wavelength_mm),
             absl::StrCat(method, ": dominant wavelength ", *r.dominant_wavelength_mm));
}

bool SameDouble(double a, double b) { return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b); }

}  // namespace

bool FitAndCheck(const DragTrace& trace) {
  if (trace.samples.size() > kMaxFittedSamples) return false;
  FitOptions burg;
  const absl::StatusOr<TraceFit> burg_fit = FitTrace(trace, burg);
  CheckFit(burg_fit, "Burg");
  FitOptions least_squares;
  least_squares.ar_method = ArMethod::kLeastSquares;
  const absl::StatusOr<TraceFit> ls_fit = FitTrace(trace, least_squares);
  CheckFit(ls_fit, "least squares");
  // Everything up to the roughness fit is shared: the friction part must agree.
  if (burg_fit.ok() && ls_fit.ok()) {
    FUZZ_CHECK(SameDouble(burg_fit->friction.mu, ls_fit->friction.mu), "the AR method changed mu");
  }
  return burg_fit.ok() || ls_fit.ok();
}

bool SameTrace(const DragTrace& a, const DragTrace& b) {
  if (a.samples.size() != b.samples.size()) return false;
  for (std::size_t i = 0; i < a.samples.size(); ++i) {
    const DragSample& x = a.samples[i];
    const DragSample& y = b.samples[i];
    if (!SameDouble(x.t, y.t) || x.phase != y.phase) return false;
    for (int k = 0; k < 3; ++k) {
      if (!SameDouble(x.position[k], y.position[k]) || !SameDouble(x.force[k], y.force[k])) return false;
    }
  }
  return true;
}

}  // namespace surfmap::fuzz
