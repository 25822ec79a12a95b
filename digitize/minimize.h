// A one-dimensional minimum's refinement (internal to digitize/).
#pragma once

#include <algorithm>

namespace impactlab::digitize {

// Refines a minimum of f along one coordinate: parabolas through the best
// point and its neighbours `step` away, the step halved each time.
template <typename F>
double RefineMinimum(F f, double x, double step, double lo, double hi, int rounds) {
  double fx = f(x);
  for (int r = 0; r < rounds; ++r, step *= 0.5) {
    const double a = std::max(lo, x - step), b = std::min(hi, x + step);
    const double fa = f(a), fb = f(b);
    double next = x;
    if (fa < fx && fa <= fb) {
      next = a;
    } else if (fb < fx) {
      next = b;
    } else {
      const double curvature = fa - 2.0 * fx + fb;
      if (curvature > 0.0 && a < x && x < b) next = x + 0.5 * step * (fa - fb) / curvature;
    }
    next = std::clamp(next, lo, hi);
    const double fn = f(next);
    if (fn < fx) x = next, fx = fn;
  }
  return x;
}

}  // namespace impactlab::digitize
