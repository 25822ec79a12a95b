// Long-double references shared by the numerical-stability suites: computed
// independently of the library, without cancellation.
#pragma once

#include <cmath>

#include "tests/support/precision.h"

namespace impactlab::testing {

// binom(2n, n) / 4^n, the coefficients of 1/sqrt(1 - x) and of asin.
inline LD CentralBinomialOver4n(int n) {
  LD a = 1.0L;
  for (int i = 0; i < n; ++i) a *= static_cast<LD>(2 * i + 1) / static_cast<LD>(2 * i + 2);
  return a;
}

// asin u: Maclaurin series for |u| <= 1e-3 (9 terms, truncation < 1e-48
// relative), atan2(u, sqrt((1 - u)(1 + u))) otherwise (the library uses asin).
inline LD RefAsin(LD u) {
  if (fabsl(u) <= 1e-3L) {
    LD sum = 0.0L, power = u;
    for (int n = 0; n < 9; ++n, power *= u * u) {
      sum += CentralBinomialOver4n(n) * power / (2 * n + 1);
    }
    return sum;
  }
  return atan2l(u, sqrtl((1.0L - u) * (1.0L + u)));
}

// sin(asin(u)/2) = u / sqrt(2 (1 + sqrt(1 - u^2))): no trigonometry, no cancellation.
inline LD RefHalfAngleSine(LD u) {
  return u / sqrtl(2.0L * (1.0L + sqrtl((1.0L - u) * (1.0L + u))));
}

// h(zeta) = acos(zeta)/sqrt(1 - zeta^2) (acosh(zeta)/sqrt(zeta^2 - 1) above 1).
// Near zeta = 1, with u = 1 - zeta (exact) and x = u/2:
//   acos(1 - u) = 2 asin(sqrt(x)) = sqrt(2u) sum binom(2n,n)/(4^n (2n+1)) x^n
//   sqrt(1 - zeta^2) = sqrt(2u) sqrt(1 - x)
// so h = [sum binom(2n,n)/(4^n (2n+1)) x^n] * [sum binom(2m,m)/4^m x^m], an
// analytic series valid on both sides of zeta = 1 (|x| < 1); used for
// |u| <= 1/16 (40 terms, truncation < 1e-60). Elsewhere atan2 (zeta < 1) or
// asinh(sqrt(zeta^2 - 1)) (zeta > 1), both well conditioned.
inline LD RefH(LD zeta) {
  const LD u = 1.0L - zeta;
  if (fabsl(u) <= 1.0L / 16.0L) {
    const LD x = u / 2.0L;
    LD asin_part = 0.0L, root_part = 0.0L, power = 1.0L;
    for (int n = 0; n < 40; ++n, power *= x) {
      const LD a = CentralBinomialOver4n(n);
      asin_part += a / (2 * n + 1) * power;
      root_part += a * power;
    }
    return asin_part * root_part;
  }
  if (zeta < 1.0L) {
    const LD s = sqrtl(u * (1.0L + zeta));
    return atan2l(s, zeta) / s;
  }
  const LD s = sqrtl((zeta - 1.0L) * (zeta + 1.0L));
  return asinhl(s) / s;
}

}  // namespace impactlab::testing
