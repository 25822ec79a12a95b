// Interpolation of equally spaced samples (internal to digitize/).
#pragma once

#include <cmath>
#include <vector>

namespace impactlab::digitize {

// Catmull-Rom interpolation of equally spaced samples at a fractional index
// (0 beyond them): a straight interpolation would blur a line reflected
// about a point between samples.
inline double CatmullRom(const std::vector<double>& v, double position) {
  const int i = static_cast<int>(std::floor(position));
  const int n = static_cast<int>(v.size());
  if (i < 1 || i + 2 >= n) return 0.0;
  const double f = position - i, p0 = v[i - 1], p1 = v[i], p2 = v[i + 1], p3 = v[i + 2];
  return p1 + 0.5 * f *
                  (p2 - p0 +
                   f * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + f * (3.0 * (p1 - p2) + p3 - p0)));
}

}  // namespace impactlab::digitize
