#include "synth/beam_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <Eigen/Dense>

#include "io/log_reader.h"  // kStandardGravity
#include "synth/beam_model_internal.h"
#include "synth/gaussian.h"

namespace impactlab {
namespace {

using beam_internal::LinearEquations;
constexpr double kPi = std::numbers::pi;
constexpr int kRk4StepsPerSample = 20;

// One phase's equations as a first-order system in y = (q, q').
template <int N>
class LinearPhase {
 public:
  using Coordinates = Eigen::Matrix<double, N, 1>;
  using State = Eigen::Matrix<double, 2 * N, 1>;

  explicit LinearPhase(const LinearEquations<N>& equations)
      : equations_(equations), mass_inverse_(equations.mass.inverse()) {}

  const Eigen::Matrix<double, N, N>& mass_inverse() const { return mass_inverse_; }

  Coordinates Acceleration(const State& y) const {
    return mass_inverse_ * (equations_.force - equations_.damping * y.template tail<N>() -
                            equations_.stiffness * y.template head<N>());
  }

  // Classical RK4 over `duration` in steps no longer than `max_step`.
  State Advance(State y, double duration, double max_step) const {
    if (duration <= 0.0) return y;
    const int steps = std::max(1, static_cast<int>(std::ceil(duration / max_step - 1e-9)));
    const double h = duration / steps;
    for (int s = 0; s < steps; ++s) {
      const State k1 = Derivative(y);
      const State k2 = Derivative(y + 0.5 * h * k1);
      const State k3 = Derivative(y + 0.5 * h * k2);
      const State k4 = Derivative(y + h * k3);
      y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    return y;
  }

 private:
  State Derivative(const State& y) const {
    State dy;
    dy << y.template tail<N>(), Acceleration(y);
    return dy;
  }

  LinearEquations<N> equations_;
  Eigen::Matrix<double, N, N> mass_inverse_;
};

// Amplitudes of known modes (plus a constant) in a clean record from sample
// `first` on, by linear least squares: the normal equations, accumulated a
// sample at a time so that a long record needs no design matrix.
std::vector<double> ModeAmplitudes(const std::vector<double>& y, std::size_t first, double rate_hz,
                                   const std::vector<BeamPole>& modes) {
  // Columns: the constant, then per mode e^(-sigma t) (real pole) or
  // e^(-sigma t) cos and sin (pair).
  std::vector<Eigen::Index> column_of(modes.size());
  Eigen::Index columns = 1;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    column_of[m] = columns;
    columns += modes[m].frequency_hz > 0.0 ? 2 : 1;
  }
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(columns, columns);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(columns);
  Eigen::VectorXd row = Eigen::VectorXd::Zero(columns);
  for (std::size_t i = first; i < y.size(); ++i) {
    const double t = static_cast<double>(i - first) / rate_hz;
    row[0] = 1.0;
    for (std::size_t m = 0; m < modes.size(); ++m) {
      const double e = std::exp(-modes[m].decay_rate_per_s * t);
      const double w = 2.0 * kPi * modes[m].frequency_hz * t;
      row[column_of[m]] = e * std::cos(w);
      if (modes[m].frequency_hz > 0.0) row[column_of[m] + 1] = e * std::sin(w);
    }
    rhs += row * y[i];
    normal.noalias() += row * row.transpose();
  }
  const Eigen::VectorXd x = normal.partialPivLu().solve(rhs);
  std::vector<double> amplitudes;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    const Eigen::Index c = column_of[m];
    amplitudes.push_back(modes[m].frequency_hz > 0.0 ? std::hypot(x[c], x[c + 1]) : std::abs(x[c]));
  }
  return amplitudes;
}

using synth_detail::Gaussian;

}  // namespace

BeamRecord SimulateBeam(const BeamArm& arm, const BeamSensors& sensors, double sample_rate_hz,
                        double duration_s) {
  using beam_internal::TipDeflectionShape;
  using beam_internal::TipSlopeShape;
  if (std::string error; !arm.Check(&error)) throw std::invalid_argument("BeamArm: " + error);
  const double l = arm.length_m;
  const LinearEquations<3> free_equations = beam_internal::FreeFlightEquations(arm);
  const LinearEquations<2> wall_equations = beam_internal::OnTheWallEquations(free_equations, l);
  const LinearPhase<3> free(free_equations);
  const LinearPhase<2> pinned(wall_equations);
  const Eigen::Matrix<double, 3, 2> on_the_wall = beam_internal::OnTheWallBasis(l);

  BeamRecord record;
  record.free_modes =
      beam_internal::Poles(free_equations.mass, free_equations.damping, free_equations.stiffness);
  record.post_modes =
      beam_internal::Poles(wall_equations.mass, wall_equations.damping, wall_equations.stiffness);

  // The sensors' transverse velocities from p': each accelerometer sample is
  // their change over the sample interval.
  const double xa = sensors.a1_position, d = sensors.a2_inboard_m;
  const Eigen::RowVector3d a1_velocity(xa * l, TipDeflectionShape(xa), TipSlopeShape(xa, l));
  const Eigen::RowVector3d a2_velocity(l - d, 1.0, -d);
  // The wall's push on the tip (>= 0 while it holds the tip), from
  // M p'' + C p' + K p = Q + G^T lambda with G p'' = 0.
  const Eigen::RowVector3d g = beam_internal::TipTravelRow(l);
  const Eigen::Vector3d m_inv_g = free.mass_inverse() * g.transpose();
  const double g_m_inv_g = g.dot(m_inv_g);
  auto contact_force = [&](const Eigen::Matrix<double, 6, 1>& y_full) {
    return g.dot(free.Acceleration(y_full)) / g_m_inv_g;  // = -lambda
  };
  // (q2, q3, q2', q3') on the wall -> (p, p').
  auto full_state = [&](const Eigen::Vector4d& r) {
    Eigen::Matrix<double, 6, 1> y_full;
    y_full << on_the_wall * r.head<2>(), on_the_wall * r.tail<2>();
    y_full[0] += arm.wall_angle_rad;
    return y_full;
  };
  // Subtracting the angles first keeps the gap's digits near the wall.
  auto gap = [&](const Eigen::Matrix<double, 6, 1>& y_full) {
    return l * (y_full[0] - arm.wall_angle_rad) + y_full[1];
  };

  const double dt = 1.0 / sample_rate_hz, step = dt / kRk4StepsPerSample;
  const auto rows = static_cast<std::size_t>(std::llround(duration_s * sample_rate_hz));
  Eigen::Matrix<double, 6, 1> y = Eigen::Matrix<double, 6, 1>::Zero();
  y[0] = arm.start_angle_rad;
  Eigen::Vector4d r = Eigen::Vector4d::Zero();  // on the wall, after the impact
  double t_state = arm.start_delay_s;           // y holds the state at this time (at rest before)
  bool impacted = false;
  record.min_contact_force_n = std::numeric_limits<double>::infinity();

  double v1_before = 0.0, v2_before = 0.0;  // at the previous sample
  for (std::size_t i = 0; i < rows; ++i) {
    const double t = static_cast<double>(i) * dt;
    if (!impacted && t > t_state) {
      const Eigen::Matrix<double, 6, 1> next = free.Advance(y, t - t_state, step);
      if (gap(next) >= 0.0) {
        // Bisect the crossing inside (t_state, t].
        double lo = 0.0, hi = t - t_state;
        for (int it = 0; it < 200 && hi - lo > 1e-13; ++it) {
          const double mid = 0.5 * (lo + hi);
          (gap(free.Advance(y, mid, step)) >= 0.0 ? hi : lo) = mid;
        }
        Eigen::Matrix<double, 6, 1> at = free.Advance(y, hi, step);
        record.impact_time_s = t_state + hi;
        // Plastic impact: project the velocity onto G p' = 0.
        const double tip_speed = g.dot(at.tail<3>());
        record.impact_speed_m_s = tip_speed;
        at.tail<3>() -= m_inv_g * tip_speed / g_m_inv_g;
        r << at[1], at[2], at[4], at[5];
        r = pinned.Advance(r, t - record.impact_time_s, step);
        t_state = t;
        impacted = true;
      } else {
        y = next;
        t_state = t;
      }
    } else if (impacted) {
      r = pinned.Advance(r, t - t_state, step);
      t_state = t;
    }
    const Eigen::Matrix<double, 6, 1> full = impacted ? full_state(r) : y;
    if (impacted) {
      record.min_contact_force_n = std::min(record.min_contact_force_n, contact_force(full));
    }
    const double v1 = a1_velocity.dot(full.tail<3>()), v2 = a2_velocity.dot(full.tail<3>());
    record.time_s.push_back(t);
    record.angle_rad.push_back(full[0]);
    record.a1_m_s2.push_back(i == 0 ? 0.0 : (v1 - v1_before) * sample_rate_hz);
    record.a2_m_s2.push_back(i == 0 ? 0.0 : (v2 - v2_before) * sample_rate_hz);
    v1_before = v1;
    v2_before = v2;
  }
  if (!impacted) {
    throw std::invalid_argument(fmt::format(
        "the tip does not reach the wall within {} s; lengthen the record", duration_s));
  }
  // The first sample whose interval lies wholly after the impact.
  const auto first = static_cast<std::size_t>(std::ceil(record.impact_time_s * sample_rate_hz)) + 1;
  for (const auto* channel : {&record.angle_rad, &record.a1_m_s2, &record.a2_m_s2}) {
    record.post_mode_amplitudes.push_back(
        ModeAmplitudes(*channel, first, sample_rate_hz, record.post_modes));
  }
  return record;
}

LoggedSamples LogExperiment(const BeamRecord& record, const BeamSensors& sensors,
                            double noise_factor, std::uint64_t seed) {
  const double counts_per_rad = sensors.counts_per_rev * sensors.gear_ratio / (2.0 * kPi);
  Gaussian noise(seed);
  auto volts = [&](double a, double sensitivity, double sigma) {
    const double v = a / kStandardGravity * sensitivity + noise_factor * sigma * noise();
    return std::round(v / sensors.adc_lsb_v) * sensors.adc_lsb_v;
  };
  LoggedSamples logged;
  logged.time_s = record.time_s;
  for (std::size_t i = 0; i < record.time_s.size(); ++i) {
    logged.encoder_counts.push_back(
        static_cast<long long>(std::floor(record.angle_rad[i] * counts_per_rad)));
    // a1's deviate before a2's, row by row: the order the seed's bytes follow.
    logged.a1_v.push_back(
        volts(record.a1_m_s2[i], sensors.a1_sensitivity_v_per_g, sensors.a1_noise_v));
    logged.a2_v.push_back(
        volts(record.a2_m_s2[i], sensors.a2_sensitivity_v_per_g, sensors.a2_noise_v));
  }
  return logged;
}

}  // namespace impactlab
