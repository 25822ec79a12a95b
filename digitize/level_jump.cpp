#include "digitize/level_jump.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "digitize/interpolate.h"
#include "digitize/minimize.h"

namespace impactlab::digitize {

namespace {

// D's antisymmetry about trial centres, on pairs s = step, 2 step, ... out to
// the window either side: r_k = D(m + s_k) + D(m - s_k) fitted as 2 mu plus,
// for each line, c (L(m + s_k) - L(m - s_k)) times how differently bright
// the two rows are at s_k as a share of the whole step; c in [0, 1].
class Antisymmetry {
 public:
  Antisymmetry(const std::vector<double>& offsets, const std::vector<double>& difference,
               const std::vector<std::vector<double>>& lines, double half_window_px)
      : d_(difference), lines_(lines), start_(offsets.front()), step_(offsets[1] - offsets[0]) {
    pairs_ = std::max(4, static_cast<int>(std::floor(half_window_px / step_)));
  }

  double HalfWindow() const { return pairs_ * step_; }

  double At(double u) const { return CatmullRom(d_, (u - start_) / step_); }

  // What of D about m is symmetric, less the lines' shares, over what is
  // antisymmetric: near 0 at the edge; about 1 on a stretch where D is flat,
  // which is as symmetric as anything, but holds no step.
  double Ratio(double m) const {
    const Fit fit = Solve(m);
    return fit.anti > 0.0 ? fit.rss / fit.anti : std::numeric_limits<double>::max();
  }

  // The residuals' RMS and the centre's standard deviation, the residuals'
  // correlation along s allowed for.
  void Uncertainty(double m, double* rms, double* sigma) const {
    const Fit fit = Solve(m);
    *rms = std::sqrt(fit.rss / std::max(1, pairs_ - fit.parameters - 1));
    double rho_sum = 0.0;
    for (int lag = 1; lag < pairs_ / 2 && fit.rss > 0.0; ++lag) {
      const double c = fit.residuals.head(pairs_ - lag).dot(fit.residuals.tail(pairs_ - lag));
      if (c <= 0.0) break;
      rho_sum += c / fit.rss;
    }
    // The residual sum's curvature in m with mu and the lines' coefficients
    // fitted afresh at each m: what a shift costs once they have taken up
    // all they can of it.
    const double h = 0.5 * step_;
    const double curvature = (Solve(m + h).rss - 2.0 * fit.rss + Solve(m - h).rss) / (h * h);
    *sigma = curvature > 0.0 && std::isfinite(curvature)
                 ? *rms * std::sqrt(2.0 / curvature) * std::sqrt(1.0 + 2.0 * rho_sum)
                 : std::numeric_limits<double>::infinity();
  }

 private:
  struct Fit {
    Eigen::VectorXd residuals;
    int parameters = 1;  // mu and the lines' free coefficients
    double rss = 0.0, anti = 0.0;
  };

  Fit Solve(double m) const {
    Fit fit;
    // How differently bright the two rows are at each pair, as a share of
    // the levels' whole step: what is left of a line there in D.
    Eigen::VectorXd r(pairs_), share(pairs_);
    double whole_step = 0.0;  // the levels' step, not the samples'
    for (int k = 1; k <= pairs_; ++k) {
      const double a = At(m + k * step_), b = At(m - k * step_);
      r[k - 1] = a + b;
      share[k - 1] = b - a;
      fit.anti += (b - a) * (b - a);
      whole_step = std::max(whole_step, b - a);
    }
    for (int k = 0; k < pairs_; ++k) {
      share[k] = whole_step > 0.0 ? std::clamp(share[k] / whole_step, -1.0, 1.0) : 0.0;
    }
    std::vector<Eigen::VectorXd> columns;
    for (const std::vector<double>& line : lines_) {
      Eigen::VectorXd column(pairs_);
      for (int k = 1; k <= pairs_; ++k) {
        column[k - 1] = share[k - 1] * (CatmullRom(line, (m + k * step_ - start_) / step_) -
                                        CatmullRom(line, (m - k * step_ - start_) / step_));
      }
      if (column.squaredNorm() > 1e-12) columns.push_back(std::move(column));
    }
    // A line's coefficient is the share of it that the tone curve keeps from
    // cancelling: between none and all of it. One past a bound is held there.
    Eigen::VectorXd coefficients;
    Eigen::MatrixXd design;
    for (;;) {
      const int p = 1 + static_cast<int>(columns.size());
      design.resize(pairs_, p);
      design.col(0).setOnes();
      for (int c = 1; c < p; ++c) design.col(c) = columns[c - 1];
      coefficients = design.colPivHouseholderQr().solve(r);
      int worst = -1;
      double most = 0.0;
      for (int c = 1; c < p; ++c) {
        const double past = std::max(-coefficients[c], coefficients[c] - 1.0);
        if (past > most) most = past, worst = c;
      }
      if (worst < 0) break;
      if (coefficients[worst] > 1.0) r -= columns[worst - 1];
      columns.erase(columns.begin() + (worst - 1));
    }
    fit.parameters = static_cast<int>(coefficients.size());
    fit.residuals = r - design * coefficients;
    fit.rss = fit.residuals.squaredNorm();
    return fit;
  }

  const std::vector<double>& d_;
  const std::vector<std::vector<double>>& lines_;
  double start_, step_;
  int pairs_ = 4;
};

// Where a row steps between its level and its background: the half-way
// crossing nearest the level's side, scanning from the end of the row where
// it is bright (`from_left`: the leaving row, bright at low offsets). The
// lines' light is taken out in proportion to how dark the row is there (a
// saturating tone curve shows a line fainter on the bright level).
double RowStep(const std::vector<double>& row, const std::vector<std::vector<double>>& lines,
               bool from_left) {
  const int n = static_cast<int>(row.size()), part = std::max(2, n / 8);
  std::vector<double> bright, dark;
  for (int i = 0; i < part; ++i) {
    bright.push_back(row[from_left ? i : n - 1 - i]);
    dark.push_back(row[from_left ? n - 1 - i : i]);
  }
  std::nth_element(bright.begin(), bright.begin() + part / 2, bright.end());
  std::nth_element(dark.begin(), dark.begin() + part / 2, dark.end());
  const double high = bright[part / 2], low = dark[part / 2];
  if (!(high > low)) return std::numeric_limits<double>::quiet_NaN();
  auto value = [&](int i) {
    double v = row[i];
    const double darkness = std::clamp((high - v) / (high - low), 0.0, 1.0);
    for (const std::vector<double>& line : lines) {
      if (line.size() == row.size()) v -= darkness * line[i];
    }
    return v;
  };
  const double half = 0.5 * (high + low);
  for (int k = 1; k < n; ++k) {
    const int i = from_left ? k : n - 1 - k, previous = from_left ? k - 1 : n - k;
    const double a = value(previous), b = value(i);
    if (b < half && a >= half) {
      return previous + (i - previous) * (a - half) / (a - b);  // an index
    }
  }
  return std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

LevelJump FitLevelJump(const std::vector<double>& offsets, const std::vector<double>& leaving,
                       const std::vector<double>& reaching, const LevelJumpSearch& search) {
  LevelJump jump;
  const std::size_t n = offsets.size();
  if (n < 8 || leaving.size() != n || reaching.size() != n) return jump;
  std::vector<double> difference(n);
  for (std::size_t i = 0; i < n; ++i) difference[i] = leaving[i] - reaching[i];
  const Antisymmetry antisymmetry(offsets, difference, search.lines, search.half_window_px);
  // Trial centres whose window lies within the samples (the interpolation
  // needs one beyond either end).
  const double step = offsets[1] - offsets[0], w = antisymmetry.HalfWindow();
  const double lo = std::max(search.centre_lo_px, offsets[1] + w + step);
  const double hi = std::min(search.centre_hi_px, offsets[n - 3] - w - step);
  if (!(hi > lo)) return jump;
  // Trial centres a quarter pixel apart (the ratio's valley is a beam's end
  // wide), then the best refined to a small fraction of a pixel.
  constexpr double kScan = 0.25;  // px
  const int trials = std::max(1, static_cast<int>(std::ceil((hi - lo) / kScan)));
  double best = std::numeric_limits<double>::max(), m = lo;
  for (int i = 0; i <= trials; ++i) {
    const double c = lo + (hi - lo) * i / trials;
    const double f = antisymmetry.Ratio(c);
    if (f < best) best = f, m = c;
  }
  m = RefineMinimum([&](double c) { return antisymmetry.Ratio(c); }, m, kScan, lo, hi, 7);
  jump.centre_px = m;
  jump.step = antisymmetry.At(m - w) - antisymmetry.At(m + w);
  antisymmetry.Uncertainty(m, &jump.residual_rms, &jump.sigma_px);
  const double margin = 0.1;  // px
  const double end = RowStep(leaving, search.lines, true);
  const double start = RowStep(reaching, search.lines, false);
  jump.leaving_end_px = offsets.front() + step * end;
  jump.reaching_start_px = offsets.front() + step * start;
  jump.found = jump.step > 5.0 * jump.residual_rms && m > lo + margin && m < hi - margin &&
               std::isfinite(jump.sigma_px);
  return jump;
}

}  // namespace impactlab::digitize
