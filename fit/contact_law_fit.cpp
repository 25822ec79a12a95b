#include "fit/contact_law_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>

#include <fmt/format.h>
#include <boost/math/special_functions/beta.hpp>

#include "fit/least_squares_internal.h"
#include "model/hunt_crossley_terms.h"
#include "model/kelvin_voigt.h"
#include "model/power_law_contact.h"
#include "model/power_law_tables.h"

namespace impactlab {
namespace {

template <typename T>
double ValueOf(const T& x) {
  if constexpr (std::is_same_v<T, double>) {
    return x;
  } else {
    return x.a;
  }
}

// A(v) in T: the pendulum's amplitude and its slope at the value, so a Jet
// carries dA/dv. False past the horizontal.
template <typename T>
bool Amplitude(const Pendulum& pendulum, const T& speed, T* out) {
  const double v = ValueOf(speed);
  if (!(v > 0.0) || !std::isfinite(v)) return false;
  try {
    const fit_internal::AmplitudeSlope a = fit_internal::AmplitudeAndSlope(pendulum, v);
    *out = T(a.amplitude) + T(a.slope) * (speed - T(v));
  } catch (const std::domain_error&) {
    return false;
  }
  return true;
}

// Hunt-Crossley's e(eps) in T: from its Chebyshev table where that covers eps
// (model/power_law_tables.h: as cheap as a closed form, the value and slope
// within 1e-14 and 2e-9 of the exact ones), else by the exact root and its
// implicit derivative.
template <typename T>
T HuntCrossleyE(const T& eps) {
  if (const auto e = power_law_tables::HuntCrossleyRestitution(ValueOf(eps))) {
    return Along(*e, ValueOf(eps), eps);
  }
  return hunt_crossley::RestitutionOf(eps);
}

// One run, prepared: its read maxima by session rebound number.
struct PreparedRun {
  const LawRun* run = nullptr;
  std::vector<int> rebounds;  // read maxima
  std::vector<double> x, sigma;
  int last = 0;                // last read rebound
  bool has_contact = false;    // its own contact time, used
  double release_speed = 0.0;  // speed into the release's impact (contact_rebound -1)
};

// The law with its parameter layout: theta = [damping term][ln stiffness][n],
// each present when the law has it and the data fix it.
struct LawModel {
  ContactLawKind kind = ContactLawKind::kHuntCrossley;
  Separation separation = Separation::kKinematic;
  double exponent = 1.5;
  bool fit_stiffness = false;
  double hertz_time = 0.0;  // Hertz: 2 B(1/(n+1), 1/2)/(n+1) at the fixed n

  bool HasDamping() const { return kind != ContactLawKind::kHertz; }
  bool FitsExponent() const {
    return kind == ContactLawKind::kHuntCrossleyExponent && fit_stiffness;
  }
  int Size() const {
    return (HasDamping() ? 1 : 0) + (fit_stiffness ? 1 : 0) + (FitsExponent() ? 1 : 0);
  }
  int StiffnessIndex() const { return HasDamping() ? 1 : 0; }

  template <typename T>
  bool Restitution(const T* theta, const T& speed, double mass, T* e) const {
    using std::acos;
    using std::exp;
    using std::sqrt;
    switch (kind) {
      case ContactLawKind::kHertz:
        *e = T(1.0);
        return true;
      case ContactLawKind::kKelvinVoigt: {
        const T zeta = exp(theta[0]);
        if (!(ValueOf(zeta) < 1.0)) return false;
        const T root = sqrt(T(1.0) - zeta * zeta);
        *e = separation == Separation::kKinematic ? exp(-T(M_PI) * zeta / root)
                                                  : exp(T(-2.0) * zeta * acos(zeta) / root);
        return true;
      }
      case ContactLawKind::kHuntCrossley:
      case ContactLawKind::kHuntCrossleyExponent:
        *e = HuntCrossleyE(exp(theta[0]) * speed);
        return true;
      case ContactLawKind::kHertzDamper: {
        T s_c;
        return Damper(theta, speed, mass, e, &s_c);
      }
    }
    return false;
  }

  // The Hertz peak compression x* = ((n+1) M v^2 / (2k))^(1/(n+1)) in T.
  template <typename T>
  T PeakScale(const T& log_k, const T& n, const T& speed, double mass) const {
    using std::exp;
    using std::log;
    const T one(1.0);
    return exp((log((n + one) * T(0.5 * mass) * speed * speed) - log_k) / (n + one));
  }

  // The damper's e and scaled contact time at beta = c x*/(M v), carried to T
  // by their derivatives in beta.
  template <typename T>
  bool Damper(const T* theta, const T& speed, double mass, T* e, T* s_c) const {
    using std::exp;
    const T beta =
        exp(theta[0]) * PeakScale(theta[1], T(exponent), speed, mass) / (T(mass) * speed);
    const double b = ValueOf(beta);
    if (!(b >= 0.0) || !std::isfinite(b)) return false;
    const HertzDamperScaled d = HertzDamperScaledImpact(exponent, b, separation, 1e-9);
    if (!d.ok) return false;  // no separation there: Ceres shrinks the step
    *e = T(d.restitution) + T(d.d_restitution) * (beta - T(b));
    *s_c = T(d.contact_time) + T(d.d_contact_time) * (beta - T(b));
    return true;
  }

  template <typename T>
  bool ContactTime(const T* theta, const T& speed, double mass, T* tau) const {
    using std::acos;
    using std::exp;
    using std::log;
    using std::pow;
    using std::sqrt;
    const T log_k = theta[StiffnessIndex()];
    if (kind == ContactLawKind::kKelvinVoigt) {
      const T zeta = exp(theta[0]);
      if (!(ValueOf(zeta) < 1.0)) return false;
      const T wn = exp(T(0.5) * log_k) / T(std::sqrt(mass));
      const T root = sqrt(T(1.0) - zeta * zeta);
      *tau = separation == Separation::kKinematic ? T(M_PI) / (wn * root)
                                                  : T(2.0) * acos(zeta) / (root * wn);
      return true;
    }
    const T n = FitsExponent() ? theta[StiffnessIndex() + 1] : T(exponent);
    const T x_star = PeakScale(log_k, n, speed, mass);  // t* = x*/v
    if (kind == ContactLawKind::kHertzDamper) {
      T e, s_c;
      if (!Damper(theta, speed, mass, &e, &s_c)) return false;
      *tau = x_star / speed * s_c;
      return true;
    }
    if (kind == ContactLawKind::kHertz) {
      *tau = x_star / speed * T(hertz_time);
      return true;
    }
    const T eps = exp(theta[0]) * speed;
    const double eps0 = ValueOf(eps);
    // s_c(eps, n) from its table where it covers them (eps <= 256, n in
    // [0.5, 5]: every n a fit of n searches), else the quadrature.
    const double n0 = ValueOf(n);
    if (const auto s_c = power_law_tables::HuntCrossleyContactTime(n0, eps0)) {
      *tau = x_star / speed * Along(*s_c, eps0, eps, n0, n);
      return true;
    }
    const hunt_crossley::Exit exit = hunt_crossley::ExitOf(eps0);
    if (!(exit.gap > 0.0)) return false;
    const T e = hunt_crossley::RestitutionOf(eps, exit);  // the root solved once
    const T gap = T(exit.gap) - (eps * e - T(eps0 * exit.restitution));
    const auto s = FitsExponent() ? hunt_crossley::ContactTimes(n, eps, e, gap)
                                  : hunt_crossley::ContactTimes<T, double>(exponent, eps, e, gap);
    *tau = x_star / speed * (s.compression + s.restitution);
    return true;
  }
};

// A run's whitened residuals: its maxima, then its contact time (if used).
struct RunResiduals {
  const PreparedRun* run;
  const LawModel* law;

  int Count() const { return static_cast<int>(run->x.size()) + (run->has_contact ? 1 : 0); }

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    using std::exp;
    const T* theta = law->Size() > 0 ? parameters[1] : nullptr;
    const LawRun& r = *run->run;
    T contact(0.0);
    const auto contact_at = [&](const T& v) {
      T tau;
      if (!law->ContactTime(theta, v, r.mass, &tau)) return false;
      contact = (tau - T(*r.measured.contact_time)) / T(r.measured.contact_time_sigma);
      return true;
    };
    if (run->has_contact && r.contact_rebound < 0 && !contact_at(T(run->release_speed))) {
      return false;
    }
    T v = exp(parameters[0][0]);
    std::size_t k = 0;
    for (int n = 0; n <= run->last; ++n) {
      if (k < run->rebounds.size() && run->rebounds[k] == n) {
        T a;
        if (!Amplitude(r.pendulum, v, &a)) return false;
        residuals[k] = (a - T(run->x[k])) / T(run->sigma[k]);
        ++k;
      }
      if (run->has_contact && n == r.contact_rebound && !contact_at(v)) return false;
      if (n < run->last) {
        T e;
        if (!law->Restitution(theta, v, r.mass, &e)) return false;
        v = v * e;
      }
    }
    if (run->has_contact) residuals[k] = contact;
    return true;
  }
};

// The run as the fit takes it, or nothing with `refusal` for maxima it
// cannot weigh (fewer than two read, one without a sigma > 0 or not > 0).
std::optional<PreparedRun> Prepare(const LawRun& run, bool use_contact_times,
                                   std::string* refusal) {
  if (!(run.mass > 0.0) || !(run.initial_displacement > 0.0)) {
    throw std::invalid_argument(fmt::format("run '{}': mass and X0 must be > 0", run.name));
  }
  PreparedRun p;
  p.run = &run;
  const auto& m = run.measured;
  for (std::size_t i = 0; i < m.xmax.size(); ++i) {
    if (std::isnan(m.xmax[i])) continue;
    const double s = i < m.xmax_sigma.size() ? m.xmax_sigma[i] : 0.0;
    if (!(s > 0.0) || !(m.xmax[i] > 0.0)) {
      *refusal = fmt::format("run '{}': maximum {} needs a value and a sigma > 0", run.name, i);
      return std::nullopt;
    }
    p.rebounds.push_back(static_cast<int>(i));
    p.x.push_back(m.xmax[i]);
    p.sigma.push_back(s);
  }
  if (p.rebounds.size() < 2) {
    *refusal = fmt::format("run '{}': fewer than two read maxima", run.name);
    return std::nullopt;
  }
  p.last = p.rebounds.back();
  p.has_contact = use_contact_times && m.contact_time && m.contact_time_sigma > 0.0 &&
                  run.contact_rebound >= -1 && run.contact_rebound <= p.last;
  p.release_speed = SpeedFromAmplitude(run.pendulum, run.initial_displacement);
  return p;
}

// The speed into the run's measured impact, from its measurements (for
// starting values and for predicting a held-out run's contact time).
double ContactSpeedEstimate(const PreparedRun& p, double log_e) {
  if (p.run->contact_rebound < 0) return p.release_speed;
  const double v0 = SpeedFromAmplitude(p.run->pendulum, p.x.front());
  return v0 * std::exp(log_e * (p.run->contact_rebound - p.rebounds.front()));
}

std::string Sentence(const LawModel& law, const std::vector<PreparedRun>& runs,
                     const Identifiability& id) {
  int contacts = 0;
  std::set<double> speeds;
  for (const PreparedRun& p : runs) {
    if (!p.has_contact) continue;
    ++contacts;
    speeds.insert(std::round(ContactSpeedEstimate(p, 0.0) * 1e6) / 1e6);
  }
  std::string k_part;
  const char* k_name = law.kind == ContactLawKind::kKelvinVoigt ? "K" : "k";
  if (law.fit_stiffness) {
    k_part = fmt::format("{} from {} contact time{} at {} speed{}", k_name, contacts,
                         contacts == 1 ? "" : "s", speeds.size(), speeds.size() == 1 ? "" : "s");
  } else {
    k_part =
        fmt::format("{} not determined (no run has its own contact time with a sigma)", k_name);
  }
  std::string s;
  switch (law.kind) {
    case ContactLawKind::kKelvinVoigt:
      s = "zeta from the maxima' decay; " + k_part;
      break;
    case ContactLawKind::kHertz:
      s = "no dissipation to fit (e = 1); " + k_part;
      break;
    case ContactLawKind::kHuntCrossley:
      s = fmt::format("chi from how e changes with impact speed; {}; n fixed at {}", k_part,
                      law.exponent);
      break;
    case ContactLawKind::kHertzDamper:
      s = fmt::format(
          "c k^(-1/(n+1)) from the maxima' decay and its speed dependence; {}; n fixed at {}",
          k_part, law.exponent);
      break;
    case ContactLawKind::kHuntCrossleyExponent:
      s = fmt::format("chi from how e changes with impact speed; {}; {}", k_part,
                      law.FitsExponent()
                          ? (speeds.size() >= 2 ? "n from how tau_c changes with speed"
                                                : "n weakly fixed: contact times at one speed")
                          : "n not determined without contact times");
      break;
  }
  if (!id.identifiable && !id.message.empty()) s += "; " + id.message;
  return s + ".";
}

// The profile of theta[i]: min chi^2 over the other parameters with theta[i]
// held at t, minus the best fit's. Each profile point starts from the best
// fit and leaves the problem there afterwards.
class Profile {
 public:
  Profile(ceres::Problem& problem, std::vector<double>& theta, std::vector<double>& w, int i,
          double chi2_min, const SolverControl& solver)
      : problem_(problem),
        theta_(theta),
        w_(w),
        i_(i),
        chi2_min_(chi2_min),
        solver_(solver),
        theta0_(theta),
        w0_(w) {
    if (theta.size() == 1) {
      problem_.SetParameterBlockConstant(theta_.data());
    } else {
      problem_.SetManifold(theta_.data(),
                           new ceres::SubsetManifold(static_cast<int>(theta.size()), {i}));
    }
  }
  ~Profile() {
    theta_ = theta0_;
    w_ = w0_;
    if (theta_.size() == 1) {
      problem_.SetParameterBlockVariable(theta_.data());
    } else {
      problem_.SetManifold(theta_.data(), nullptr);
    }
  }
  Profile(const Profile&) = delete;
  Profile& operator=(const Profile&) = delete;

  // NaN where the solve fails.
  double Rise(double t) {
    theta_ = theta0_;
    w_ = w0_;
    theta_[static_cast<std::size_t>(i_)] = t;
    FitStatus status;
    fit_internal::Solve(problem_, solver_, &status);
    if (!status.usable) return std::numeric_limits<double>::quiet_NaN();
    return 2.0 * status.final_cost - chi2_min_;
  }

 private:
  ceres::Problem& problem_;
  std::vector<double>& theta_;
  std::vector<double>& w_;
  int i_;
  double chi2_min_;
  SolverControl solver_;
  std::vector<double> theta0_, w0_;
};

// The 68 % interval of theta[i] (log space, or n itself): the linearised one
// where the profile rises by s^2 at its ends (within `tolerance`), else where
// the profile crosses s^2, found by doubling the step and then bisecting.
// chi^2 - chi^2_min along the linearised profile path, theta_hat + cov[:, i]
// delta / cov(i, i) (every parameter, nuisance included, in the covariance's
// order: theta, then w): no solve, one evaluation. In the quadratic
// approximation it equals the profile; a screen before the profile's solves.
double LinearPathRise(ceres::Problem& problem, std::vector<double>& theta, std::vector<double>& w,
                      const Eigen::MatrixXd& cov, int i, double delta, double chi2_min) {
  const std::vector<double> theta0 = theta, w0 = w;
  const Eigen::VectorXd step = cov.col(i) * (delta / cov(i, i));
  for (std::size_t k = 0; k < theta.size(); ++k) theta[k] += step(static_cast<Eigen::Index>(k));
  for (std::size_t k = 0; k < w.size(); ++k) {
    w[k] += step(static_cast<Eigen::Index>(theta.size() + k));
  }
  double cost = 0.0;
  const bool ok =
      problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  theta = theta0;
  w = w0;
  return ok ? 2.0 * cost - chi2_min : std::numeric_limits<double>::quiet_NaN();
}

ParameterInterval IntervalOf(ceres::Problem& problem, std::vector<double>& theta,
                             std::vector<double>& w, const Eigen::MatrixXd& cov, int i,
                             double chi2_min, double scale, bool is_log,
                             std::pair<double, double> bounds,
                             const ContactLawFitOptions& options) {
  const double center = theta[static_cast<std::size_t>(i)];
  const double sigma = std::sqrt(cov(i, i));
  const double target = scale * scale;
  const double half_width = sigma * scale;
  ParameterInterval out;
  // The screen: quadratic along the linearised path (to half the tolerance)
  // and inside the bounds: the linear interval, without a solve.
  bool quadratic = center - half_width >= bounds.first && center + half_width <= bounds.second;
  for (const double sign : {-1.0, 1.0}) {
    const double rise =
        LinearPathRise(problem, theta, w, cov, i, sign * half_width, chi2_min) / target;
    (sign < 0 ? out.rise_at_lower : out.rise_at_upper) = rise;
    quadratic = quadratic && std::abs(rise - 1.0) <= 0.5 * options.profile_tolerance;
  }
  if (quadratic) {
    out.lower = is_log ? std::exp(center - half_width) : center - half_width;
    out.upper = is_log ? std::exp(center + half_width) : center + half_width;
    return out;
  }
  Profile profile(problem, theta, w, i, chi2_min, options.solver);
  std::array<double, 2> ends{};
  std::array<double, 2> rises{};
  bool linear_ok = true;
  for (int side = 0; side < 2; ++side) {
    const double sign = side == 0 ? -1.0 : 1.0;
    double t = std::clamp(center + sign * half_width, bounds.first, bounds.second);
    const double rise = profile.Rise(t);
    rises[side] = rise / target;
    ends[side] = t;
    linear_ok = linear_ok && std::isfinite(rise) &&
                std::abs(rise / target - 1.0) <= options.profile_tolerance &&
                t == center + sign * half_width;
  }
  out.rise_at_lower = rises[0];
  out.rise_at_upper = rises[1];
  if (!linear_ok) {
    out.profile = true;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? -1.0 : 1.0;
      const double bound = side == 0 ? bounds.first : bounds.second;
      // Bracket: inside where the rise is below the target.
      double inside = center, outside = center + sign * half_width;
      double rise = profile.Rise(outside);
      for (int k = 0; k < 12 && !(rise >= target); ++k) {
        if (outside == bound) break;
        inside = outside;
        outside = std::clamp(center + sign * half_width * std::pow(2.0, k + 1), bounds.first,
                             bounds.second);
        rise = profile.Rise(outside);
      }
      if (!(rise >= target)) {
        ends[side] = outside;  // never reached: the bound (or the search's end)
        out.at_bound = out.at_bound || outside == bound;
        continue;
      }
      for (int k = 0; k < 30 && std::abs(outside - inside) > 1e-4 * half_width; ++k) {
        const double mid = 0.5 * (inside + outside);
        (profile.Rise(mid) >= target ? outside : inside) = mid;
      }
      ends[side] = 0.5 * (inside + outside);
    }
  }
  out.lower = is_log ? std::exp(ends[0]) : ends[0];
  out.upper = is_log ? std::exp(ends[1]) : ends[1];
  return out;
}

struct Solved {
  ContactLawFit fit;
  LawModel law;
  std::vector<double> theta;
  std::vector<double> w;
};

Solved Solve(ContactLawKind kind, const std::vector<PreparedRun>& runs,
             const ContactLawFitOptions& options) {
  const fit_internal::Stopwatch stopwatch;
  Solved out;
  ContactLawFit& fit = out.fit;
  fit.law = ContactLawName(kind);

  LawModel& law = out.law;
  law.kind = kind;
  law.separation = options.separation;
  law.exponent = options.exponent;
  law.fit_stiffness =
      std::any_of(runs.begin(), runs.end(), [](const PreparedRun& p) { return p.has_contact; });
  {
    const double a = 1.0 / (law.exponent + 1.0);
    law.hertz_time = 2.0 * a * boost::math::beta(a, 0.5);
  }

  // Starting values: the runs' mean two-point ln e and mean contact time.
  double q = 0.0, speed = 0.0, tau = 0.0, mass = 0.0;
  int contacts = 0;
  for (const PreparedRun& p : runs) {
    const Pendulum& pendulum = p.run->pendulum;
    const double va = SpeedFromAmplitude(pendulum, p.x.front());
    const double vb = SpeedFromAmplitude(pendulum, p.x.back());
    q += std::log(vb / va) / (p.rebounds.back() - p.rebounds.front()) / runs.size();
    speed += va / runs.size();
    mass += p.run->mass / runs.size();
    if (p.has_contact) {
      tau += *p.run->measured.contact_time;
      ++contacts;
    }
  }
  q = std::min(q, -1e-3);
  if (contacts > 0) tau /= contacts;
  std::vector<double>& theta = out.theta;
  theta.assign(static_cast<std::size_t>(law.Size()), 0.0);
  std::vector<std::string> names;
  if (kind == ContactLawKind::kKelvinVoigt) {
    const double zeta = DampingRatioFromLogRestitution(q, options.separation);
    theta[0] = std::log(zeta);
    names.push_back("log zeta");
    if (law.fit_stiffness) {
      theta[1] = std::log(StiffnessFromContactTime(mass, tau, zeta, options.separation));
      names.push_back("log K");
    }
  } else if (kind == ContactLawKind::kHertzDamper) {
    if (!law.fit_stiffness) {
      fit.reason = "needs contact times: the maxima alone fix only the combination c k^(-1/(n+1))";
      fit.status.seconds = stopwatch.Seconds();
      return out;
    }
    // Hertz's k from the contact times, then c from the damping ratio the
    // decay suggests: at n = 1, beta = 2 zeta.
    const double n = law.exponent;
    const double x_star = tau * speed / law.hertz_time;
    const double log_k =
        std::log(0.5 * (n + 1.0) * mass * speed * speed) - (n + 1.0) * std::log(x_star);
    const double zeta = DampingRatioFromLogRestitution(q, options.separation);
    theta[0] = std::log(2.0 * zeta * mass * speed / x_star);
    theta[1] = log_k;
    names = {"log c", "log k"};
  } else {
    if (law.HasDamping()) {
      const double chi = DampingFactorFor(std::exp(q), speed, DampingFactorConvention::kExact);
      theta[0] = std::log(std::max(chi, 1e-12 / speed));
      names.push_back("log chi");
    }
    if (law.fit_stiffness) {
      // Hertz: tau = c_n x*/v, so x* = tau v / c_n and k = (n+1) M v^2 / (2 x*^(n+1)).
      const double n = law.exponent;
      const double x_star = tau * speed / law.hertz_time;
      theta[static_cast<std::size_t>(law.StiffnessIndex())] =
          std::log(0.5 * (n + 1.0) * mass * speed * speed) - (n + 1.0) * std::log(x_star);
      names.push_back("log k");
      if (law.FitsExponent()) {
        theta.back() = n;
        names.push_back("n");
      }
    }
  }

  std::vector<double>& w = out.w;
  for (const PreparedRun& p : runs) {
    w.push_back(std::log(SpeedFromAmplitude(p.run->pendulum, p.x.front())) -
                p.rebounds.front() * q);
  }

  ceres::Problem problem;
  std::vector<RunResiduals> functors;
  functors.reserve(runs.size());
  for (std::size_t i = 0; i < runs.size(); ++i) {
    functors.push_back({&runs[i], &law});
    auto* cost =
        new ceres::DynamicAutoDiffCostFunction<RunResiduals, 4>(new RunResiduals(functors.back()));
    cost->AddParameterBlock(1);
    std::vector<double*> blocks{&w[i]};
    if (law.Size() > 0) {
      cost->AddParameterBlock(law.Size());
      blocks.push_back(theta.data());
    }
    cost->SetNumResiduals(functors.back().Count());
    problem.AddResidualBlock(cost, nullptr, blocks);
    fit.maxima += static_cast<int>(runs[i].x.size());
    fit.contact_times += runs[i].has_contact ? 1 : 0;
  }
  if (law.FitsExponent()) {
    problem.SetParameterLowerBound(theta.data(), law.Size() - 1, 0.5);
    problem.SetParameterUpperBound(theta.data(), law.Size() - 1, 5.0);
  }
  fit.parameter_count = law.Size() + static_cast<int>(runs.size());
  fit.dof = fit.maxima + fit.contact_times - fit.parameter_count;

  const auto finish = [&] {
    fit.status.seconds = stopwatch.Seconds();
    return out;
  };
  if (!fit_internal::SolveUsable(problem, options.solver, &fit.status, &fit.reason)) {
    return finish();
  }

  // chi^2 split between maxima and contact times.
  for (std::size_t i = 0; i < runs.size(); ++i) {
    std::vector<double> r(static_cast<std::size_t>(functors[i].Count()));
    const double* blocks[2] = {&w[i], theta.data()};
    if (!functors[i](blocks, r.data())) continue;
    for (std::size_t k = 0; k < runs[i].x.size(); ++k) fit.chi2_maxima += r[k] * r[k];
    if (runs[i].has_contact) fit.chi2_contact += r.back() * r.back();
  }
  fit.chi2 = fit.chi2_maxima + fit.chi2_contact;
  const double data = fit.maxima + fit.contact_times;
  fit.aic = fit.chi2 + 2.0 * fit.parameter_count;
  fit.bic = fit.chi2 + fit.parameter_count * std::log(data);
  fit.scatter = CheckScatter(fit.chi2, fit.dof);

  std::vector<double*> blocks;
  if (law.Size() > 0) blocks.push_back(theta.data());
  for (double& wi : w) blocks.push_back(&wi);
  Eigen::VectorXd residuals;
  const Eigen::MatrixXd jacobian = fit_internal::Jacobian(problem, blocks, &residuals);
  Identifiability id;
  id.identifiable = true;
  if (law.Size() > 0) {
    id = fit_internal::Analyse(jacobian, law.Size(), names, options.min_relative_singular_value);
  }
  fit.identifiability = Sentence(law, runs, id);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
  const Eigen::VectorXd s = svd.singularValues();
  if (law.Size() > 0 && !id.identifiable) {
    fit.reason = "not identifiable: " + id.message;
    return finish();
  }
  if (s.size() < jacobian.cols() || !(s[s.size() - 1] > 0.0)) {
    fit.reason = "the Jacobian is singular";
    return finish();
  }
  const Eigen::MatrixXd v = svd.matrixV();
  const Eigen::MatrixXd cov = v * s.cwiseInverse().cwiseAbs2().asDiagonal() * v.transpose();
  const auto p = static_cast<Eigen::Index>(law.Size());
  if (p > 0) fit.covariance = fit_internal::MakeCovariance(names, cov.topLeftCorner(p, p), false);
  for (Eigen::Index i = 0; i < p; ++i) {
    const double value = theta[static_cast<std::size_t>(i)];
    const double sd = std::sqrt(cov(i, i));
    const std::string& name = names[static_cast<std::size_t>(i)];
    if (name == "n") {
      fit.parameters.push_back({"exponent", "1", {value, sd}});
      continue;
    }
    const Estimate e{std::exp(value), std::exp(value) * sd};
    if (name == "log zeta") fit.parameters.push_back({"damping_ratio", "1", e});
    if (name == "log K") fit.parameters.push_back({"stiffness", "stiffness", e});
    if (name == "log chi") fit.parameters.push_back({"damping_factor", "inverse_speed", e});
    if (name == "log k") fit.parameters.push_back({"hertz_stiffness", "hertz_stiffness", e});
    if (name == "log c") fit.parameters.push_back({"damping", "damping", e});
  }
  for (std::size_t i = 0; i < w.size(); ++i) {
    const auto wi = p + static_cast<Eigen::Index>(i);
    fit.run_rebound0_speed.push_back({std::exp(w[i]), std::exp(w[i]) * std::sqrt(cov(wi, wi))});
  }
  if (options.intervals && options.profile_tolerance > 0.0) {
    const double inf = std::numeric_limits<double>::infinity();
    for (Eigen::Index i = 0; i < p; ++i) {
      const bool is_n = names[static_cast<std::size_t>(i)] == "n";
      ParameterInterval interval =
          IntervalOf(problem, theta, w, cov, static_cast<int>(i), fit.chi2, fit.scatter.Scale(),
                     !is_n, is_n ? std::pair{0.5, 5.0} : std::pair{-inf, inf}, options);
      interval.name = fit.parameters[static_cast<std::size_t>(i)].name;
      fit.intervals.push_back(interval);
    }
  }
  fit.ok = true;
  return finish();
}

// Predicts the held-out run's later maxima from its measured first one.
void PredictHeldOut(const LawModel& law, const std::vector<double>& theta, const PreparedRun& p,
                    double* ss_norm, double* ss_length, int* count, bool* ok) {
  const Pendulum& pendulum = p.run->pendulum;
  double v = SpeedFromAmplitude(pendulum, p.x.front());
  std::size_t k = 1;
  for (int n = p.rebounds.front(); n < p.last && k < p.x.size(); ++n) {
    double e = 1.0;
    if (!law.Restitution(theta.data(), v, p.run->mass, &e)) {
      *ok = false;
      return;
    }
    v *= e;
    if (p.rebounds[k] != n + 1) continue;
    double a = 0.0;
    if (!Amplitude(pendulum, v, &a)) {
      *ok = false;
      return;
    }
    const double d = a - p.x[k];
    *ss_norm += (d / p.sigma[k]) * (d / p.sigma[k]);
    *ss_length += d * d;
    ++*count;
    ++k;
  }
}

}  // namespace

const char* ContactLawName(ContactLawKind kind) {
  switch (kind) {
    case ContactLawKind::kKelvinVoigt:
      return "kelvin-voigt";
    case ContactLawKind::kHertz:
      return "hertz";
    case ContactLawKind::kHuntCrossley:
      return "hunt-crossley";
    case ContactLawKind::kHuntCrossleyExponent:
      return "hunt-crossley-n";
    case ContactLawKind::kHertzDamper:
      return "hertz-damper";
  }
  return "";
}

bool ContactLawFitOptions::Check(std::string* why) const {
  if (!(exponent > 0.0 && exponent <= 10.0)) {
    *why = fmt::format("exponent must be in (0, 10], got {}", exponent);
    return false;
  }
  return solver.Check(why) &&
         fit_internal::CheckRelativeSingularValue(min_relative_singular_value, why);
}

std::string ContactLawUninformed(ContactLawKind kind, const std::vector<LawRun>& runs,
                                 const ContactLawFitOptions& options) {
  if (kind == ContactLawKind::kKelvinVoigt || kind == ContactLawKind::kHuntCrossley) return {};
  // The contact times the fit would use (as Prepare takes them), and the
  // impact speed of each whose maximum before it was read.
  int contacts = 0;
  std::vector<double> log_speed, weight;
  for (const LawRun& run : runs) {
    const ReboundMeasurements& m = run.measured;
    if (!options.use_contact_times || !m.contact_time || !(m.contact_time_sigma > 0.0) ||
        !(*m.contact_time > 0.0)) {
      continue;
    }
    int last = -1;
    for (std::size_t i = 0; i < m.xmax.size(); ++i) {
      if (!std::isnan(m.xmax[i])) last = static_cast<int>(i);
    }
    const int c = run.contact_rebound;
    if (c < -1 || c > last) continue;
    ++contacts;
    const double amplitude = c < 0 ? run.initial_displacement : m.xmax[static_cast<std::size_t>(c)];
    if (!(amplitude > 0.0) || !(run.mass > 0.0)) continue;
    log_speed.push_back(std::log(SpeedFromAmplitude(run.pendulum, amplitude)));
    const double relative = m.contact_time_sigma / *m.contact_time;
    weight.push_back(1.0 / (relative * relative));
  }
  if (contacts == 0) {
    switch (kind) {
      case ContactLawKind::kHertz:
        return "the elastic law has nothing to fit in the maxima (e = 1), and no run has its own "
               "contact time with a sigma to fix k";
      case ContactLawKind::kHertzDamper:
        return "the maxima alone fix only the combination c k^(-1/(n+1)), and no run has its own "
               "contact time with a sigma to fix k";
      default:
        return "n is fixed by how the contact time changes with impact speed, and no run has its "
               "own contact time with a sigma";
    }
  }
  if (kind != ContactLawKind::kHuntCrossleyExponent) return {};
  // tau_c ~ v^s, s = -(n-1)/(n+1) (the Hertz part): the weighted line of
  // ln tau_c on ln v fixes s to 1/sqrt(Sxx), and n = (1-s)/(1+s) to
  // (n+1)^2/2 times that at the fixed n. Worse than kMaxExponentSigma, n is
  // not fixed within its range [0.5, 5].
  constexpr double kMaxExponentSigma = 1.0;
  double sw = 0.0, swx = 0.0;
  for (std::size_t i = 0; i < log_speed.size(); ++i) {
    sw += weight[i];
    swx += weight[i] * log_speed[i];
  }
  double sxx = 0.0;
  for (std::size_t i = 0; i < log_speed.size(); ++i) {
    const double d = log_speed[i] - swx / sw;
    sxx += weight[i] * d * d;
  }
  const double n = options.exponent;
  const double sigma_n = sxx > 0.0 ? 0.5 * (n + 1.0) * (n + 1.0) / std::sqrt(sxx)
                                   : std::numeric_limits<double>::infinity();
  if (sigma_n <= kMaxExponentSigma) return {};
  return fmt::format(
      "n is fixed by how the contact time changes with impact speed: the {} contact time{} "
      "(ln v spread {:.2g}) would fix n to +-{:.2g} at best, more than {}",
      contacts, contacts == 1 ? "" : "s",
      log_speed.empty() ? 0.0
                        : *std::max_element(log_speed.begin(), log_speed.end()) -
                              *std::min_element(log_speed.begin(), log_speed.end()),
      sigma_n, kMaxExponentSigma);
}

ContactLawFit FitContactLaw(ContactLawKind kind, const std::vector<LawRun>& runs,
                            const ContactLawFitOptions& options) {
  if (std::string why; !options.Check(&why)) throw std::invalid_argument(why);
  // Runs the law cannot be fitted to: a fit that did not run, with why.
  const auto refuse = [&](std::string why) {
    ContactLawFit refused;
    refused.law = ContactLawName(kind);
    refused.reason = std::move(why);
    return refused;
  };
  if (runs.size() < 2) {
    return refuse(fmt::format("a contact law needs two runs or more, got {}", runs.size()));
  }
  const fit_internal::Stopwatch stopwatch;
  std::vector<PreparedRun> prepared;
  for (const LawRun& run : runs) {
    std::string refusal;
    std::optional<PreparedRun> p = Prepare(run, options.use_contact_times, &refusal);
    if (!p) return refuse(refusal);
    prepared.push_back(std::move(*p));
  }
  Solved solved = Solve(kind, prepared, options);
  ContactLawFit& fit = solved.fit;
  if (!fit.ok || !options.leave_one_out || prepared.size() < 3) return fit;

  // Leave one run out: the law refitted on the others predicts it (no
  // intervals needed of the refits).
  ContactLawFitOptions refit_options = options;
  refit_options.intervals = false;
  double ss_norm = 0.0, ss_length = 0.0;
  int count = 0;
  bool ok = true;
  for (std::size_t h = 0; h < prepared.size(); ++h) {
    std::vector<PreparedRun> training;
    for (std::size_t i = 0; i < prepared.size(); ++i) {
      if (i != h) training.push_back(prepared[i]);
    }
    const Solved refit = Solve(kind, training, refit_options);
    if (!refit.fit.ok) {
      ok = false;
      continue;
    }
    PredictHeldOut(refit.law, refit.theta, prepared[h], &ss_norm, &ss_length, &count, &ok);
  }
  fit.status.seconds = stopwatch.Seconds();
  fit.loo_ok = ok && count > 0;
  fit.loo_maxima = count;
  if (count > 0) {
    fit.loo_rms_normalized = std::sqrt(ss_norm / count);
    fit.loo_rms_length = std::sqrt(ss_length / count);
  }
  return fit;
}

}  // namespace impactlab
