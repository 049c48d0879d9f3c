#include "server/estimate/ar_roots.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Eigenvalues>

namespace surfmap {
namespace {

// |1 - sum_j a_j e^(-i j w)|^2, the inverse of the normalised AR spectrum.
double InversePowerSpectrum(const std::vector<double>& a, double w) {
  std::complex<double> sum = 1.0;
  const std::complex<double> step = std::polar(1.0, -w);
  std::complex<double> z = 1.0;
  for (double aj : a) {
    z *= step;
    sum -= aj * z;
  }
  return std::norm(sum);
}

// True when the AR power spectrum has its maximum at w = 0 (checked on a grid
// of 512 frequencies over [0, pi]; a peak narrower than pi/512 would need a root
// within ~0.003 of the unit circle at an angle below that, i.e. a wavelength of
// > 1000 steps, far longer than any drag).
bool SpectrumPeaksAtZero(const std::vector<double>& a) {
  constexpr int kGrid = 512;
  const double at_zero = InversePowerSpectrum(a, 0.0);
  for (int i = 1; i <= kGrid; ++i) {
    if (InversePowerSpectrum(a, std::numbers::pi * i / kGrid) < at_zero) return false;
  }
  return true;
}

}  // namespace

std::vector<std::complex<double>> ArCharacteristicRoots(const std::vector<double>& a) {
  const int p = static_cast<int>(a.size());
  if (p == 0) return {};
  if (p == 1) return {std::complex<double>(a[0], 0.0)};
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(p, p);
  for (int j = 0; j < p; ++j) companion(0, j) = a[j];
  for (int i = 1; i < p; ++i) companion(i, i - 1) = 1.0;
  Eigen::EigenSolver<Eigen::MatrixXd> solver(companion, /*computeEigenvectors=*/false);
  std::vector<std::complex<double>> roots;
  roots.reserve(p);
  if (solver.info() != Eigen::Success) {
    // Only non-finite coefficients get here; report them as non-roots that
    // fail every stationarity test.
    roots.assign(p, std::complex<double>(std::numeric_limits<double>::infinity(), 0.0));
    return roots;
  }
  for (int i = 0; i < p; ++i) roots.push_back(solver.eigenvalues()(i));
  return roots;
}

double ArLargestRootModulus(const std::vector<double>& a) {
  double largest = 0.0;
  for (const auto& z : ArCharacteristicRoots(a)) largest = std::max(largest, std::abs(z));
  return largest;
}

std::optional<double> ArDominantWavelengthSteps(const std::vector<double>& a) {
  const auto roots = ArCharacteristicRoots(a);
  if (roots.empty()) return std::nullopt;
  const auto dominant = std::max_element(
      roots.begin(), roots.end(),
      [](const auto& x, const auto& y) { return std::abs(x) < std::abs(y); });
  const double angle = std::abs(std::arg(*dominant));
  // Eigenvalues of a real matrix come as exact conjugate pairs or as reals with
  // a rounding-level imaginary part; treat the latter as real.
  if (std::abs(dominant->imag()) <= 1e-12 * std::max(1.0, std::abs(*dominant)) ||
      angle >= std::numbers::pi - 1e-12) {
    return std::nullopt;
  }
  if (SpectrumPeaksAtZero(a)) return std::nullopt;
  return 2.0 * std::numbers::pi / angle;
}

}  // namespace surfmap
