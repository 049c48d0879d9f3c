#include "server/estimate/ar_noise.h"

namespace surfmap {

double FilteredNoiseProduct(const std::vector<double>& c, const std::vector<double>& u,
                            const std::vector<double>& v, int shift) {
  double sum = 0.0;
  for (int i = 0; i < static_cast<int>(u.size()); ++i) {
    for (int j = 0; j < static_cast<int>(v.size()); ++j) {
      sum += u[i] * v[j] * NoiseAutocovarianceAt(c, i - shift - j);
    }
  }
  return sum;
}

}  // namespace surfmap
