// A function of one variable tabulated as Chebyshev series on consecutive
// pieces [breaks[i], breaks[i+1]], or of two on the rectangles of two piece
// lists, with its exact derivatives: the derivatives of the same series
// (Clenshaw's recurrence differentiated), so that a fit's Jets see the slope
// of the very function whose values they get.
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

// A function of two variables tabulated as a tensor product of Chebyshev
// series on the rectangles of two piece lists: on piece (i, j), f =
// sum_k sum_l c_kl T_k(t_x) T_l(t_y), with c_0l and c_k0 stored halved (so
// c_00 quartered), coefficients of piece (i, j) at
// [((i * (y pieces) + j) * x terms + k) * y terms + l].
struct ChebyshevSurface {
  std::span<const double> x_breaks;
  std::span<const double> y_breaks;
  int x_terms = 0;
  int y_terms = 0;
  std::span<const double> coefficients;
};

struct ValueSlopes {
  double value = 0.0;
  double slope_x = 0.0;  // d value / dx
  double slope_y = 0.0;  // d value / dy
};

namespace chebyshev_internal {

// The piece of `breaks` that holds x (x at a break: the lower piece), or -1
// outside [breaks.front(), breaks.back()].
inline int PieceOf(std::span<const double> breaks, double x) {
  if (breaks.size() < 2 || !(x >= breaks.front() && x <= breaks.back())) return -1;
  const auto upper = std::lower_bound(breaks.begin() + 1, breaks.end(), x);
  return static_cast<int>(upper - breaks.begin() - 1);
}

}  // namespace chebyshev_internal

// f(x, y) and its two partial derivatives (each the derivative of the same
// series); nullopt outside the table's rectangle.
inline std::optional<ValueSlopes> Evaluate(const ChebyshevSurface& table, double x, double y) {
  constexpr int kMaxTerms = 64;
  const int i = chebyshev_internal::PieceOf(table.x_breaks, x);
  const int j = chebyshev_internal::PieceOf(table.y_breaks, y);
  if (i < 0 || j < 0 || table.x_terms > kMaxTerms || table.y_terms > kMaxTerms) {
    return std::nullopt;
  }
  const double xa = table.x_breaks[i], xb = table.x_breaks[i + 1];
  const double ya = table.y_breaks[j], yb = table.y_breaks[j + 1];
  const double tx = (2.0 * x - (xa + xb)) / (xb - xa);
  const double ty = (2.0 * y - (ya + yb)) / (yb - ya);
  // T_l(ty) and T_l'(ty) by their recurrences (T_l' = l U_{l-1}).
  double t[kMaxTerms], dt[kMaxTerms];
  double u_prev = 0.0, u = 1.0;  // U_{l-2}, U_{l-1}
  for (int l = 0; l < table.y_terms; ++l) {
    t[l] = l == 0 ? 1.0 : l == 1 ? ty : 2.0 * ty * t[l - 1] - t[l - 2];
    if (l == 0) {
      dt[l] = 0.0;
    } else {
      dt[l] = l * u;
      const double u_next = 2.0 * ty * u - u_prev;
      u_prev = u;
      u = u_next;
    }
  }
  // Each x coefficient at ty, and its derivative in ty, then Clenshaw in tx
  // on both (the x series' own derivative from the first).
  const int columns = static_cast<int>(table.y_breaks.size()) - 1;
  const double* c = table.coefficients.data() +
                    static_cast<std::size_t>(i * columns + j) * table.x_terms * table.y_terms;
  double a[kMaxTerms], da[kMaxTerms];
  for (int k = 0; k < table.x_terms; ++k) {
    double s = 0.0, ds = 0.0;
    for (int l = 0; l < table.y_terms; ++l) {
      s += c[k * table.y_terms + l] * t[l];
      ds += c[k * table.y_terms + l] * dt[l];
    }
    a[k] = s;
    da[k] = ds;
  }
  double b1 = 0.0, b2 = 0.0, d1 = 0.0, d2 = 0.0, e1 = 0.0, e2 = 0.0;
  for (int k = table.x_terms - 1; k >= 1; --k) {
    const double d0 = 2.0 * b1 + 2.0 * tx * d1 - d2;
    const double b0 = a[k] + 2.0 * tx * b1 - b2;
    const double e0 = da[k] + 2.0 * tx * e1 - e2;
    d2 = d1, d1 = d0;
    b2 = b1, b1 = b0;
    e2 = e1, e1 = e0;
  }
  return ValueSlopes{a[0] + tx * b1 - b2, (b1 + tx * d1 - d2) * 2.0 / (xb - xa),
                     (da[0] + tx * e1 - e2) * 2.0 / (yb - ya)};
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

// The same for a function of two variables at (x, y) in T, evaluated at
// their values (x0, y0).
template <typename T>
T Along(const ValueSlopes& f, double x0, const T& x, double y0, const T& y) {
  if constexpr (std::is_same_v<T, double>) {
    return f.value;
  } else {
    return T(f.value) + T(f.slope_x) * (x - T(x0)) + T(f.slope_y) * (y - T(y0));
  }
}

}  // namespace impactlab
