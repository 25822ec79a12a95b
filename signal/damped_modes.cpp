#include "signal/damped_modes.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>

#include <ceres/ceres.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "signal/qr_compressed_cost.h"
#include "signal/signal_internal.h"
#include "signal/singular_vectors.h"
#include "signal/spectrum.h"

namespace impactlab {
namespace {

using signal_internal::kTwoPi;
constexpr double kMaxDampingRatio = 0.95;
constexpr double kMinDampingRatio = -0.3;  // allows growth, so light damping is not biased up

// Decay rate from damped frequency and damping ratio.
double DecayRate(double frequency_hz, double zeta) {
  return kTwoPi * frequency_hz * zeta / std::sqrt(1.0 - zeta * zeta);
}

// A pole of the signal: a damped mode (frequency > 0) or a real decay (0).
struct Pole {
  double frequency_hz = 0.0;
  double decay_per_s = 0.0;
  bool oscillating() const { return frequency_hz > 0.0; }
  double zeta() const { return decay_per_s / std::hypot(decay_per_s, kTwoPi * frequency_hz); }
};

// A pole with its linear amplitudes: a cos + b sin (mode) or a (decay).
struct Term {
  Pole pole;
  double a = 0.0, b = 0.0;
  double energy = 0.0;  // sum of the term's squared samples over the window
};

struct LinearFit {
  std::vector<Term> terms;  // by decreasing energy
  double offset = 0.0;
  double noise_variance = 0.0;
};

// exp(s t_i) at t_i = i dt, i = 0, 1, ..., for a complex rate s, a block of
// kBlock values at a time: exp(s t_b) at the block's start times exp(s j dt),
// j < kBlock, from a table made once. exp, cos and sin per sample were a
// third of the logs sample's CPU, and stepping each value from the last (one
// complex product) made a chain of dependent products, each waiting for the
// one before; these products are independent, and each value is within a few
// ulps (two exponentials and a product) wherever it lies in its block.
class SampledExponential {
 public:
  SampledExponential(std::complex<double> rate, double interval_s)
      : rate_(rate), interval_s_(interval_s) {
    for (std::size_t j = 0; j < kBlock; ++j) {
      const std::complex<double> z = std::exp(rate * (interval_s * static_cast<double>(j)));
      table_re_[j] = z.real();
      table_im_[j] = z.imag();
    }
  }

  std::complex<double> Next() {
    const std::size_t j = i_ % kBlock;
    if (j == 0) Fill();
    ++i_;
    return {re_[j], im_[j]};
  }

 private:
  static constexpr std::size_t kBlock = 64;

  // The block from i_ on; the product written out in reals (std::complex's
  // checks for inf and NaN would keep it from vectorising).
  void Fill() {
    const std::complex<double> anchor = std::exp(rate_ * (interval_s_ * static_cast<double>(i_)));
    const double ar = anchor.real(), ai = anchor.imag();
    for (std::size_t j = 0; j < kBlock; ++j) {
      re_[j] = ar * table_re_[j] - ai * table_im_[j];
      im_[j] = ar * table_im_[j] + ai * table_re_[j];
    }
  }

  std::complex<double> rate_;
  double interval_s_;
  std::array<double, kBlock> table_re_{}, table_im_{}, re_{}, im_{};
  std::size_t i_ = 0;
};

// c + sum of modes exp(-sigma t)(a cos w t + b sin w t) + sum of decays
// B exp(-r t) minus the samples, with derivatives column-major by the blocks
// (a, b, f, zeta) of each mode, (B, r) of each decay, then c.
class DampedModesModel {
 public:
  DampedModesModel(std::span<const double> y, double interval_s, int modes, int decays, bool offset)
      : y_(y), interval_s_(interval_s), modes_(modes), decays_(decays), offset_(offset) {}

  int parameters() const { return 4 * modes_ + 2 * decays_ + (offset_ ? 1 : 0); }
  std::vector<int> block_sizes() const {
    std::vector<int> sizes(static_cast<std::size_t>(modes_), 4);
    sizes.insert(sizes.end(), static_cast<std::size_t>(decays_), 2);
    if (offset_) sizes.push_back(1);
    return sizes;
  }

  // `jacobian`, when not null: y.size() x parameters(), column-major.
  bool operator()(double const* const* parameters, double* residuals, double* jacobian) const {
    const std::size_t n = y_.size();
    const double c = offset_ ? parameters[modes_ + decays_][0] : 0.0;
    for (std::size_t i = 0; i < n; ++i) residuals[i] = c - y_[i];
    for (int k = 0; k < modes_; ++k) {
      const double* p = parameters[k];
      const double a = p[0], b = p[1], f = p[2], zeta = p[3];
      if (!(std::abs(zeta) < 1.0)) return false;
      const double omega = kTwoPi * f;
      const double root = std::sqrt(1.0 - zeta * zeta);
      const double sigma = omega * zeta / root;
      const double dsigma_df = kTwoPi * zeta / root;
      const double dsigma_dzeta = omega / (root * root * root);
      double* jac = jacobian ? jacobian + 4 * k * n : nullptr;
      SampledExponential phasor({-sigma, omega}, interval_s_);
      for (std::size_t i = 0; i < n; ++i) {
        const double t = interval_s_ * static_cast<double>(i);
        const std::complex<double> z = phasor.Next();  // e (cos wt + i sin wt)
        const double ecw = z.real(), esw = z.imag();
        const double m = a * ecw + b * esw;
        residuals[i] += m;
        if (jac) {
          const double dm_domega = t * (b * ecw - a * esw);
          const double dm_dsigma = -t * m;
          jac[i] = ecw;
          jac[n + i] = esw;
          jac[2 * n + i] = kTwoPi * dm_domega + dm_dsigma * dsigma_df;
          jac[3 * n + i] = dm_dsigma * dsigma_dzeta;
        }
      }
    }
    for (int j = 0; j < decays_; ++j) {
      const double* p = parameters[modes_ + j];
      double* jac = jacobian ? jacobian + (4 * modes_ + 2 * j) * n : nullptr;
      SampledExponential decay({-p[1], 0.0}, interval_s_);
      for (std::size_t i = 0; i < n; ++i) {
        const double t = interval_s_ * static_cast<double>(i);
        const double e = decay.Next().real();
        residuals[i] += p[0] * e;
        if (jac) {
          jac[i] = e;
          jac[n + i] = -t * p[0] * e;
        }
      }
    }
    if (offset_ && jacobian) {
      std::fill_n(jacobian + (4 * modes_ + 2 * decays_) * n, n, 1.0);
    }
    // A trial step with a growing decay (r < 0) overflows: say the step is
    // infeasible, as Ceres then expects, rather than hand it inf (which it
    // rejects the same way, but only after logging the whole block).
    for (std::size_t i = 0; i < n; ++i) {
      if (!std::isfinite(residuals[i])) return false;
    }
    return true;
  }

 private:
  std::span<const double> y_;
  double interval_s_;
  int modes_, decays_;
  bool offset_;
};

// Poles of the pencil on block averages of `y`.
std::vector<Pole> PencilPoles(std::span<const double> y, double sample_rate_hz,
                              double max_frequency_hz, int order,
                              const DampedModeOptions& options) {
  const std::size_t n = y.size();
  // Block averaging by D keeps every pole (as z^D) and must not alias the band.
  const auto max_block =
      std::max<std::size_t>(1, static_cast<std::size_t>(sample_rate_hz / (2.2 * max_frequency_hz)));
  const auto wanted = static_cast<std::size_t>(options.pencil_max_samples);
  const std::size_t block =
      std::min(max_block, std::max<std::size_t>(1, (n + wanted - 1) / wanted));
  const std::size_t m = std::min(wanted, n / block);
  Eigen::VectorXd x(static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < m; ++i) {
    double sum = 0.0;
    for (std::size_t j = 0; j < block; ++j) sum += y[i * block + j];
    x(static_cast<Eigen::Index>(i)) = sum / static_cast<double>(block);
  }
  const auto pencil = static_cast<Eigen::Index>(
      std::clamp<double>(std::round(options.pencil_fraction * static_cast<double>(m)), 2.0,
                         static_cast<double>(m) / 2.0));
  const Eigen::Index rows = static_cast<Eigen::Index>(m) - pencil;
  const Eigen::Index p = std::min<Eigen::Index>(order, pencil - 1);
  if (rows < 2 || p < 1) return {};
  Eigen::MatrixXd hankel(rows, pencil + 1);
  for (Eigen::Index i = 0; i < rows; ++i) {
    for (Eigen::Index j = 0; j <= pencil; ++j) hankel(i, j) = x(i + j);
  }
  const Eigen::MatrixXd v = LeadingRightSingularVectors(hankel, p);
  const Eigen::MatrixXd v1 = v.topRows(pencil);
  const Eigen::MatrixXd v2 = v.bottomRows(pencil);
  const Eigen::MatrixXd a = v1.completeOrthogonalDecomposition().solve(v2);
  const Eigen::VectorXcd z = a.eigenvalues();

  const double interval = static_cast<double>(block) / sample_rate_hz;
  // The span the pencil saw: a pole with less than one cycle in it cannot be
  // told from a decay.
  const double span_s = static_cast<double>(m * block) / sample_rate_hz;
  const double window_s = static_cast<double>(n) / sample_rate_hz;
  std::vector<Pole> poles;
  for (Eigen::Index i = 0; i < z.size(); ++i) {
    if (std::abs(z(i)) == 0.0 || z(i).imag() < 0.0) continue;  // each pair once
    const std::complex<double> s = std::log(z(i)) / interval;
    Pole pole{s.imag() / kTwoPi, -s.real()};
    if (pole.frequency_hz > max_frequency_hz) continue;
    if (pole.frequency_hz * span_s < 1.0) {
      // A decay slower than e-fold over the window is the offset's job: the two
      // could not be told apart.
      pole.frequency_hz = 0.0;
      if (pole.decay_per_s * window_s >= 1.0) poles.push_back(pole);
      continue;
    }
    const double zeta = pole.zeta();
    if (zeta > kMinDampingRatio && zeta < kMaxDampingRatio) poles.push_back(pole);
  }
  return poles;
}

// Linear least squares for the amplitudes of the given poles (and c).
LinearFit LinearAmplitudes(std::span<const double> y, double sample_rate_hz,
                           const std::vector<Pole>& poles, bool offset) {
  const auto n = static_cast<Eigen::Index>(y.size());
  std::vector<Eigen::Index> column_of;
  Eigen::Index columns = 0;
  for (const Pole& pole : poles) {
    column_of.push_back(columns);
    columns += pole.oscillating() ? 2 : 1;
  }
  if (offset) ++columns;
  Eigen::MatrixXd basis(n, columns);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / sample_rate_hz;
    for (std::size_t j = 0; j < poles.size(); ++j) {
      const double e = std::exp(-poles[j].decay_per_s * t);
      const double w = kTwoPi * poles[j].frequency_hz * t;
      basis(i, column_of[j]) = e * std::cos(w);
      if (poles[j].oscillating()) basis(i, column_of[j] + 1) = e * std::sin(w);
    }
    if (offset) basis(i, columns - 1) = 1.0;
  }
  const Eigen::Map<const Eigen::VectorXd> target(y.data(), n);
  const Eigen::VectorXd x = basis.colPivHouseholderQr().solve(target);
  LinearFit fit;
  fit.offset = offset ? x(columns - 1) : 0.0;
  fit.noise_variance = (basis * x - target).squaredNorm() /
                       static_cast<double>(std::max<Eigen::Index>(1, n - columns));
  for (std::size_t j = 0; j < poles.size(); ++j) {
    Term term;
    term.pole = poles[j];
    const Eigen::Index c = column_of[j];
    const Eigen::Index width = poles[j].oscillating() ? 2 : 1;
    term.a = x(c);
    term.b = width == 2 ? x(c + 1) : 0.0;
    term.energy = (basis.middleCols(c, width) * x.segment(c, width)).squaredNorm();
    fit.terms.push_back(term);
  }
  std::sort(fit.terms.begin(), fit.terms.end(),
            [](const Term& p, const Term& q) { return p.energy > q.energy; });
  return fit;
}

// The band the pencil must resolve: the option, or 1.5 x the highest of the
// window's leading spectral peaks (at least twice the strongest), so block
// averaging can bring a long window down to the pencil's size.
double MaxFrequency(std::span<const double> samples, double sample_rate_hz,
                    const DampedModeOptions& options) {
  const double limit = 0.45 * sample_rate_hz;
  if (options.max_frequency_hz > 0.0) return std::min(options.max_frequency_hz, limit);
  if (samples.size() < 64) return limit;
  SpectrumOptions spectrum;
  spectrum.detrend = Detrend::kMean;
  spectrum.zero_padding = 2.0;
  spectrum.max_peaks = options.modes + options.extra_modes;
  spectrum.refine_iterations = 0;
  const std::vector<SpectralPeak> peaks = ComputeSpectrum(samples, sample_rate_hz, spectrum).peaks;
  if (peaks.empty()) return limit;
  double highest = 0.0;
  for (const SpectralPeak& peak : peaks) highest = std::max(highest, peak.frequency_hz);
  return std::min(limit, std::max(1.5 * highest, 2.0 * peaks[0].frequency_hz));
}

int PencilOrder(const DampedModeOptions& options) {
  return 2 * (options.modes + options.extra_modes) + options.decays + (options.fit_offset ? 1 : 0);
}

DampedMode ToMode(const Term& term) {
  DampedMode mode;
  const double zeta = term.pole.zeta();
  mode.frequency_hz.value = term.pole.frequency_hz;
  mode.damping_ratio.value = zeta;
  mode.amplitude.value = std::hypot(term.a, term.b);
  mode.phase_rad.value = std::atan2(-term.b, term.a);
  mode.natural_frequency_hz = term.pole.frequency_hz / std::sqrt(1.0 - zeta * zeta);
  mode.decay_rate_per_s = term.pole.decay_per_s;
  mode.energy = term.energy;
  return mode;
}

// The pencil's start, by energy, before the significance test.
LinearFit PencilStart(std::span<const double> samples, double sample_rate_hz,
                      const DampedModeOptions& options) {
  const std::vector<Pole> poles =
      PencilPoles(samples, sample_rate_hz, MaxFrequency(samples, sample_rate_hz, options),
                  PencilOrder(options), options);
  return LinearAmplitudes(samples, sample_rate_hz, poles, options.fit_offset);
}

}  // namespace

bool DampedModeOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (modes < 1) return fail("modes must be at least 1");
  if (decays < 0) return fail("decays must be >= 0");
  if (!(min_term_snr >= 0.0)) return fail("min_term_snr must be >= 0");
  if (extra_modes < 0) return fail("extra_modes must be >= 0");
  if (pencil_max_samples < 16) return fail("pencil_max_samples must be at least 16");
  if (!(pencil_fraction >= 0.2 && pencil_fraction <= 0.5)) {
    return fail("pencil_fraction must lie in [0.2, 0.5] (Hua & Sarkar: N/3 .. N/2 is best)");
  }
  if (!(max_frequency_hz >= 0.0)) return fail("max_frequency_hz must be >= 0");
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  if (!(function_tolerance > 0.0)) return fail("function_tolerance must be positive");
  return true;
}

std::vector<DampedMode> MatrixPencilModes(std::span<const double> samples, double sample_rate_hz,
                                          const DampedModeOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("DampedModeOptions: " + error);
  }
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("damped modes: rate must be > 0");
  std::vector<DampedMode> modes;
  for (const Term& term : PencilStart(samples, sample_rate_hz, options).terms) {
    if (term.pole.oscillating()) modes.push_back(ToMode(term));
  }
  return modes;
}

DampedModeFit FitDampedModes(std::span<const double> samples, double sample_rate_hz,
                             const DampedModeOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("DampedModeOptions: " + error);
  }
  if (!(sample_rate_hz > 0.0)) throw std::invalid_argument("damped modes: rate must be > 0");
  const auto started = std::chrono::steady_clock::now();
  DampedModeFit fit;
  fit.samples = static_cast<int>(samples.size());
  const int most_parameters = 4 * options.modes + 2 * options.decays + (options.fit_offset ? 1 : 0);
  if (static_cast<int>(samples.size()) < 3 * most_parameters + 16) {
    fit.reason =
        fmt::format("{} samples are too few for {} mode(s)", samples.size(), options.modes);
    return fit;
  }

  // Starting values: the pencil's poles with amplitudes by linear least
  // squares; only terms the data support.
  const LinearFit start = PencilStart(samples, sample_rate_hz, options);
  double total_energy = 0.0;
  for (double v : samples) total_energy += (v - start.offset) * (v - start.offset);
  const double floor = std::max(options.min_term_snr * start.noise_variance, 1e-12 * total_energy);
  // Two poles closer than the window's resolution (1 / duration) are one mode
  // the pencil split: the weaker is dropped.
  const double resolution_hz = sample_rate_hz / static_cast<double>(samples.size());
  auto resolved = [&](const std::vector<Term>& chosen, const Term& term) {
    return std::none_of(chosen.begin(), chosen.end(), [&](const Term& other) {
      return std::abs(other.pole.frequency_hz - term.pole.frequency_hz) < resolution_hz;
    });
  };
  std::vector<Term> modes, decays;
  for (const Term& term : start.terms) {
    if (term.pole.oscillating()) fit.pencil_modes.push_back(ToMode(term));
    if (term.energy <= floor) continue;
    if (term.pole.oscillating() && static_cast<int>(modes.size()) < options.modes) {
      if (resolved(modes, term)) modes.push_back(term);
    } else if (!term.pole.oscillating() && static_cast<int>(decays.size()) < options.decays) {
      decays.push_back(term);
    }
  }
  if (modes.empty()) {
    fit.reason = "the matrix pencil found no oscillating mode above the noise";
    return fit;
  }
  const int mode_count = static_cast<int>(modes.size());
  const int decay_count = static_cast<int>(decays.size());

  // Ceres refines every term jointly.
  std::vector<std::array<double, 4>> mode_blocks;
  for (const Term& m : modes) {
    mode_blocks.push_back({m.a, m.b, m.pole.frequency_hz, m.pole.zeta()});
  }
  std::vector<std::array<double, 2>> decay_blocks;
  for (const Term& d : decays) decay_blocks.push_back({d.a, d.pole.decay_per_s});
  std::array<double, 1> offset_block = {start.offset};
  std::vector<double*> parameters;
  for (auto& block : mode_blocks) parameters.push_back(block.data());
  for (auto& block : decay_blocks) parameters.push_back(block.data());
  if (options.fit_offset) parameters.push_back(offset_block.data());

  const DampedModesModel model(samples, 1.0 / sample_rate_hz, mode_count, decay_count,
                               options.fit_offset);
  ceres::Problem problem;
  problem.AddResidualBlock(
      new QrCompressedCost(static_cast<int>(samples.size()), model.block_sizes(), model), nullptr,
      parameters);
  for (auto& block : mode_blocks) {
    problem.SetParameterLowerBound(block.data(), 2, 0.0);
    problem.SetParameterUpperBound(block.data(), 2, 0.5 * sample_rate_hz);
    problem.SetParameterLowerBound(block.data(), 3, kMinDampingRatio);
    problem.SetParameterUpperBound(block.data(), 3, kMaxDampingRatio);
  }
  for (auto& block : decay_blocks) problem.SetParameterLowerBound(block.data(), 1, 0.0);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.parameter_tolerance = 1e-14;
  solver.gradient_tolerance = 1e-16;
  solver.logging_type = ceres::SILENT;
  solver.minimizer_progress_to_stdout = false;
  solver.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  fit.iterations = static_cast<int>(summary.iterations.size());
  if (!summary.IsSolutionUsable()) {
    fit.reason = "Ceres: " + summary.message;
    return fit;
  }

  // Covariance s^2 (J^T J)^-1 from the analytic Jacobian at the solution.
  const auto n = static_cast<Eigen::Index>(samples.size());
  const Eigen::Index p = model.parameters();
  Eigen::VectorXd residuals(n);
  Eigen::MatrixXd jacobian(n, p);
  model(parameters.data(), residuals.data(), jacobian.data());
  const double s2 = residuals.squaredNorm() / static_cast<double>(n - p);
  fit.residual_rms = std::sqrt(s2);
  // Judged and inverted in correlation form (the columns' units differ); a
  // singular direction (two terms the data cannot tell apart) is left out by
  // the pseudo-inverse, which keeps the other parameters' variances.
  const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
  const Eigen::VectorXd scale = normal.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scale.asDiagonal() * normal *
                                                             scale.asDiagonal());
  const Eigen::VectorXd values = eigen.eigenvalues();
  const double cutoff = 1e-12 * values.maxCoeff();
  fit.covariance_ok = values.minCoeff() > cutoff;
  Eigen::VectorXd inverse_values = Eigen::VectorXd::Zero(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    if (values(i) > cutoff) inverse_values(i) = 1.0 / values(i);
  }
  const Eigen::MatrixXd covariance = s2 * scale.asDiagonal() * eigen.eigenvectors() *
                                     inverse_values.asDiagonal() *
                                     eigen.eigenvectors().transpose() * scale.asDiagonal();
  if (!fit.covariance_ok) {
    fit.note = "J^T J is singular at the solution: two terms cannot be told apart";
  }
  auto sigma = [&](Eigen::Index i) { return std::sqrt(std::max(0.0, covariance(i, i))); };

  for (int k = 0; k < mode_count; ++k) {
    const auto& block = mode_blocks[static_cast<std::size_t>(k)];
    const Eigen::Index c0 = 4 * k;
    Term term;
    term.pole = {block[2], DecayRate(block[2], block[3])};
    term.a = block[0];
    term.b = block[1];
    term.energy = (jacobian.middleCols(c0, 2) * Eigen::Vector2d(block[0], block[1])).squaredNorm();
    DampedMode mode = ToMode(term);
    mode.damping_ratio.value = block[3];  // exact, not through the decay rate
    const double amplitude = mode.amplitude.value;
    // A = |(a, b)|, phi = atan2(-b, a): gradients by (a, b).
    const Eigen::Vector2d d_amplitude(block[0] / amplitude, block[1] / amplitude);
    const Eigen::Vector2d d_phase(block[1] / (amplitude * amplitude),
                                  -block[0] / (amplitude * amplitude));
    const Eigen::Matrix2d ab = covariance.block(c0, c0, 2, 2);
    mode.amplitude.sigma = std::sqrt(std::max(0.0, d_amplitude.dot(ab * d_amplitude)));
    mode.phase_rad.sigma = std::sqrt(std::max(0.0, d_phase.dot(ab * d_phase)));
    mode.frequency_hz.sigma = sigma(c0 + 2);
    mode.damping_ratio.sigma = sigma(c0 + 3);
    fit.modes.push_back(mode);
  }
  std::sort(fit.modes.begin(), fit.modes.end(),
            [](const DampedMode& x, const DampedMode& y) { return x.energy > y.energy; });
  for (int j = 0; j < decay_count; ++j) {
    const Eigen::Index c0 = 4 * mode_count + 2 * j;
    const auto& block = decay_blocks[static_cast<std::size_t>(j)];
    fit.decays.push_back({{block[0], sigma(c0)}, {block[1], sigma(c0 + 1)}});
  }
  if (options.fit_offset) fit.offset = {offset_block[0], sigma(p - 1)};
  if (mode_count < options.modes && fit.note.empty()) {
    fit.note = fmt::format("{} of {} mode(s) above the noise", mode_count, options.modes);
  }
  fit.ok = true;
  fit.fit_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
  return fit;
}

}  // namespace impactlab
