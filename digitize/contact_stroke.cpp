#include "digitize/contact_stroke.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "digitize/minimize.h"

namespace impactlab::digitize {

namespace {

constexpr double kSigmaPerFwhm = 1.0 / 2.354820045;
// Neighbours beyond these take no part (a profile across a stroke crosses one
// grid line, two where lines are close).
constexpr int kMaxNeighbours = 3;
constexpr int kMaxColumns = 3 + 2 * kMaxNeighbours;
using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kMaxColumns>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxColumns, 1>;

double Gaussian(double d, double sigma) {
  const double z = d / sigma;
  return std::exp(-0.5 * z * z);
}

// The linear part of the model for one trial centre and width, by least
// squares: the columns are the background (1 and a slope), each neighbour,
// each neighbour's overlap with the stroke (the stroke's light scaled by the
// neighbour's, normalized to 1 at its peak) and the stroke. The stroke's and
// overlap columns change with every trial, the rest not: their products are
// computed once, and a trial costs a pass over the stroke's few samples.
//
// A neighbour only adds light: one whose coefficient would go negative is
// left out. A tone curve can at most take all of the stroke's light away on
// the neighbour's peak, or double it: an overlap coefficient beyond +-height
// is held at that bound (a term of the stroke's column). A stroke fainter
// than `height_lo` is held at it.
class Model {
 public:
  Model(const std::vector<double>& u, const std::vector<double>& v,
        const std::vector<StrokeNeighbour>& neighbours, const StrokeSearch& search)
      : u_(u), v_(v), search_(search), n_(static_cast<int>(u.size())) {
    mid_ = 0.5 * (u.front() + u.back());
    half_ = std::max(0.5 * (u.back() - u.front()), 1e-9);
    step_ = n_ > 1 ? (u.back() - u.front()) / (n_ - 1) : 1.0;
    for (std::size_t q = 0; q < neighbours.size(); ++q) {
      double peak = 0.0;
      for (double s : neighbours[q].shape) peak = std::max(peak, s);
      if (peak > 0.0 && static_cast<int>(neighbours[q].shape.size()) == n_ &&
          static_cast<int>(neighbours_.size()) < kMaxNeighbours) {
        neighbours_.push_back(&neighbours[q]);
        peaks_.push_back(peak);
        index_.push_back(static_cast<int>(q));
      }
    }
    k_ = static_cast<int>(neighbours_.size());
    f_ = 2 + k_;
    fixed_.assign(f_, std::vector<double>(n_));
    for (int i = 0; i < n_; ++i) {
      fixed_[0][i] = 1.0;
      fixed_[1][i] = (u[i] - mid_) / half_;
      for (int j = 0; j < k_; ++j) fixed_[2 + j][i] = neighbours_[j]->shape[i];
    }
    ff_.setZero(f_, f_);
    fv_.setZero(f_);
    vv_ = 0.0;
    for (int i = 0; i < n_; ++i) {
      for (int a = 0; a < f_; ++a) {
        fv_[a] += fixed_[a][i] * v[i];
        for (int b = a; b < f_; ++b) ff_(a, b) += fixed_[a][i] * fixed_[b][i];
      }
      vv_ += v[i] * v[i];
    }
    for (int a = 0; a < f_; ++a) {
      for (int b = 0; b < a; ++b) ff_(a, b) = ff_(b, a);
    }
  }

  struct State {
    std::array<bool, kMaxNeighbours> active{};  // neighbour in the model
    std::array<int, kMaxNeighbours> overlap{};  // 0: free; +-1: held at a bound; 2: none
  };

  struct Solution {
    double objective = std::numeric_limits<double>::max();  // residual sum of squares + priors
    double rss = std::numeric_limits<double>::max();        // residual sum of squares
    double height = 0.0;
    std::array<double, 2> background{};            // level and slope
    std::array<double, kMaxNeighbours> scale{};    // each neighbour's coefficient
    std::array<double, kMaxNeighbours> overlap{};  // each overlap coefficient
    State state;
  };

  Solution Solve(double centre, double fwhm) const {
    // The stroke and the overlaps, nonzero within 5 sigma of the centre:
    // their products with the fixed columns, each other and the data.
    const double sigma = fwhm * kSigmaPerFwhm;
    const int i0 =
        std::max(0, static_cast<int>(std::floor((centre - 5.0 * sigma - u_.front()) / step_)));
    const int i1 =
        std::min(n_, static_cast<int>(std::ceil((centre + 5.0 * sigma - u_.front()) / step_)) + 1);
    const int t = k_ + 1;  // g, then each neighbour's overlap
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kMaxNeighbours + 1> fg;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxNeighbours + 1, kMaxNeighbours + 1>
        q;
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxNeighbours + 1, 1> gv;
    fg.setZero(f_, t);
    q.setZero(t, t);
    gv.setZero(t);
    std::array<double, kMaxNeighbours + 1> column{};
    for (int i = i0; i < i1; ++i) {
      const double g = Gaussian(u_[i] - centre, sigma);
      column[0] = g;
      for (int j = 0; j < k_; ++j) column[1 + j] = g * neighbours_[j]->shape[i] / peaks_[j];
      for (int a = 0; a < t; ++a) {
        if (column[a] == 0.0) continue;
        for (int m = 0; m < f_; ++m) fg(m, a) += fixed_[m][i] * column[a];
        for (int b = a; b < t; ++b) q(a, b) += column[a] * column[b];
        gv[a] += column[a] * v_[i];
      }
    }
    for (int a = 0; a < t; ++a) {
      for (int b = 0; b < a; ++b) q(a, b) = q(b, a);
    }

    State state;
    for (int j = 0; j < k_; ++j) {
      state.active[j] = true;
      state.overlap[j] = search_.overlap_term ? 0 : 2;
    }
    Solution out;
    for (int iteration = 0; iteration < 4 * k_ + 3; ++iteration) {
      // Columns: the fixed ones in the model, the free overlaps, the stroke
      // (with the held overlaps in it), each a combination of g and the
      // overlaps for the varying ones.
      std::array<int, kMaxColumns> fixed_of{};
      int fixed_count = 0;
      fixed_of[fixed_count++] = 0;
      fixed_of[fixed_count++] = 1;
      for (int j = 0; j < k_; ++j) {
        if (state.active[j]) fixed_of[fixed_count++] = 2 + j;
      }
      std::array<std::array<double, kMaxNeighbours + 1>, kMaxNeighbours + 1> varying{};
      std::array<int, kMaxNeighbours> free_of{};
      int varying_count = 0;
      for (int j = 0; j < k_; ++j) {
        if (state.active[j] && state.overlap[j] == 0) {
          varying[varying_count] = {};
          varying[varying_count][1 + j] = 1.0;
          free_of[varying_count++] = j;
        }
      }
      std::array<double, kMaxNeighbours + 1> stroke{};
      stroke[0] = 1.0;
      for (int j = 0; j < k_; ++j) {
        if (state.active[j] && (state.overlap[j] == 1 || state.overlap[j] == -1)) {
          stroke[1 + j] = Bound(state.overlap[j]);
        }
      }
      varying[varying_count++] = stroke;
      const int p = fixed_count + varying_count;
      Small normal(p, p);
      SmallVector rhs(p);
      auto dot_fixed_varying = [&](int m, const std::array<double, kMaxNeighbours + 1>& a) {
        double sum = 0.0;
        for (int s = 0; s < t; ++s) sum += a[s] * fg(m, s);
        return sum;
      };
      for (int r = 0; r < fixed_count; ++r) {
        for (int c = 0; c < fixed_count; ++c) normal(r, c) = ff_(fixed_of[r], fixed_of[c]);
        for (int c = 0; c < varying_count; ++c) {
          normal(r, fixed_count + c) = normal(fixed_count + c, r) =
              dot_fixed_varying(fixed_of[r], varying[c]);
        }
        rhs[r] = fv_[fixed_of[r]];
      }
      for (int r = 0; r < varying_count; ++r) {
        for (int c = 0; c < varying_count; ++c) {
          double sum = 0.0;
          for (int a = 0; a < t; ++a) {
            for (int b = 0; b < t; ++b) sum += varying[r][a] * q(a, b) * varying[c][b];
          }
          normal(fixed_count + r, fixed_count + c) = sum;
        }
        double sum = 0.0;
        for (int a = 0; a < t; ++a) sum += varying[r][a] * gv[a];
        rhs[fixed_count + r] = sum;
      }
      double prior_constant = 0.0;
      for (int r = 2; r < fixed_count; ++r) {
        const StrokeNeighbour& neighbour = *neighbours_[fixed_of[r] - 2];
        const double weight = PriorWeight(neighbour);
        normal(r, r) += weight;
        rhs[r] += weight * neighbour.prior;
        prior_constant += weight * neighbour.prior * neighbour.prior;
      }
      // Keeps a column that no sample lights (a stroke off the profile) from
      // making the system singular.
      for (int r = 0; r < p; ++r) normal(r, r) += 1e-12 * (1.0 + normal(r, r));
      SmallVector b = normal.ldlt().solve(rhs);
      if (b[p - 1] < search_.height_lo && search_.height_lo > 0.0) {
        const double h = search_.height_lo;
        const SmallVector reduced = normal.topLeftCorner(p - 1, p - 1)
                                        .ldlt()
                                        .solve(rhs.head(p - 1) - h * normal.col(p - 1).head(p - 1));
        b.head(p - 1) = reduced;
        b[p - 1] = h;
      }
      const double height = b[p - 1];
      // Neighbours taking light away, then overlaps past their bounds.
      int worst = -1;
      double most_negative = 0.0;
      for (int r = 2; r < fixed_count; ++r) {
        if (b[r] < most_negative) most_negative = b[r], worst = fixed_of[r] - 2;
      }
      if (worst >= 0) {
        state.active[worst] = false;
        continue;
      }
      int past = -1;
      double most_past = 0.0;
      for (int r = 0; r + 1 < varying_count && height > 0.0; ++r) {
        const double o = b[fixed_count + r];
        const double excess = o > 0.0 ? o - Bound(1) * height : -o - height;
        if (excess > most_past) most_past = excess, past = r;
      }
      if (past >= 0) {
        state.overlap[free_of[past]] = b[fixed_count + past] > 0.0 ? 1 : -1;
        continue;
      }
      out.objective = b.dot(normal * b) - 2.0 * b.dot(rhs) + vv_ + prior_constant;
      double prior_part = 0.0;
      for (int r = 2; r < fixed_count; ++r) {
        const StrokeNeighbour& neighbour = *neighbours_[fixed_of[r] - 2];
        prior_part += PriorWeight(neighbour) * (b[r] - neighbour.prior) * (b[r] - neighbour.prior);
        out.scale[fixed_of[r] - 2] = b[r];
      }
      out.rss = std::max(0.0, out.objective - prior_part);
      if (!std::isfinite(out.objective))
        out.objective = out.rss = std::numeric_limits<double>::max();
      out.height = height;
      out.background = {b[0], b[1]};
      for (int r = 0; r + 1 < varying_count; ++r) out.overlap[free_of[r]] = b[fixed_count + r];
      for (int j = 0; j < k_; ++j) {
        if (state.active[j] && (state.overlap[j] == 1 || state.overlap[j] == -1)) {
          out.overlap[j] = Bound(state.overlap[j]) * height;
        }
      }
      out.state = state;
      return out;
    }
    return out;
  }

  // The centre's standard deviation per unit of white noise on the samples,
  // from the whole model's Jacobian (the centre and width too) at a solution.
  double CentrePerNoise(double centre, double fwhm, bool width_free, const Solution& s) const {
    const double sigma = fwhm * kSigmaPerFwhm;
    std::vector<int> neighbour_columns, overlap_columns;
    for (int j = 0; j < k_; ++j) {
      if (!s.state.active[j]) continue;
      neighbour_columns.push_back(j);
      if (s.state.overlap[j] == 0) overlap_columns.push_back(j);
    }
    const int p = 2 + static_cast<int>(neighbour_columns.size() + overlap_columns.size()) + 1 + 1 +
                  (width_free ? 1 : 0);
    Eigen::MatrixXd jacobian(n_, p);
    for (int i = 0; i < n_; ++i) {
      const double d = u_[i] - centre, g = Gaussian(d, sigma);
      int c = 0;
      jacobian(i, c++) = 1.0;
      jacobian(i, c++) = fixed_[1][i];
      for (int j : neighbour_columns) jacobian(i, c++) = neighbours_[j]->shape[i];
      // The stroke's amplitude here, overlaps included, and its column.
      double amplitude = s.height, column = g;
      for (int j = 0; j < k_; ++j) {
        if (!s.state.active[j] || s.state.overlap[j] == 2) continue;
        const double normalized = neighbours_[j]->shape[i] / peaks_[j];
        amplitude += s.overlap[j] * normalized;
        if (s.state.overlap[j] != 0) column += Bound(s.state.overlap[j]) * normalized * g;
      }
      for (int j : overlap_columns) jacobian(i, c++) = g * neighbours_[j]->shape[i] / peaks_[j];
      jacobian(i, c++) = column;
      jacobian(i, c++) = amplitude * g * d / (sigma * sigma);
      if (width_free) jacobian(i, c++) = amplitude * g * d * d / (sigma * sigma * fwhm);
    }
    Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    for (std::size_t q = 0; q < neighbour_columns.size(); ++q) {
      normal(2 + q, 2 + q) += PriorWeight(*neighbours_[neighbour_columns[q]]);
    }
    const int centre_column = p - 1 - (width_free ? 1 : 0);
    const Eigen::MatrixXd inverse =
        normal.ldlt().solve(Eigen::MatrixXd::Identity(normal.rows(), normal.cols()));
    const double variance = inverse(centre_column, centre_column);
    return variance > 0.0 && std::isfinite(variance) ? std::sqrt(variance)
                                                     : std::numeric_limits<double>::infinity();
  }

  // Each of the caller's neighbours' coefficient (0 when left out) and the
  // nearest's overlap coefficient relative to the stroke's height.
  void Coefficients(const Solution& s, std::size_t neighbours, std::vector<double>* scales,
                    double* overlap) const {
    scales->assign(neighbours, 0.0);
    *overlap = 0.0;
    for (int j = 0; j < k_; ++j) {
      if (s.state.active[j]) (*scales)[index_[j]] = s.scale[j];
      if (index_[j] == 0 && s.height > 0.0) *overlap = s.overlap[j] / s.height;
    }
  }

  // How many times more the centre scatters than white noise of the
  // residuals' size would make it: the residuals' correlation along the
  // profile (blur, JPEG blocks, grain, and what the model misses, all
  // spread over several samples) leaves fewer independent samples.
  double CorrelationFactor(double centre, double fwhm, const Solution& s) const {
    const double sigma = fwhm * kSigmaPerFwhm;
    std::vector<double> r(n_);
    double mean = 0.0;
    for (int i = 0; i < n_; ++i) {
      const double g = Gaussian(u_[i] - centre, sigma);
      double model = s.background[0] + s.background[1] * fixed_[1][i] + s.height * g;
      for (int j = 0; j < k_; ++j) {
        if (!s.state.active[j]) continue;
        model += s.scale[j] * neighbours_[j]->shape[i];
        if (s.state.overlap[j] != 2)
          model += s.overlap[j] * g * neighbours_[j]->shape[i] / peaks_[j];
      }
      r[i] = v_[i] - model;
      mean += r[i];
    }
    mean /= n_;
    double c0 = 0.0;
    for (double& x : r) x -= mean, c0 += x * x;
    if (!(c0 > 0.0)) return 1.0;
    double sum = 0.0;
    for (int lag = 1; lag < n_ / 4; ++lag) {
      double c = 0.0;
      for (int i = 0; i + lag < n_; ++i) c += r[i] * r[i + lag];
      const double rho = c / c0;
      if (rho <= 0.0) break;
      sum += rho;
    }
    return std::sqrt(1.0 + 2.0 * sum);
  }

 private:
  // How far the overlap's coefficient may go, relative to the stroke's
  // height, on either side.
  static double Bound(int side) { return side > 0 ? 1.0 : -1.0; }

  // A prior's weight in the normal equations: noise^2 / prior_sigma^2.
  double PriorWeight(const StrokeNeighbour& neighbour) const {
    if (!(neighbour.prior_sigma > 0.0) || !(search_.noise > 0.0)) return 0.0;
    return search_.noise * search_.noise / (neighbour.prior_sigma * neighbour.prior_sigma);
  }

  const std::vector<double>& u_;
  const std::vector<double>& v_;
  StrokeSearch search_;
  int n_ = 0, k_ = 0, f_ = 0;
  std::vector<const StrokeNeighbour*> neighbours_;
  std::vector<double> peaks_;
  std::vector<int> index_;  // each one's place among the caller's neighbours
  std::vector<std::vector<double>> fixed_;
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxColumns, kMaxColumns> ff_;
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxColumns, 1> fv_;
  double vv_ = 0.0;
  double mid_ = 0.0, half_ = 1.0, step_ = 1.0;
};

}  // namespace

std::vector<double> GaussianShape(const std::vector<double>& offsets, double centre_px,
                                  double fwhm_px) {
  std::vector<double> shape;
  shape.reserve(offsets.size());
  for (double u : offsets) shape.push_back(Gaussian(u - centre_px, fwhm_px * kSigmaPerFwhm));
  return shape;
}

StrokeFit FitStroke(const std::vector<double>& offsets, const std::vector<double>& values,
                    const std::vector<StrokeNeighbour>& neighbours, const StrokeSearch& search) {
  StrokeFit fit;
  const int n = static_cast<int>(offsets.size());
  const double lo = search.centre_lo_px, hi = search.centre_hi_px;
  const double w_lo = search.fwhm_lo_px, w_hi = search.fwhm_hi_px;
  if (n < 8 || static_cast<int>(values.size()) != n || !(hi >= lo) || !(w_hi >= w_lo) ||
      !(w_lo > 0.0)) {
    return fit;
  }
  const Model model(offsets, values, neighbours, search);
  auto cost = [&](double c, double w) {
    const Model::Solution s = model.Solve(c, w);
    // A dark stroke is no stroke: worse than any bright one.
    return s.height > 0.0 ? s.objective : std::numeric_limits<double>::max();
  };
  // A grid of trial centres and widths, then refined coordinate by coordinate.
  constexpr double kCentreStep = 0.5;
  const bool width_free = w_hi > w_lo;
  const int widths = width_free ? 5 : 1;
  const int centres = std::max(1, static_cast<int>(std::ceil((hi - lo) / kCentreStep)));
  double best = std::numeric_limits<double>::max(), c = 0.5 * (lo + hi), w = w_lo;
  for (int i = 0; i <= centres; ++i) {
    const double ci = lo + (hi - lo) * i / centres;
    for (int k = 0; k < widths; ++k) {
      const double wk = width_free ? w_lo * std::pow(w_hi / w_lo, k / (widths - 1.0)) : w_lo;
      const double f = cost(ci, wk);
      if (f < best) best = f, c = ci, w = wk;
    }
  }
  if (best == std::numeric_limits<double>::max()) return fit;
  for (int round = 0; round < (width_free ? 3 : 1); ++round) {
    c = RefineMinimum([&](double x) { return cost(x, w); }, c, kCentreStep, lo, hi, 7);
    if (width_free) {
      w = RefineMinimum([&](double x) { return cost(c, x); }, w, 0.15 * w, w_lo, w_hi, 6);
    }
  }
  const Model::Solution solution = model.Solve(c, w);
  if (!(solution.height > 0.0)) return fit;
  // A centre pressed against the search's end is no stroke found there.
  const double margin = 0.5 * kCentreStep;
  fit.found = c > lo + margin && c < hi - margin;
  fit.centre_px = c;
  fit.fwhm_px = w;
  fit.height = solution.height;
  fit.residual_rms = std::sqrt(solution.rss / std::max(1, n - 6));
  model.Coefficients(solution, neighbours.size(), &fit.neighbour_scales, &fit.overlap);
  fit.centre_per_noise_px = model.CentrePerNoise(c, w, width_free, solution);
  fit.correlation = model.CorrelationFactor(c, w, solution);
  return fit;
}

}  // namespace impactlab::digitize
