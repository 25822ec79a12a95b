#include "model/estimate.h"

#include <algorithm>
#include <cstddef>

namespace impactlab {

double CorrelationInflation(std::span<const double> residual) {
  const std::size_t n = residual.size();
  double variance = 0.0;
  for (double r : residual) variance += r * r;
  if (n < 8 || !(variance > 0.0)) return 1.0;
  const std::size_t max_lag = std::min<std::size_t>(n / 4, 4096);
  double sum = 0.0;
  for (std::size_t k = 1; k <= max_lag; ++k) {
    double lagged = 0.0;
    for (std::size_t i = 0; i + k < n; ++i) lagged += residual[i] * residual[i + k];
    const double rho = lagged / variance;
    if (!(rho > 0.0)) break;
    sum += rho;
  }
  return std::max(1.0, 1.0 + 2.0 * sum);
}

}  // namespace impactlab
