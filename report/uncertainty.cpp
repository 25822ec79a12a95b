#include "report/uncertainty.h"

#include <cmath>

#include <fmt/format.h>

namespace impactlab {

RoundedEstimate RoundToError(double value, double sigma) {
  // The place of the error's second significant digit: 10^place.
  const int place = static_cast<int>(std::floor(std::log10(sigma))) - 1;
  RoundedEstimate r;
  if (place < 0) {
    r.decimals = -place;
    r.sigma_digits = std::llround(sigma * std::pow(10.0, r.decimals));
    r.value = fmt::format("{:.{}f}", value, r.decimals);
    r.sigma = fmt::format("{:.{}f}", sigma, r.decimals);
  } else {
    // Rounded to tens, hundreds, ...: no digits after the point, and the
    // digits below the error's second are zeros.
    const double unit = std::pow(10.0, place);
    r.decimals = 0;
    r.sigma_digits = std::llround(sigma / unit) * std::llround(unit);
    r.value = fmt::format("{:.0f}", std::round(value / unit) * unit);
    r.sigma = fmt::format("{}", r.sigma_digits);
  }
  // -0.00 is 0.00.
  if (r.value.find_first_not_of("-0.") == std::string::npos && r.value[0] == '-') {
    r.value.erase(0, 1);
  }
  return r;
}

}  // namespace impactlab
