// A function of one variable tabulated as Chebyshev series on consecutive
// pieces [breaks[i], breaks[i+1]], with its exact derivative: the derivative
// of the same series (Clenshaw's recurrence differentiated), so that a fit's
// Jets see the slope of the very function whose values they get.
//
// The tables themselves are constant data (model/power_law_tables.inc, made
// by the generator in tests/model/power_law_tables_test.cpp).
#pragma once

#include <algorithm>
#include <optional>
#include <span>
#include <type_traits>

namespace impactlab {

struct ChebyshevTable {
  std::span<const double> breaks;        // ascending; pieces = breaks.size() - 1
  int terms = 0;                         // coefficients per piece
  std::span<const double> coefficients;  // piece i's are [i * terms, (i + 1) * terms)
};

struct ValueSlope {
  double value = 0.0;
  double slope = 0.0;  // d value / dx
};

// sum_k c_k T_k(t) at x mapped to t in [-1, 1] on its piece (c_0 stored
// halved, as the series is written), and its derivative in x; nullopt
// outside [breaks.front(), breaks.back()] or for an empty table.
inline std::optional<ValueSlope> Evaluate(const ChebyshevTable& table, double x) {
  if (table.breaks.size() < 2 || !(x >= table.breaks.front() && x <= table.breaks.back())) {
    return std::nullopt;
  }
  // The piece whose upper end is the first break >= x (x at a break: the lower piece).
  const auto upper = std::lower_bound(table.breaks.begin() + 1, table.breaks.end(), x);
  const auto piece = static_cast<std::size_t>(upper - table.breaks.begin() - 1);
  const double a = table.breaks[piece], b = table.breaks[piece + 1];
  const double t = (2.0 * x - (a + b)) / (b - a);
  const double* c = table.coefficients.data() + piece * static_cast<std::size_t>(table.terms);
  // Clenshaw: b_k = c_k + 2 t b_{k+1} - b_{k+2}, f = c_0 + t b_1 - b_2; and
  // its derivative in t, d_k = 2 b_{k+1} + 2 t d_{k+1} - d_{k+2}.
  double b1 = 0.0, b2 = 0.0, d1 = 0.0, d2 = 0.0;
  for (int k = table.terms - 1; k >= 1; --k) {
    const double d0 = 2.0 * b1 + 2.0 * t * d1 - d2;
    const double b0 = c[k] + 2.0 * t * b1 - b2;
    d2 = d1;
    d1 = d0;
    b2 = b1;
    b1 = b0;
  }
  return ValueSlope{c[0] + t * b1 - b2, (b1 + t * d1 - d2) * 2.0 / (b - a)};
}

// The tabulated function at x in T (a double or a ceres::Jet) whose value
// x0 = the double x it was evaluated at: its value, carried to a Jet by its
// slope (first order is all a Jet holds).
template <typename T>
T Along(const ValueSlope& f, double x0, const T& x) {
  if constexpr (std::is_same_v<T, double>) {
    return f.value;
  } else {
    return T(f.value) + T(f.slope) * (x - T(x0));
  }
}

}  // namespace impactlab
