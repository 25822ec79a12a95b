// A value and its standard error as a reader quotes them: the error to two
// significant digits, the value to the same last digit (0.3335 ± 0.3994 is
// 0.33 ± 0.40; 460429 ± 301 is 460430 ± 300).
#pragma once

#include <string>

namespace impactlab {

struct RoundedEstimate {
  std::string value, sigma;    // fixed-point texts, "0.33" and "0.40"
  int decimals = 0;            // digits after the point of both (0 for a rounded integer)
  long long sigma_digits = 0;  // the error in units of the last digit: 40 (two digits, or 100)
};

// `sigma` must be positive and finite.
RoundedEstimate RoundToError(double value, double sigma);

}  // namespace impactlab
