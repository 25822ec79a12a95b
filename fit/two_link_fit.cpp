#include "fit/two_link_fit.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <optional>
#include <stdexcept>
#include <utility>

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>
#include <fmt/format.h>
#include <Eigen/Dense>

#include "fit/quantisation_covariance.h"
#include "fit/secant_covariance.h"
#include "multibody/two_link_keys.h"
#include "multibody/two_link_simulation.h"
#include "signal/damped_modes.h"
#include "signal/impact_detection.h"

namespace impactlab {
namespace {

constexpr const char* kChannelNames[6] = {"q1", "q4", "a1", "a2", "a3", "a4"};

// Accelerometer samples this close to a simulated impact or separation are
// left out (an impact's one-sample spike moves with it).
constexpr long long kEventGuard = 5;

// The free-flight stage ends this long before the measured impact, so that
// a start whose impact comes a few ms early is still in free flight there.
constexpr double kFreeFlightGuard_s = 0.01;

// The encoders' windows after the impact: the first this long, each next
// twice as long, until the record's end.
constexpr double kFirstWindow_s = 0.1;

// The free-flight stage's prior at its start: this wide in a logarithm, or in
// a parameter's own unit. Free flight hardly sees some parameters (a tool's
// inertia trades with its drive's, J_eq: both turn with link 2), and without
// it Levenberg-Marquardt's scaling runs such a one off to 1e-22.
constexpr double kAnchorLog = 0.5, kAnchorAbsolute = 0.05;

// A trial simulation may take this many times the start's integration steps.
constexpr long kStepBudget = 10;

// A free parameter: where it lives and how it is varied.
struct FreeParameter {
  std::string name;
  bool logarithmic = true;
  double start = 0.0;
};

double* Slot(TwoLinkParameters& p, const std::string& name) {
  double* slot = nullptr;
  VisitTwoLinkKeys(
      p, [&](const char* section, const char* key, double& value, TwoLinkKeyRule, const char*) {
        if (name == fmt::format("{}.{}", section, key)) slot = &value;
      });
  return slot;
}

double RobustSigma(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  const double median = *mid;
  for (double& v : values) v = std::abs(v - median);
  std::nth_element(values.begin(), mid, values.end());
  return 1.4826 * *mid;
}

// The channel's noise from its second differences (a smooth signal's are
// (2 pi f / rate)^2 of it: small at these rates).
double NoiseSigma(const std::vector<double>& x) {
  std::vector<double> second;
  for (std::size_t i = 1; i + 1 < x.size(); ++i) second.push_back(x[i + 1] - 2.0 * x[i] + x[i - 1]);
  return RobustSigma(second) / std::sqrt(6.0);
}

struct Channel {
  const std::vector<double>* measured = nullptr;
  double sigma = 0.0;
  std::vector<bool> spike;      // samples left out (accelerometers)
  std::vector<double> centred;  // an encoder's readings at their counts' centres
  const std::vector<double>& values() const { return centred.empty() ? *measured : centred; }
};

// What a stage of the fit compares: the encoders alone or every channel,
// up to a time or (until_s < 0) to the record's end.
struct Stage {
  bool encoders_only = false;
  double until_s = -1.0;
  bool anchored = false;  // a weak prior at the stage's start holds what its data do not fix
};

// What one simulation gives the fit.
struct Evaluation {
  bool ok = false;
  std::string reason;  // why not ok: the parameters' check, or the simulation's refusal
  Eigen::VectorXd residuals;
  double frequency_hz = 0.0;
  double impact_s = -1.0;
  std::vector<double> channel_rms;
  std::vector<bool> near_event;  // accelerometer samples left out next to simulated impacts
  int used = 0;                  // residuals that count (the rest are left out, 0)
  long steps = 0;                // the simulation's integration steps
};

class Problem {
 public:
  Problem(const TwoLinkParameters& start, const TwoLinkMeasurement& m, const TwoLinkFitOptions& o)
      : start_(start), measurement_(m), options_(o) {
    // A record the fit cannot take is data, said in refusal(); the
    // constructor stops there, keeping what it read before.
    const std::size_t n = m.time_s.size();
    if (n < 10) {
      refusal_ = "two-link fit: the record has fewer than 10 samples";
      return;
    }
    rate_ = static_cast<double>(n - 1) / (m.time_s.back() - m.time_s.front());
    if (!(rate_ > 0.0) || !std::isfinite(rate_)) {
      refusal_ =
          fmt::format("two-link fit: the record's time must increase (it runs from {} s to {} s)",
                      m.time_s.front(), m.time_s.back());
      return;
    }
    // The simulation logs at most kTwoLinkMaxSamples a case: a record longer
    // than that cannot be compared sample by sample whatever the parameters,
    // so it is the record that is refused, before anything is simulated (the
    // product is the one the parameters' check forms below).
    const double rate_times_duration = rate_ * m.time_s.back();
    if (!(rate_times_duration <= kTwoLinkMaxSamples)) {
      refusal_ = fmt::format(
          "two-link fit: the record is too long for the simulation: {} samples over {:g} s at "
          "{:g} Hz (rate x duration {:.7g}), over its limit of {:g} per case",
          n, m.time_s.back(), rate_, rate_times_duration, kTwoLinkMaxSamples);
      return;
    }
    start_.sensors.sample_rate_hz = rate_;
    start_.cases[o.case_number - 1].duration_s = m.time_s.back();
    for (const std::string& name : o.free) {
      TwoLinkParameters copy = start_;
      double* slot = Slot(copy, name);
      if (!slot) throw std::invalid_argument("two-link fit: no parameter \"" + name + "\"");
      FreeParameter p;
      p.name = name;
      p.start = *slot;
      p.logarithmic = *slot > 0.0 && name.rfind("case", 0) != 0;
      free_.push_back(p);
    }
    const std::optional<std::vector<double>>* sources[6] = {&m.q1_rad,
                                                            &m.q4_rad,
                                                            &m.acceleration_m_s2[0],
                                                            &m.acceleration_m_s2[1],
                                                            &m.acceleration_m_s2[2],
                                                            &m.acceleration_m_s2[3]};
    for (int c = 0; c < 6; ++c) {
      Channel channel;
      if (sources[c]->has_value()) {
        channel.measured = &sources[c]->value();
        if (channel.measured->size() != n) {
          refusal_ = fmt::format("two-link fit: channel {} has {} samples, not {}",
                                 kChannelNames[c], channel.measured->size(), n);
          return;
        }
        channel.sigma = NoiseSigma(*channel.measured);
        if (c < 2) {
          // A count says the angle lies in [count, count + 1) steps: its
          // centre, half a step up, is the unbiased reading.
          const double step = c == 0 ? m.encoder_a_step_rad : m.encoder_b_step_rad;
          channel.sigma = std::max(channel.sigma, step / std::sqrt(12.0));
          channel.centred = *channel.measured;
          for (double& v : channel.centred) v += 0.5 * step;
        }
        channel.spike.assign(n, false);
        if (c >= 2) MarkSpikes(&channel);
        if (!(channel.sigma > 0.0)) channel.sigma = 1e-12;
      }
      channels_.push_back(channel);
    }
    // The impact as `reduce` finds it (signal/impact_detection.h): the
    // accelerometer whose strongest jump stands highest above its noise, and
    // in it the jump's onset. The encoders are the fallback.
    std::vector<ChannelSamples> samples;
    for (int c = 0; c < 6; ++c) {
      if (!channels_[static_cast<std::size_t>(c)].measured) continue;
      samples.push_back({kChannelNames[c],
                         c < 2 ? LogChannelKind::kAngle : LogChannelKind::kAcceleration,
                         *channels_[static_cast<std::size_t>(c)].measured});
    }
    const ImpactEstimate impact = DetectImpact(samples, m.time_s.front(), rate_, {});
    if (impact.found) measured_impact_ = impact.time_s.value;
    if (o.use_ring_down_frequency && m.acceleration_m_s2[0]) {
      if (measured_impact_ >= 0.0) {
        const DampedModeFit fit = RingDown(*m.acceleration_m_s2[0], measured_impact_);
        if (fit.ok && !fit.modes.empty() && fit.modes[0].frequency_hz.sigma > 0.0) {
          measured_frequency_ = fit.modes[0].frequency_hz;
        }
      }
    }
  }

  // Why the record cannot be fitted (empty: it can); the rest of the
  // problem is then only what was read before.
  const std::string& refusal() const { return refusal_; }
  int parameter_count() const { return static_cast<int>(free_.size()); }
  int residual_count() const {
    int count = measured_frequency_ ? 1 : 0;
    for (const Channel& c : channels_) {
      if (c.measured) count += static_cast<int>(c.measured->size());
    }
    return count;
  }
  const std::vector<FreeParameter>& free() const { return free_; }
  std::optional<Estimate> measured_frequency() const { return measured_frequency_; }
  double measured_impact() const { return measured_impact_; }
  const std::vector<Channel>& channels() const { return channels_; }

  Eigen::VectorXd StartPoint() const {
    Eigen::VectorXd x(free_.size());
    for (std::size_t i = 0; i < free_.size(); ++i) {
      x(static_cast<Eigen::Index>(i)) =
          free_[i].logarithmic ? std::log(free_[i].start) : free_[i].start;
    }
    return x;
  }

  TwoLinkParameters ParametersAt(const Eigen::VectorXd& x) const {
    TwoLinkParameters p = start_;
    for (std::size_t i = 0; i < free_.size(); ++i) {
      const double v = x(static_cast<Eigen::Index>(i));
      *Slot(p, free_[i].name) = free_[i].logarithmic ? std::exp(v) : v;
    }
    return p;
  }

  // What a stage fits (FitTwoLinkSimulation's stages).
  void set_stage(const Stage& stage) { stage_ = stage; }
  // A trial point whose simulation needs more steps than this is rejected
  // (a parameter driven to an extreme can make the motion arbitrarily stiff).
  void set_max_steps(long steps) { max_steps_ = steps; }
  // The free flight ends a little before the measured impact (-1: no impact seen).
  double free_flight_end() const {
    return measured_impact_ < 0.0 ? -1.0 : measured_impact_ - kFreeFlightGuard_s;
  }

  // `mask`: the samples to leave out next to impacts, when a difference
  // quotient needs its base point's (a mask that moved with the impacts
  // would make the quotient jump when an impact crosses a sample).
  Evaluation Evaluate(const Eigen::VectorXd& x, const std::vector<bool>* mask = nullptr) const {
    Evaluation e;
    e.residuals = Eigen::VectorXd::Zero(residual_count());
    e.channel_rms.assign(6, 0.0);
    // Parameters the model does not take, and a motion it refuses, are an
    // infeasible point, with why.
    const TwoLinkParameters p = ParametersAt(x);
    if (!p.Check(&e.reason)) return e;
    const TwoLinkModel model(p);
    TwoLinkSimulationOptions options;
    options.relative_tolerance = options_.tolerance;
    options.absolute_tolerance = options_.tolerance * 1e-3;
    options.keep_state = false;
    options.max_steps = max_steps_;
    // The step budget bounds a trial's work; the simulator's wall-clock
    // guard would make the fit depend on the machine's load (a trial that
    // a busy machine runs past it becomes an infeasible point, and the fit
    // ends elsewhere).
    options.max_wall_seconds = std::numeric_limits<double>::infinity();
    // A stage that looks at the record's start simulates no further.
    if (stage_.until_s >= 0.0)
      options.duration_s = std::min(measurement_.time_s.back(), stage_.until_s + 2.0 / rate_);
    const TwoLinkRecord record = SimulateTwoLink(model, p.cases[options_.case_number - 1], options);
    if (!record.ok) {
      e.reason = record.reason;
      return e;
    }
    ++simulations_;
    e.steps = record.steps;
    const std::size_t n = measurement_.time_s.size();
    const std::vector<double>* simulated[6] = {
        &record.gearbox_a_rad,        &record.gearbox_b_rad,        &record.acceleration_m_s2[0],
        &record.acceleration_m_s2[1], &record.acceleration_m_s2[2], &record.acceleration_m_s2[3]};
    // Samples next to a simulated impact are left out of the accelerometers.
    std::vector<bool>& near_event = e.near_event;
    if (mask) {
      near_event = *mask;
    } else {
      near_event.assign(n, false);
      for (const TwoLinkEvent& event : record.events) {
        const auto k = static_cast<long long>(std::ceil(event.time_s * rate_));
        for (long long j = k - kEventGuard; j <= k + kEventGuard; ++j) {
          if (j >= 0 && j < static_cast<long long>(n))
            near_event[static_cast<std::size_t>(j)] = true;
        }
      }
    }
    Eigen::Index row = 0;
    for (int c = 0; c < 6; ++c) {
      const Channel& channel = channels_[c];
      if (!channel.measured) continue;
      double sum = 0.0;
      int count = 0;
      for (std::size_t i = 0; i < n; ++i, ++row) {
        const auto k = static_cast<std::size_t>(std::llround(measurement_.time_s[i] * rate_));
        if (k >= simulated[c]->size()) continue;
        if (stage_.until_s >= 0.0 && measurement_.time_s[i] >= stage_.until_s) continue;
        if (c >= 2 && (stage_.encoders_only || channel.spike[i] || near_event[i])) continue;
        const double d = (*simulated[c])[k] - channel.values()[i];
        e.residuals(row) = d / channel.sigma;
        ++e.used;
        sum += d * d;
        ++count;
      }
      e.channel_rms[c] = count > 0 ? std::sqrt(sum / count) : 0.0;
    }
    e.impact_s = record.FirstImpact();
    if (measured_frequency_ && e.impact_s >= 0.0 && !stage_.encoders_only) {
      const DampedModeFit fit = RingDown(record.acceleration_m_s2[0], e.impact_s);
      if (!fit.ok || fit.modes.empty()) return e;
      e.frequency_hz = NearestFrequency(fit, measured_frequency_->value);
      e.residuals(row) = (e.frequency_hz - measured_frequency_->value) / measured_frequency_->sigma;
      ++e.used;
    }
    e.ok = true;
    return e;
  }

  int simulations() const { return simulations_.load(); }

 private:
  void MarkSpikes(Channel* channel) const {
    const std::vector<double>& x = *channel->measured;
    for (std::size_t i = 1; i + 1 < x.size(); ++i) {
      double a = x[i - 1], b = x[i], c = x[i + 1];
      const double median = std::max(std::min(a, b), std::min(std::max(a, b), c));
      if (std::abs(b - median) > 8.0 * channel->sigma) {
        for (std::size_t j = i >= 2 ? i - 2 : 0; j <= std::min(x.size() - 1, i + 2); ++j) {
          channel->spike[j] = true;
        }
      }
    }
  }

  DampedModeFit RingDown(const std::vector<double>& x, double impact_s) const {
    const auto first =
        static_cast<std::size_t>(std::ceil((impact_s + options_.ring_down_delay_s) * rate_));
    const auto count = static_cast<std::size_t>(options_.ring_down_duration_s * rate_);
    if (first >= x.size()) return {};
    const std::size_t last = std::min(x.size(), first + count);
    return FitDampedModes(std::span<const double>(x.data() + first, last - first), rate_, {});
  }

  static double NearestFrequency(const DampedModeFit& fit, double target) {
    double best = fit.modes[0].frequency_hz.value;
    for (const DampedMode& m : fit.modes) {
      if (std::abs(m.frequency_hz.value - target) < std::abs(best - target))
        best = m.frequency_hz.value;
    }
    return best;
  }

  TwoLinkParameters start_;
  const TwoLinkMeasurement& measurement_;
  const TwoLinkFitOptions& options_;
  std::string refusal_;
  double rate_ = 0.0;
  std::vector<FreeParameter> free_;
  std::vector<Channel> channels_;
  std::optional<Estimate> measured_frequency_;
  double measured_impact_ = -1.0;
  Stage stage_;
  long max_steps_ = 0;
  mutable std::atomic<int> simulations_{0};
};

// Simulations at several points, `threads` at a time, each with the
// accelerometer samples left out at `mask` (the base point's).
std::vector<Evaluation> EvaluateAll(const Problem& problem,
                                    const std::vector<Eigen::VectorXd>& points,
                                    const std::vector<bool>& mask, int threads) {
  std::vector<Evaluation> results(points.size());
  for (std::size_t first = 0; first < points.size(); first += static_cast<std::size_t>(threads)) {
    std::vector<std::future<Evaluation>> running;
    const std::size_t end = std::min(points.size(), first + static_cast<std::size_t>(threads));
    for (std::size_t t = first; t < end; ++t) {
      running.push_back(
          std::async(std::launch::async, [&, t] { return problem.Evaluate(points[t], &mask); }));
    }
    for (std::size_t t = first; t < end; ++t) results[t] = running[t - first].get();
  }
  return results;
}

// The residuals' Jacobian by differences of whole simulations, `threads`
// at a time: forward differences while iterating, central ones for the
// covariance (a parameter that enters only through a ratio with another then
// gives exactly opposite columns, so the pair's degeneracy is seen; forward
// differences differ by the response's curvature, which the bouncing after
// an impact makes large).
Eigen::MatrixXd Jacobian(const Problem& problem, const Eigen::VectorXd& x, const Evaluation& base,
                         const TwoLinkFitOptions& o, bool central, bool* ok) {
  const int p = problem.parameter_count();
  std::vector<Eigen::VectorXd> points;
  std::vector<double> steps;  // signed
  for (int j = 0; j < p; ++j) {
    const bool log = problem.free()[static_cast<std::size_t>(j)].logarithmic;
    const double h = log ? o.relative_step : o.absolute_step * std::max(1.0, std::abs(x(j)));
    for (const double step : central ? std::vector<double>{h, -h} : std::vector<double>{h}) {
      points.push_back(x);
      points.back()(j) += step;
      steps.push_back(step);
    }
  }
  const std::vector<Evaluation> results = EvaluateAll(problem, points, base.near_event, o.threads);
  *ok = std::all_of(results.begin(), results.end(), [](const Evaluation& e) { return e.ok; });
  Eigen::MatrixXd jacobian(base.residuals.size(), p);
  if (!*ok) return jacobian;
  for (int j = 0; j < p; ++j) {
    if (central) {
      const Evaluation& up = results[static_cast<std::size_t>(2 * j)];
      const Evaluation& down = results[static_cast<std::size_t>(2 * j + 1)];
      jacobian.col(j) = (up.residuals - down.residuals) / (2.0 * steps[2 * j]);
    } else {
      jacobian.col(j) =
          (results[static_cast<std::size_t>(j)].residuals - base.residuals) / steps[j];
    }
  }
  return jacobian;
}

class SimulationCost : public ceres::CostFunction {
 public:
  SimulationCost(const Problem& problem, const TwoLinkFitOptions& options)
      : problem_(problem), options_(options) {
    set_num_residuals(problem.residual_count());
    mutable_parameter_block_sizes()->push_back(problem.parameter_count());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::VectorXd> x(parameters[0], problem_.parameter_count());
    // Levenberg-Marquardt asks for the residuals at a trial point, and once
    // the step is taken for them again with the Jacobian: one simulation saved.
    if (last_x_.size() != x.size() || last_x_ != x) {
      last_ = problem_.Evaluate(x);
      last_x_ = x;
    }
    const Evaluation& e = last_;
    if (!e.ok) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, num_residuals()) = e.residuals;
    if (jacobians && jacobians[0]) {
      bool ok = false;
      const Eigen::MatrixXd j = Jacobian(problem_, x, e, options_, false, &ok);
      if (!ok) return false;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          jacobians[0], num_residuals(), problem_.parameter_count()) = j;
    }
    return true;
  }

 private:
  const Problem& problem_;
  const TwoLinkFitOptions& options_;
  mutable Eigen::VectorXd last_x_;  // Ceres evaluates one point at a time
  mutable Evaluation last_;
};

// The stages of one start (docs/two-link-fit.md, "Stages"). The encoders'
// cost is smooth before the impact; after it, the micro-bounces make the
// response to a parameter change grow along the record, with side minima
// in the whole record's cost that a window over its first 0.1 s does not
// have. So: the encoders in free flight, then in windows doubling from
// the impact, then whole, then every channel. A log without encoders, or
// without an impact, has fewer stages.
std::vector<Stage> Stages(const Problem& problem, double record_end_s) {
  const bool encoders = problem.channels()[0].measured || problem.channels()[1].measured;
  std::vector<Stage> stages;
  if (encoders && problem.free_flight_end() > 0.0) {
    stages.push_back({true, problem.free_flight_end(), true});
    for (double after = kFirstWindow_s; problem.measured_impact() + after < record_end_s;
         after *= 2.0) {
      stages.push_back({true, problem.measured_impact() + after, false});
    }
  }
  if (encoders) stages.push_back({true, -1.0, false});
  stages.push_back({false, -1.0, false});
  return stages;
}

// A weak Gaussian prior centred at `at` (kAnchorLog, kAnchorAbsolute wide).
ceres::CostFunction* Anchor(const Problem& problem, const Eigen::VectorXd& at) {
  const int p = problem.parameter_count();
  Eigen::MatrixXd inverse_width = Eigen::MatrixXd::Zero(p, p);
  for (int j = 0; j < p; ++j) {
    const bool log = problem.free()[static_cast<std::size_t>(j)].logarithmic;
    inverse_width(j, j) = 1.0 / (log ? kAnchorLog : kAnchorAbsolute);
  }
  return new ceres::NormalPrior(inverse_width, at);
}

std::string StageName(const Stage& stage) {
  if (stage.anchored) return "free flight";
  if (!stage.encoders_only) return "all channels";
  return stage.until_s > 0.0 ? fmt::format("encoders to {:.3f} s", stage.until_s) : "encoders";
}

// Hands each accepted or rejected Levenberg-Marquardt iteration to the
// options' on_progress, with where in the starts and stages it is.
class ProgressReport : public ceres::IterationCallback {
 public:
  ProgressReport(const TwoLinkFitOptions& options, const Problem& problem,
                 std::chrono::steady_clock::time_point began, TwoLinkFitProgress where)
      : options_(options), problem_(problem), began_(began), where_(std::move(where)) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    where_.iteration = summary.iteration;
    // A rejected step leaves the fit where it was: its trial cost is not the stage's.
    if (summary.iteration == 0 || summary.step_is_successful) where_.chi2 = 2.0 * summary.cost;
    where_.simulations = problem_.simulations();
    where_.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - began_).count();
    options_.on_progress(where_);
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const TwoLinkFitOptions& options_;
  const Problem& problem_;
  std::chrono::steady_clock::time_point began_;
  TwoLinkFitProgress where_;
};

std::string Combination(const Eigen::VectorXd& direction, const std::vector<FreeParameter>& free) {
  std::string out;
  for (Eigen::Index j = 0; j < direction.size(); ++j) {
    const double c = direction(j);
    if (std::abs(c) < 0.05) continue;
    const std::string term = free[static_cast<std::size_t>(j)].logarithmic
                                 ? "ln " + free[static_cast<std::size_t>(j)].name
                                 : free[static_cast<std::size_t>(j)].name;
    out += fmt::format("{}{:.2f} {}", out.empty() ? (c < 0 ? "-" : "") : (c < 0 ? " - " : " + "),
                       std::abs(c), term);
  }
  return out;
}

// The secants' Gauss-Newton steps after the iterations: at most this many
// rounds of new secants, each with at most this many steps, a step that
// lowers chi2 by less than this ending the round (the simulation's own
// resolution of chi2 is ~1e-3).
constexpr int kSecantRounds = 2, kSecantSteps = 3;
constexpr double kNegligibleChi2Drop = 0.01;

// The secant covariance at x, and the row weights it used.
struct Secants {
  SecantCovariance covariance;
  Eigen::VectorXd row_weight;
};

// The residuals of a channel are correlated along the record (an encoder's
// in runs of one count): each channel's rows are weighted down by the square
// root of its correlation inflation at `at`. The secants run `threads` at a
// time with the accelerometer samples left out as at `at`, from the central
// Jacobian's singular directions (weighted alike); `first_steps` as in
// SecantCovarianceOptions.
Secants SecantsAt(const Problem& problem, const Eigen::VectorXd& x, const Evaluation& at,
                  const Eigen::MatrixXd& jacobian, const TwoLinkFitOptions& options,
                  std::vector<double> first_steps) {
  Secants out;
  out.row_weight = Eigen::VectorXd::Ones(at.residuals.size());
  Eigen::Index row = 0;
  for (const Channel& channel : problem.channels()) {
    if (!channel.measured) continue;
    const auto n = static_cast<Eigen::Index>(channel.measured->size());
    const double inflation = CorrelationInflation(
        std::span<const double>(at.residuals.data() + row, static_cast<std::size_t>(n)));
    out.row_weight.segment(row, n).setConstant(1.0 / std::sqrt(inflation));
    row += n;
  }
  const ResidualsAtPoints residuals_at = [&](const std::vector<Eigen::VectorXd>& points) {
    std::vector<std::optional<Eigen::VectorXd>> r;
    for (const Evaluation& e : EvaluateAll(problem, points, at.near_event, options.threads)) {
      if (e.ok)
        r.emplace_back(out.row_weight.cwiseProduct(e.residuals));
      else
        r.emplace_back(std::nullopt);
    }
    return r;
  };
  SecantCovarianceOptions secant_options;
  secant_options.undetermined_ratio = options.undetermined_ratio;
  secant_options.first_steps = std::move(first_steps);
  out.covariance =
      SecantCovarianceAt(x, out.row_weight.asDiagonal() * jacobian, residuals_at, secant_options);
  return out;
}

// The covariance of the fitted values: the sandwich B M B with the secants
// of the unweighted residuals, the cost the fit minimises. The middle term
// M: an encoder's error is its counts', a known function of the fitted
// angle and of the grid's phase against it, which no record tells, so it is
// computed over the phases (fit/quantisation_covariance.h), plus any noise
// beyond it as white; an accelerometer's noise is white, its rows times its
// residuals' correlation inflation; the frequency's one row, its own sigma.
Eigen::MatrixXd FittedValuesCovariance(const Problem& problem,
                                       const TwoLinkMeasurement& measurement, const Evaluation& at,
                                       const Secants& secants) {
  const Eigen::VectorXd unweight = secants.row_weight.cwiseInverse();
  const Eigen::MatrixXd a = unweight.asDiagonal() * secants.covariance.secants;
  Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(a.cols(), a.cols());
  Eigen::Index row = 0;
  for (int c = 0; c < 6; ++c) {
    const Channel& channel = problem.channels()[static_cast<std::size_t>(c)];
    if (!channel.measured) continue;
    const auto n = static_cast<Eigen::Index>(channel.measured->size());
    const Eigen::MatrixXd rows = a.middleRows(row, n);
    const double step = c == 0   ? measurement.encoder_a_step_rad
                        : c == 1 ? measurement.encoder_b_step_rad
                                 : 0.0;
    if (c < 2 && step > 0.0) {
      std::vector<double> angle(static_cast<std::size_t>(n));
      for (Eigen::Index i = 0; i < n; ++i) {
        angle[static_cast<std::size_t>(i)] =
            channel.values()[static_cast<std::size_t>(i)] + channel.sigma * at.residuals(row + i);
      }
      meat += QuantisationScoreCovariance(rows, angle, step, channel.sigma);
      const double beyond = 1.0 - step * step / 12.0 / (channel.sigma * channel.sigma);
      if (beyond > 0.0) meat += beyond * rows.transpose() * rows;
    } else {
      const double inflation = 1.0 / (secants.row_weight(row) * secants.row_weight(row));
      meat += inflation * rows.transpose() * rows;
    }
    row += n;
  }
  for (; row < a.rows(); ++row) meat += a.row(row).transpose() * a.row(row);
  return SecantSandwich(secants.covariance, unweight, meat);
}

// A fit that did not run: what was read before `reason` stopped it, each
// free parameter at its start and not determined, each channel read with its
// noise and samples but no misfit (nothing was simulated to compare).
TwoLinkFitResult Refused(const Problem& problem, TwoLinkFitRefusal kind, const std::string& reason,
                         std::chrono::steady_clock::time_point clock_start) {
  TwoLinkFitResult result;
  result.ok = false;
  result.reason = reason;
  result.refused = kind;
  result.fitted = problem.ParametersAt(problem.StartPoint());
  for (const FreeParameter& f : problem.free()) {
    FittedParameter out;
    out.name = f.name;
    out.start = f.start;
    out.value = {f.start, 0.0};
    out.determined = false;
    result.parameters.push_back(out);
  }
  for (std::size_t c = 0; c < problem.channels().size(); ++c) {
    const Channel& channel = problem.channels()[c];
    if (!channel.measured) continue;
    result.channels.push_back({kChannelNames[c], std::nullopt, std::nullopt, channel.sigma,
                               static_cast<int>(channel.measured->size())});
  }
  result.measured_frequency_hz = problem.measured_frequency();
  result.measured_impact_s = problem.measured_impact();
  result.termination = reason;
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  return result;
}

}  // namespace

bool TwoLinkFitOptions::Check(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = what;
    return false;
  };
  if (free.empty()) return fail("two-link fit: name at least one parameter to free");
  if (case_number < 1 || case_number > 3) return fail("two-link fit: case must be 1, 2 or 3");
  if (max_iterations < 1 || starts < 1 || !(relative_step > 0.0) || !(absolute_step > 0.0) ||
      threads < 1 || !(tolerance > 0.0) || !(undetermined_ratio > 0.0)) {
    return fail("two-link fit: iterations, steps, tolerance and threads must be positive");
  }
  return true;
}

TwoLinkFitResult FitTwoLinkSimulation(const TwoLinkParameters& start,
                                      const TwoLinkMeasurement& measurement,
                                      const TwoLinkFitOptions& options) {
  std::string error;
  if (!options.Check(&error)) throw std::invalid_argument(error);
  const auto clock_start = std::chrono::steady_clock::now();
  Problem problem(start, measurement, options);
  if (!problem.refusal().empty())
    return Refused(problem, TwoLinkFitRefusal::kRecord, problem.refusal(), clock_start);
  const Evaluation first = problem.Evaluate(problem.StartPoint());
  if (!first.ok) {
    return Refused(problem, TwoLinkFitRefusal::kStartParameters,
                   "two-link fit: the start parameters cannot be simulated: " + first.reason,
                   clock_start);
  }
  problem.set_max_steps(kStepBudget * first.steps);

  // Each start runs the stages. Start 0 is the given
  // parameters; start k > 0 moves parameter (k - 1) / 2 by +-20 % (+-30 ms
  // for a time) from them, and the lowest chi2 wins.
  TwoLinkFitResult result;
  Eigen::VectorXd x = problem.StartPoint();  // kept if no start gets anywhere
  double best_cost = std::numeric_limits<double>::infinity();
  int iterations = 0;
  ceres::Solver::Summary summary;
  std::string best_message;
  const std::vector<Stage> stages = Stages(problem, measurement.time_s.back());
  for (int k = 0; k < options.starts; ++k) {
    Eigen::VectorXd trial = problem.StartPoint();
    if (k > 0) {
      const int j = ((k - 1) / 2) % problem.parameter_count();
      const double sign = (k % 2 == 1) ? 1.0 : -1.0;
      trial(j) += sign * (problem.free()[static_cast<std::size_t>(j)].logarithmic ? 0.2 : 0.03);
    }
    for (std::size_t i = 0; i < stages.size(); ++i) {
      const Stage& stage = stages[i];
      problem.set_stage(stage);
      ceres::Problem ceres_problem;
      ceres_problem.AddResidualBlock(new SimulationCost(problem, options), nullptr, trial.data());
      if (stage.anchored)
        ceres_problem.AddResidualBlock(Anchor(problem, trial), nullptr, trial.data());
      ceres::Solver::Options solver_options;
      solver_options.linear_solver_type = ceres::DENSE_QR;
      solver_options.max_num_iterations = options.max_iterations;
      solver_options.function_tolerance = stage.encoders_only ? 1e-6 : 1e-8;
      solver_options.parameter_tolerance = 1e-8;
      solver_options.logging_type = ceres::SILENT;
      std::optional<ProgressReport> report;
      if (options.on_progress) {
        report.emplace(options, problem, clock_start,
                       TwoLinkFitProgress{k, options.starts, static_cast<int>(i),
                                          static_cast<int>(stages.size()), StageName(stage)});
        solver_options.callbacks.push_back(&*report);
      }
      ceres::Solve(solver_options, &ceres_problem, &summary);
      iterations += static_cast<int>(summary.iterations.size());
    }
    result.start_costs.push_back(2.0 * summary.final_cost);
    if (2.0 * summary.final_cost < best_cost) {
      best_cost = 2.0 * summary.final_cost;
      x = trial;
      best_message = summary.message;
    }
  }

  if (options.on_progress) {
    const int count = static_cast<int>(stages.size());
    TwoLinkFitProgress where{options.starts - 1, options.starts, count, count, "uncertainty"};
    where.chi2 = best_cost;
    where.simulations = problem.simulations();
    where.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
    options.on_progress(where);
  }
  result.iterations = iterations;
  result.termination = best_message;
  Evaluation last = problem.Evaluate(x);
  bool ok = false;
  const Eigen::MatrixXd jacobian = Jacobian(problem, x, last, options, true, &ok);
  const int p = problem.parameter_count();
  result.iterated_chi2 = last.residuals.squaredNorm();

  // The covariance from secants along the weighted Jacobian's singular
  // directions, each over about two of its own sigma: after the impact the
  // central differences over the fixed step misjudge the response along the
  // weak directions (fit/secant_covariance.h). Undetermined directions are
  // left out.
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(p, p);
  Eigen::MatrixXd jacobian_covariance = Eigen::MatrixXd::Zero(p, p);
  std::vector<bool> determined(static_cast<std::size_t>(p), true);
  if (ok) {
    Secants secants = SecantsAt(problem, x, last, jacobian, options, {});
    result.secant_simulations += secants.covariance.evaluations;
    // Levenberg-Marquardt found its way with forward differences over the
    // fixed step, and along a weak direction it stops where they, not the
    // secants, say the gradient vanishes: several sigma from the minimum in
    // the five-parameter benchmark. Gauss-Newton steps with the secants go
    // the rest of the way, each kept only if it lowers the fit's chi2.
    for (int round = 0; round < kSecantRounds; ++round) {
      const double before = last.residuals.squaredNorm();
      for (int step = 0; step < kSecantSteps; ++step) {
        const Eigen::VectorXd d =
            SecantStep(secants.covariance, last.residuals, secants.row_weight.cwiseInverse());
        const double chi2 = last.residuals.squaredNorm();
        bool lower = false;
        for (double fraction = 1.0; fraction > 0.2 && !lower; fraction *= 0.5) {
          Evaluation trial = problem.Evaluate(x + fraction * d);
          ++result.secant_simulations;
          if (trial.ok && trial.residuals.squaredNorm() < chi2) {
            x += fraction * d;
            last = std::move(trial);
            lower = true;
          }
        }
        if (!lower || chi2 - last.residuals.squaredNorm() < kNegligibleChi2Drop) break;
      }
      // A point moved by less than about one sigma keeps its secants.
      if (before - last.residuals.squaredNorm() < 1.0) break;
      secants = SecantsAt(problem, x, last, jacobian, options, secants.covariance.steps);
      result.secant_simulations += secants.covariance.evaluations;
    }
    const SecantCovariance& secant = secants.covariance;
    covariance = FittedValuesCovariance(problem, measurement, last, secants);
    const Eigen::VectorXd& s = secant.singular_values;
    for (int i = 0; i < p; ++i) {
      const Eigen::VectorXd direction = secant.directions.col(i);
      const double ratio = s(0) > 0.0 ? s(i) / s(0) : 0.0;
      result.singular_value_ratios.push_back(ratio);
      result.secant_sigma_ratios.push_back(secant.sigma_ratios[static_cast<std::size_t>(i)]);
      if (!secant.determined[static_cast<std::size_t>(i)]) {
        result.undetermined.push_back({Combination(direction, problem.free()), ratio});
        for (int j = 0; j < p; ++j) {
          if (std::abs(direction(j)) >= 0.05) determined[static_cast<std::size_t>(j)] = false;
        }
      } else {
        jacobian_covariance += direction * direction.transpose() / (s(i) * s(i));
      }
    }
  }
  result.fitted = problem.ParametersAt(x);
  result.chi2 = last.residuals.squaredNorm();
  result.dof = std::max(1, last.used - p);
  result.birge_ratio = std::sqrt(result.chi2 / result.dof);
  const double scale = std::max(1.0, result.birge_ratio);
  for (int j = 0; j < p; ++j) {
    const FreeParameter& f = problem.free()[static_cast<std::size_t>(j)];
    FittedParameter out;
    out.name = f.name;
    out.start = f.start;
    out.determined = ok && determined[static_cast<std::size_t>(j)];
    const double value = f.logarithmic ? std::exp(x(j)) : x(j);
    const double sigma_x = out.determined ? std::sqrt(covariance(j, j)) : 0.0;
    out.value = {value, f.logarithmic ? value * sigma_x : sigma_x};
    const double jacobian_sigma_x = out.determined ? std::sqrt(jacobian_covariance(j, j)) : 0.0;
    out.jacobian_sigma = f.logarithmic ? value * jacobian_sigma_x : jacobian_sigma_x;
    out.std_error_scaled = out.value.sigma * scale;
    result.parameters.push_back(out);
  }
  for (int c = 0; c < 6; ++c) {
    const Channel& channel = problem.channels()[static_cast<std::size_t>(c)];
    if (!channel.measured) continue;
    result.channels.push_back({kChannelNames[c], first.channel_rms[static_cast<std::size_t>(c)],
                               last.channel_rms[static_cast<std::size_t>(c)], channel.sigma,
                               static_cast<int>(channel.measured->size())});
  }
  result.measured_frequency_hz = problem.measured_frequency();
  result.start_frequency_hz = first.frequency_hz;
  result.fitted_frequency_hz = last.frequency_hz;
  result.measured_impact_s = problem.measured_impact();
  result.start_impact_s = first.impact_s;
  result.fitted_impact_s = last.impact_s;
  result.simulations = problem.simulations();
  result.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  result.ok = true;
  return result;
}

std::string TwoLinkFitResult::Summary() const {
  std::string out =
      "| parameter | start | fitted | sigma | sigma (scaled) | determined |\n"
      "| --- | ---: | ---: | ---: | ---: | --- |\n";
  for (const FittedParameter& p : parameters) {
    out +=
        fmt::format("| {} | {:.6g} | {:.6g} | {:.3g} | {:.3g} | {} |\n", p.name, p.start,
                    p.value.value, p.value.sigma, p.std_error_scaled, p.determined ? "yes" : "no");
  }
  for (const UndeterminedCombination& u : undetermined) {
    out += fmt::format(
        "\nNot determined by these data: the fit does not change along {} (singular value "
        "{:.1e} of the largest); only combinations across it are fixed\n",
        u.combination, u.singular_value_ratio);
  }
  out +=
      "\n| channel | RMS at start | RMS fitted | noise sigma | samples |\n"
      "| --- | ---: | ---: | ---: | ---: |\n";
  const auto misfit = [](const std::optional<double>& rms) {
    return rms ? fmt::format("{:.4g}", *rms) : std::string("—");  // not simulated
  };
  for (const ChannelMatch& c : channels) {
    out += fmt::format("| {} | {} | {} | {:.3g} | {} |\n", c.channel, misfit(c.rms_start),
                       misfit(c.rms_fitted), c.sigma, c.samples);
  }
  out += fmt::format("\nchi2 {:.6g} on {} degrees of freedom; Birge ratio {:.3g}\n", chi2, dof,
                     birge_ratio);
  std::string ratios;
  for (double r : singular_value_ratios) ratios += fmt::format(" {:.2e}", r);
  out += "singular values of the weighted Jacobian over the largest:" + ratios + "\n";
  std::string secant;
  for (double r : secant_sigma_ratios) secant += fmt::format(" {:.2f}", r);
  out += fmt::format(
      "sigma along each direction from its secants over the Jacobian's:{}; the secants' steps "
      "took chi2 from {:.6g} to {:.6g} ({} simulations)\n",
      secant, iterated_chi2, chi2, secant_simulations);
  if (measured_frequency_hz) {
    out += fmt::format(
        "a1 ring-down: measured {:.4f} +- {:.4f} Hz; start {:.4f} Hz; fitted {:.4f} Hz\n",
        measured_frequency_hz->value, measured_frequency_hz->sigma, start_frequency_hz,
        fitted_frequency_hz);
  }
  out += fmt::format("first impact: measured {:.4f} s; start {:.4f} s; fitted {:.4f} s\n",
                     measured_impact_s, start_impact_s, fitted_impact_s);
  if (start_costs.size() > 1) {
    std::string costs;
    for (double c : start_costs) costs += fmt::format(" {:.6g}", c);
    out += fmt::format("chi2 from each start:{}\n", costs);
  }
  out += fmt::format("{} iterations, {} simulations, {:.1f} s; {}\n", iterations, simulations,
                     seconds, termination);
  return out;
}

}  // namespace impactlab
