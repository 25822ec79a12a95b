#include "synth/beam_logs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/log_reader.h"  // kStandardGravity

namespace impactlab {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr int kRk4StepsPerSample = 20;

// ---------------------------------------------------------------------------
// Small dense algebra (the model has at most 3 degrees of freedom).

template <typename T>
using Matrix = std::vector<std::vector<T>>;

template <typename T>
Matrix<T> Zeros(std::size_t n) {
  return Matrix<T>(n, std::vector<T>(n, T(0)));
}

// Solves A x = b by Gaussian elimination with partial pivoting.
template <typename T>
std::vector<T> Solve(Matrix<T> a, std::vector<T> b) {
  const std::size_t n = b.size();
  for (std::size_t col = 0; col < n; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < n; ++r) {
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    }
    std::swap(a[col], a[pivot]);
    std::swap(b[col], b[pivot]);
    for (std::size_t r = col + 1; r < n; ++r) {
      const T f = a[r][col] / a[col][col];
      for (std::size_t c = col; c < n; ++c) a[r][c] -= f * a[col][c];
      b[r] -= f * b[col];
    }
  }
  std::vector<T> x(n);
  for (std::size_t i = n; i-- > 0;) {
    T sum = b[i];
    for (std::size_t c = i + 1; c < n; ++c) sum -= a[i][c] * x[c];
    x[i] = sum / a[i][i];
  }
  return x;
}

template <typename T>
T Determinant(Matrix<T> a) {
  const std::size_t n = a.size();
  T det = T(1);
  for (std::size_t col = 0; col < n; ++col) {
    std::size_t pivot = col;
    for (std::size_t r = col + 1; r < n; ++r) {
      if (std::abs(a[r][col]) > std::abs(a[pivot][col])) pivot = r;
    }
    if (pivot != col) {
      std::swap(a[col], a[pivot]);
      det = -det;
    }
    if (a[col][col] == T(0)) return T(0);
    det *= a[col][col];
    for (std::size_t r = col + 1; r < n; ++r) {
      const T f = a[r][col] / a[col][col];
      for (std::size_t c = col; c < n; ++c) a[r][c] -= f * a[col][c];
    }
  }
  return det;
}

Matrix<double> Inverse(const Matrix<double>& a) {
  const std::size_t n = a.size();
  Matrix<double> inverse = Zeros<double>(n);
  for (std::size_t c = 0; c < n; ++c) {
    std::vector<double> e(n, 0.0);
    e[c] = 1.0;
    const std::vector<double> column = Solve(a, e);
    for (std::size_t r = 0; r < n; ++r) inverse[r][c] = column[r];
  }
  return inverse;
}

std::vector<double> Multiply(const Matrix<double>& a, const std::vector<double>& x) {
  std::vector<double> y(a.size(), 0.0);
  for (std::size_t r = 0; r < a.size(); ++r) {
    for (std::size_t c = 0; c < x.size(); ++c) y[r] += a[r][c] * x[c];
  }
  return y;
}

// T^T A T for a 3x3 A and 3x2 T.
Matrix<double> Project(const Matrix<double>& a, const std::array<std::array<double, 2>, 3>& t) {
  Matrix<double> out = Zeros<double>(2);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) out[i][j] += t[r][i] * a[r][c] * t[c][j];
      }
    }
  }
  return out;
}

// ---------------------------------------------------------------------------
// The assumed-mode model.

// Gauss-Legendre, 5 points on [0, 1]: exact to degree 9 (the integrands are <= 6).
constexpr std::array<double, 5> kGaussX = {0.04691007703066800, 0.2307653449471585, 0.5,
                                           0.7692346550528415, 0.9530899229693320};
constexpr std::array<double, 5> kGaussW = {0.1184634425280945, 0.2393143352496832,
                                           0.2844444444444444, 0.2393143352496832,
                                           0.1184634425280945};

// Shape functions (paper eq. 8) and their second derivatives, at x = xi L.
double Phi2(double xi) { return 3.0 * xi * xi - 2.0 * xi * xi * xi; }
double Phi3(double xi, double l) { return l * (xi * xi * xi - xi * xi); }
double Phi2dd(double xi, double l) { return (6.0 - 12.0 * xi) / (l * l); }
double Phi3dd(double xi, double l) { return (6.0 * xi - 2.0) / l; }

struct ArmMatrices {
  Matrix<double> m, c, k;  // for p = (theta, q2, q3)
};

ArmMatrices Assemble(const BeamArm& arm) {
  const double l = arm.length_m, rho = arm.mass_per_length_kg_per_m;
  ArmMatrices a{Zeros<double>(3), Zeros<double>(3), Zeros<double>(3)};
  double x_phi2 = 0, x_phi3 = 0, phi22 = 0, phi23 = 0, phi33 = 0, k22 = 0, k23 = 0, k33 = 0;
  for (int g = 0; g < 5; ++g) {
    const double xi = kGaussX[g], w = kGaussW[g] * l;
    const double x = xi * l, p2 = Phi2(xi), p3 = Phi3(xi, l);
    const double d2 = Phi2dd(xi, l), d3 = Phi3dd(xi, l);
    x_phi2 += w * x * p2;
    x_phi3 += w * x * p3;
    phi22 += w * p2 * p2;
    phi23 += w * p2 * p3;
    phi33 += w * p3 * p3;
    k22 += w * d2 * d2;
    k23 += w * d2 * d3;
    k33 += w * d3 * d3;
  }
  // Kinetic energy: hub, beam (x theta' + w'), tip mass (L theta' + q2'),
  // tip body rotation (theta' + q3', since phi2'(L) = 0 and phi3'(L) = 1).
  const double mt = arm.tip_mass_kg, jt = arm.tip_inertia_kg_m2;
  a.m[0][0] = arm.hub_inertia_kg_m2 + rho * l * l * l / 3.0 + mt * l * l + jt;
  a.m[0][1] = a.m[1][0] = rho * x_phi2 + mt * l;
  a.m[0][2] = a.m[2][0] = rho * x_phi3 + jt;
  a.m[1][1] = rho * phi22 + mt;
  a.m[1][2] = a.m[2][1] = rho * phi23;
  a.m[2][2] = rho * phi33 + jt;
  const double ei = arm.flexural_rigidity_n_m2, cw = arm.beam_damping_n_s_per_m2;
  a.k[1][1] = ei * k22;
  a.k[1][2] = a.k[2][1] = ei * k23;
  a.k[2][2] = ei * k33;
  a.c[0][0] = arm.hub_damping_n_m_s;
  a.c[1][1] = cw * phi22;
  a.c[1][2] = a.c[2][1] = cw * phi23;
  a.c[2][2] = cw * phi33;
  return a;
}

// M q'' + C q' + K q = Q as a first-order system y = (q, q').
struct Phase {
  Matrix<double> m_inverse, c, k;
  std::vector<double> force;

  std::size_t dofs() const { return force.size(); }

  std::vector<double> Acceleration(const std::vector<double>& y) const {
    const std::size_t n = dofs();
    std::vector<double> rhs = force;
    for (std::size_t r = 0; r < n; ++r) {
      for (std::size_t j = 0; j < n; ++j) rhs[r] -= c[r][j] * y[n + j] + k[r][j] * y[j];
    }
    return Multiply(m_inverse, rhs);
  }

  std::vector<double> Derivative(const std::vector<double>& y) const {
    const std::size_t n = dofs();
    std::vector<double> dy(2 * n);
    std::copy(y.begin() + static_cast<std::ptrdiff_t>(n), y.end(), dy.begin());
    const std::vector<double> acc = Acceleration(y);
    std::copy(acc.begin(), acc.end(), dy.begin() + static_cast<std::ptrdiff_t>(n));
    return dy;
  }

  // Classical RK4 over `duration` in steps no longer than `max_step`.
  std::vector<double> Advance(std::vector<double> y, double duration, double max_step) const {
    if (duration <= 0.0) return y;
    const int steps = std::max(1, static_cast<int>(std::ceil(duration / max_step - 1e-9)));
    const double h = duration / steps;
    auto axpy = [](const std::vector<double>& a, double s, const std::vector<double>& b) {
      std::vector<double> out(a.size());
      for (std::size_t i = 0; i < a.size(); ++i) out[i] = a[i] + s * b[i];
      return out;
    };
    for (int s = 0; s < steps; ++s) {
      const auto k1 = Derivative(y);
      const auto k2 = Derivative(axpy(y, 0.5 * h, k1));
      const auto k3 = Derivative(axpy(y, 0.5 * h, k2));
      const auto k4 = Derivative(axpy(y, h, k3));
      for (std::size_t i = 0; i < y.size(); ++i) {
        y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
      }
    }
    return y;
  }
};

// theta = theta_w - q2 / L: p = T r + (theta_w, 0, 0), r = (q2, q3).
std::array<std::array<double, 2>, 3> ConstraintBasis(double l) {
  return {{{-1.0 / l, 0.0}, {1.0, 0.0}, {0.0, 1.0}}};
}

// Poles of det(M s^2 + C s + K), each complex pair once, real poles with
// frequency 0 (the first entries): the polynomial's coefficients by
// interpolation on a circle, its roots by Durand-Kerner iteration.
std::vector<BeamMode> Modes(const Matrix<double>& m, const Matrix<double>& c,
                            const Matrix<double>& k) {
  using Complex = std::complex<double>;
  const std::size_t n = m.size();
  const std::size_t degree = 2 * n;
  double trace_m = 0, trace_k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    trace_m += m[i][i];
    trace_k += k[i][i];
  }
  // s = scale u keeps |u| ~ 1: the roots' geometric mean when K is regular.
  const double det_k = Determinant(k), det_m = Determinant(m);
  const double scale = det_k > 0.0 ? std::pow(det_k / det_m, 1.0 / static_cast<double>(degree))
                                   : std::sqrt(trace_k / trace_m);
  auto det_s = [&](Complex s) {
    Matrix<Complex> a = Zeros<Complex>(n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) a[i][j] = m[i][j] * s * s + c[i][j] * s + k[i][j];
    }
    return Determinant(a);
  };
  auto det = [&](Complex u) { return det_s(scale * u); };
  const std::size_t points = degree + 1;
  std::vector<Complex> values(points), nodes(points);
  for (std::size_t j = 0; j < points; ++j) {
    nodes[j] = std::polar(1.0, 2.0 * kPi * static_cast<double>(j) / static_cast<double>(points));
    values[j] = det(nodes[j]);
  }
  std::vector<Complex> coefficient(points);
  for (std::size_t p = 0; p < points; ++p) {
    for (std::size_t j = 0; j < points; ++j) {
      coefficient[p] += values[j] * std::pow(std::conj(nodes[j]), static_cast<double>(p));
    }
    coefficient[p] /= static_cast<double>(points);
  }
  auto polynomial = [&](Complex u) {
    Complex v = 0.0;
    for (std::size_t p = points; p-- > 0;) v = v * u + coefficient[p] / coefficient[degree];
    return v;
  };
  std::vector<Complex> roots(degree);
  for (std::size_t i = 0; i < degree; ++i) roots[i] = std::pow(Complex(0.4, 0.9), double(i));
  for (int iteration = 0; iteration < 2000; ++iteration) {
    double change = 0.0;
    for (std::size_t i = 0; i < degree; ++i) {
      Complex denominator = 1.0;
      for (std::size_t j = 0; j < degree; ++j) {
        if (j != i) denominator *= roots[i] - roots[j];
      }
      const Complex step = polynomial(roots[i]) / denominator;
      roots[i] -= step;
      change = std::max(change, std::abs(step));
    }
    if (change < 1e-15) break;
  }
  std::vector<BeamMode> modes;
  for (const Complex& u : roots) {
    // Newton on the determinant itself: the coefficients lose digits when the
    // roots spread over decades, the determinant does not.
    Complex s = scale * u;
    for (int iteration = 0; iteration < 8 && std::abs(s) > 0.0; ++iteration) {
      const Complex h = 1e-7 * std::abs(s);
      const Complex slope = (det_s(s + h) - det_s(s - h)) / (2.0 * h);
      if (std::abs(slope) == 0.0) break;
      const Complex step = det_s(s) / slope;
      s -= step;
      if (std::abs(step) <= 1e-15 * std::abs(s)) break;
    }
    // The rigid rotation's root at 0 is no mode; a conjugate pair counts once.
    if (!(std::abs(s) > 1e-6 * scale) || s.imag() < -1e-9 * std::abs(s)) continue;
    BeamMode mode;
    const bool real = std::abs(s.imag()) <= 1e-9 * std::abs(s);
    mode.frequency_hz = real ? 0.0 : s.imag() / (2.0 * kPi);
    mode.natural_frequency_hz = std::abs(s) / (2.0 * kPi);
    mode.damping_ratio = real ? 1.0 : -s.real() / std::abs(s);
    mode.decay_rate_per_s = -s.real();
    modes.push_back(mode);
  }
  std::sort(modes.begin(), modes.end(), [](const BeamMode& a, const BeamMode& b) {
    return std::pair(a.frequency_hz, a.decay_rate_per_s) <
           std::pair(b.frequency_hz, b.decay_rate_per_s);
  });
  return modes;
}

// Amplitudes of known modes (plus a constant) in a clean record, by linear least
// squares (normal equations; a handful of columns).
std::vector<double> ModeAmplitudes(const std::vector<double>& y, std::size_t first, double rate_hz,
                                   const std::vector<BeamMode>& modes) {
  // Columns: the constant, then per mode e^(-sigma t) (real pole) or
  // e^(-sigma t) cos and sin (pair).
  std::vector<std::size_t> column_of(modes.size());
  std::size_t columns = 1;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    column_of[m] = columns;
    columns += modes[m].frequency_hz > 0.0 ? 2 : 1;
  }
  Matrix<double> normal = Zeros<double>(columns);
  std::vector<double> rhs(columns, 0.0), row(columns);
  for (std::size_t i = first; i < y.size(); ++i) {
    const double t = static_cast<double>(i - first) / rate_hz;
    row[0] = 1.0;
    for (std::size_t m = 0; m < modes.size(); ++m) {
      const double e = std::exp(-modes[m].decay_rate_per_s * t);
      const double w = 2.0 * kPi * modes[m].frequency_hz * t;
      row[column_of[m]] = e * std::cos(w);
      if (modes[m].frequency_hz > 0.0) row[column_of[m] + 1] = e * std::sin(w);
    }
    for (std::size_t r = 0; r < columns; ++r) {
      rhs[r] += row[r] * y[i];
      for (std::size_t c = 0; c < columns; ++c) normal[r][c] += row[r] * row[c];
    }
  }
  const std::vector<double> x = Solve(normal, rhs);
  std::vector<double> amplitudes;
  for (std::size_t m = 0; m < modes.size(); ++m) {
    const std::size_t c = column_of[m];
    amplitudes.push_back(modes[m].frequency_hz > 0.0 ? std::hypot(x[c], x[c + 1]) : std::abs(x[c]));
  }
  return amplitudes;
}

// Standard normal deviates from a portable generator (Box-Muller on mt19937_64),
// so a seed writes the same bytes with any standard library.
class Gaussian {
 public:
  explicit Gaussian(std::uint64_t seed) : engine_(seed) {}
  double operator()() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = (static_cast<double>(engine_() >> 11) + 0.5) * 0x1.0p-53;
    const double u2 = static_cast<double>(engine_() >> 11) * 0x1.0p-53;
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * kPi * u2);
  }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

nlohmann::json ModesJson(const std::vector<BeamMode>& modes) {
  nlohmann::json out = nlohmann::json::array();
  for (const BeamMode& m : modes) {
    out.push_back({{"frequency_hz", m.frequency_hz},
                   {"natural_frequency_hz", m.natural_frequency_hz},
                   {"damping_ratio", m.damping_ratio},
                   {"decay_rate_per_s", m.decay_rate_per_s}});
  }
  return out;
}

nlohmann::json ArmJson(const BeamArm& arm) {
  return {{"length_m", arm.length_m},
          {"mass_per_length_kg_per_m", arm.mass_per_length_kg_per_m},
          {"flexural_rigidity_n_m2", arm.flexural_rigidity_n_m2},
          {"hub_inertia_kg_m2", arm.hub_inertia_kg_m2},
          {"tip_mass_kg", arm.tip_mass_kg},
          {"tip_inertia_kg_m2", arm.tip_inertia_kg_m2},
          {"beam_damping_n_s_per_m2", arm.beam_damping_n_s_per_m2},
          {"hub_damping_n_m_s", arm.hub_damping_n_m_s},
          {"motor_torque_n_m", arm.motor_torque_n_m},
          {"start_angle_rad", arm.start_angle_rad},
          {"wall_angle_rad", arm.wall_angle_rad},
          {"start_delay_s", arm.start_delay_s}};
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw InputError({path, "", std::nullopt}, "cannot write the file");
}

}  // namespace

bool BeamArm::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!(length_m > 0.0 && mass_per_length_kg_per_m > 0.0 && flexural_rigidity_n_m2 > 0.0)) {
    return fail("the beam needs a positive length, mass per length and EI");
  }
  if (!(hub_inertia_kg_m2 > 0.0 && tip_mass_kg >= 0.0 && tip_inertia_kg_m2 >= 0.0)) {
    return fail("inertias must be positive (hub) or >= 0 (tip)");
  }
  if (!(beam_damping_n_s_per_m2 >= 0.0 && hub_damping_n_m_s > 0.0)) {
    return fail("damping must be >= 0 (beam) and > 0 (hub)");
  }
  if (!(motor_torque_n_m > 0.0)) return fail("the motor torque must be positive");
  if (!(wall_angle_rad > start_angle_rad)) return fail("the wall must lie ahead of the start");
  if (!(start_delay_s >= 0.0)) return fail("start_delay_s must be >= 0");
  return true;
}

bool BeamLogOptions::Check(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = what;
    return false;
  };
  if (!simulation.Check(error)) return false;
  if (!ExperimentArm(*this).Check(error)) return false;
  if (!(sample_rate_hz >= 100.0 && sample_rate_hz <= 1e6)) {
    return fail("sample_rate_hz must lie in [100, 1e6]");
  }
  if (!(duration_s > 0.0) || duration_s * sample_rate_hz > 5e7) {
    return fail("duration_s must be positive and give at most 5e7 rows");
  }
  if (!(noise_factor >= 0.0)) return fail("noise_factor must be >= 0");
  if (log_id.empty()) return fail("log_id must not be empty");
  return true;
}

BeamArm ExperimentArm(const BeamLogOptions& options) {
  BeamArm arm = options.simulation;
  arm.tip_inertia_kg_m2 *= options.experiment_tip_inertia_factor;
  arm.hub_damping_n_m_s *= options.experiment_hub_damping_factor;
  arm.start_delay_s = options.experiment_start_delay_s;
  return arm;
}

BeamRecord SimulateBeam(const BeamArm& arm, const BeamSensors& sensors, double sample_rate_hz,
                        double duration_s) {
  if (std::string error; !arm.Check(&error)) throw std::invalid_argument("BeamArm: " + error);
  const ArmMatrices a = Assemble(arm);
  const double l = arm.length_m;
  const auto basis = ConstraintBasis(l);

  Phase free{Inverse(a.m), a.c, a.k, {arm.motor_torque_n_m, 0.0, 0.0}};
  const Matrix<double> mr = Project(a.m, basis), cr = Project(a.c, basis), kr = Project(a.k, basis);
  Phase pinned{Inverse(mr), cr, kr, {basis[0][0] * arm.motor_torque_n_m, 0.0}};

  BeamRecord record;
  record.free_modes = Modes(a.m, a.c, a.k);
  record.post_modes = Modes(mr, cr, kr);

  const double xa = sensors.a1_position, d = sensors.a2_inboard_m;
  // Transverse velocities of the sensors from p' = (theta', q2', q3') at
  // y[3..5]; each accelerometer sample is their change over the sample interval.
  auto v1_of = [&](const std::vector<double>& y_full) {
    return xa * l * y_full[3] + Phi2(xa) * y_full[4] + Phi3(xa, l) * y_full[5];
  };
  auto v2_of = [&](const std::vector<double>& y_full) {
    return (l - d) * y_full[3] + y_full[4] - d * y_full[5];
  };
  // The wall's push on the tip (>= 0 while it holds the tip), from
  // M p'' + C p' + K p = Q + G^T lambda with G p'' = 0.
  const std::vector<double> g = {l, 1.0, 0.0};
  const std::vector<double> m_inv_g = Multiply(free.m_inverse, g);
  double g_m_inv_g = 0.0;
  for (int i = 0; i < 3; ++i) g_m_inv_g += g[i] * m_inv_g[i];
  auto contact_force = [&](const std::vector<double>& y_full) {
    const std::vector<double> free_acc = free.Acceleration(y_full);
    double g_free = 0.0;
    for (int i = 0; i < 3; ++i) g_free += g[i] * free_acc[i];
    return g_free / g_m_inv_g;  // = -lambda
  };
  auto full_state = [&](const std::vector<double>& r) {  // (q2, q3, q2', q3') -> (p, p')
    return std::vector<double>{
        arm.wall_angle_rad + basis[0][0] * r[0], r[0], r[1], basis[0][0] * r[2], r[2], r[3]};
  };

  const double dt = 1.0 / sample_rate_hz, step = dt / kRk4StepsPerSample;
  const auto rows = static_cast<std::size_t>(std::llround(duration_s * sample_rate_hz));
  std::vector<double> y = {arm.start_angle_rad, 0, 0, 0, 0, 0};
  std::vector<double> r;               // after the impact
  double t_state = arm.start_delay_s;  // y holds the state at this time (at rest before)
  bool impacted = false;
  record.min_contact_force_n = std::numeric_limits<double>::infinity();
  auto gap = [&](const std::vector<double>& s) { return l * (s[0] - arm.wall_angle_rad) + s[1]; };

  double v1_before = 0.0, v2_before = 0.0;  // at the previous sample
  for (std::size_t i = 0; i < rows; ++i) {
    const double t = static_cast<double>(i) * dt;
    if (!impacted && t > t_state) {
      std::vector<double> next = free.Advance(y, t - t_state, step);
      if (gap(next) >= 0.0) {
        // Bisect the crossing inside (t_state, t].
        double lo = 0.0, hi = t - t_state;
        for (int it = 0; it < 200 && hi - lo > 1e-13; ++it) {
          const double mid = 0.5 * (lo + hi);
          (gap(free.Advance(y, mid, step)) >= 0.0 ? hi : lo) = mid;
        }
        std::vector<double> at = free.Advance(y, hi, step);
        record.impact_time_s = t_state + hi;
        record.impact_speed_m_s = l * at[3] + at[4];
        // Plastic impact: project the velocity onto G p' = 0.
        const double gv = l * at[3] + at[4];
        for (int k = 0; k < 3; ++k) at[3 + k] -= m_inv_g[k] * gv / g_m_inv_g;
        r = {at[1], at[2], at[4], at[5]};
        r = pinned.Advance(r, t - record.impact_time_s, step);
        t_state = t;
        impacted = true;
      } else {
        y = std::move(next);
        t_state = t;
      }
    } else if (impacted) {
      r = pinned.Advance(r, t - t_state, step);
      t_state = t;
    }
    const std::vector<double> full = impacted ? full_state(r) : y;
    if (impacted) {
      record.min_contact_force_n = std::min(record.min_contact_force_n, contact_force(full));
    }
    const double v1 = v1_of(full), v2 = v2_of(full);
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

BeamLogSummary GenerateBeamLogs(const fs::path& folder, const BeamLogOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("BeamLogOptions: " + error);
  }
  std::error_code ec;
  if (fs::exists(folder) && !fs::is_empty(folder, ec)) {
    throw InputError({folder, "", std::nullopt}, "the output folder exists and is not empty");
  }
  fs::create_directories(folder / "logs", ec);
  if (ec) throw InputError({folder / "logs", "", std::nullopt}, "cannot create the folder");

  const BeamArm experiment_arm = ExperimentArm(options);
  const BeamSensors& sensors = options.sensors;
  const BeamRecord sim =
      SimulateBeam(options.simulation, sensors, options.sample_rate_hz, options.duration_s);
  const BeamRecord exp =
      SimulateBeam(experiment_arm, sensors, options.sample_rate_hz, options.duration_s);

  const std::string id = options.log_id;
  const std::string experiment_file = fmt::format("logs/{}-experiment.csv", id);
  const std::string simulation_file = fmt::format("logs/{}-simulation.csv", id);
  const double counts_per_rad = sensors.counts_per_rev * sensors.gear_ratio / (2.0 * kPi);

  // The simulation: SI, clean.
  std::string text = "t,enc1,acc1,acc2\n";
  for (std::size_t i = 0; i < sim.time_s.size(); ++i) {
    text += fmt::format("{:.6f},{:.10g},{:.10g},{:.10g}\n", sim.time_s[i], sim.angle_rad[i],
                        sim.a1_m_s2[i], sim.a2_m_s2[i]);
  }
  WriteText(folder / simulation_file, text);

  // The experiment: counts and volts, noise, ADC steps, and optional defects.
  Gaussian noise(options.seed);
  auto volts = [&](double a, double sensitivity, double sigma) {
    const double v = a / kStandardGravity * sensitivity + options.noise_factor * sigma * noise();
    return std::round(v / sensors.adc_lsb_v) * sensors.adc_lsb_v;
  };
  nlohmann::json defects = nlohmann::json::array();
  const std::size_t rows = exp.time_s.size();
  const std::size_t nan_row = rows / 5, duplicate_row = 2 * rows / 5, missing_row = 3 * rows / 5;
  text = "t,enc1,acc1,acc2\n";
  long long line = 1;
  for (std::size_t i = 0; i < rows; ++i) {
    const auto counts = static_cast<long long>(std::floor(exp.angle_rad[i] * counts_per_rad));
    const double v1 = volts(exp.a1_m_s2[i], sensors.a1_sensitivity_v_per_g, sensors.a1_noise_v);
    const double v2 = volts(exp.a2_m_s2[i], sensors.a2_sensitivity_v_per_g, sensors.a2_noise_v);
    std::string row = fmt::format("{:.6f},{},{:.6f},{:.6f}\n", exp.time_s[i], counts, v1, v2);
    if (options.inject_defects && i == missing_row) {
      defects.push_back({{"kind", "missing sample"}, {"time_s", exp.time_s[i]}});
      continue;
    }
    if (options.inject_defects && i == nan_row) {
      row = fmt::format("{:.6f},{},nan,{:.6f}\n", exp.time_s[i], counts, v2);
      defects.push_back({{"kind", "NaN"}, {"line", line + 1}, {"column", "acc1"}});
    }
    text += row;
    ++line;
    if (options.inject_defects && i == duplicate_row) {
      text += row;
      ++line;
      defects.push_back({{"kind", "duplicated time"}, {"line", line}});
    }
  }
  WriteText(folder / experiment_file, text);

  WriteText(
      folder / "session.toml",
      fmt::format(R"toml(# Synthetic encoder and accelerometer logs: a flexible arm whose tip
# strikes a wall (impactlab synth-logs --seed {seed}; docs/logs.md). Truth is
# kept outside the folder.
format = 1
title = "Flexible arm striking a wall (synthetic logs, seed {seed})"
units = "SI"

[[log]]
id = "{id}"
experiment = "{experiment}"
simulation = "{simulation}"
time_column = "t"
[log.channels]
q1 = {{ column = "enc1", counts_per_rev = {cpr}, gear_ratio = {gear} }}
a1 = {{ column = "acc1", sensitivity = {s1} }}
a2 = {{ column = "acc2", sensitivity = {s2} }}
)toml",
                  fmt::arg("seed", options.seed), fmt::arg("id", id),
                  fmt::arg("experiment", experiment_file), fmt::arg("simulation", simulation_file),
                  fmt::arg("cpr", sensors.counts_per_rev), fmt::arg("gear", sensors.gear_ratio),
                  fmt::arg("s1", sensors.a1_sensitivity_v_per_g),
                  fmt::arg("s2", sensors.a2_sensitivity_v_per_g)));

  auto source_json = [&](const BeamRecord& record, const BeamArm& arm, const std::string& file) {
    nlohmann::json channels;
    const char* names[] = {"q1", "a1", "a2"};
    const char* units[] = {"rad", "m/s^2", "m/s^2"};
    for (int c = 0; c < 3; ++c) {
      // The dominant mode: the oscillating one with the most energy, A^2 / sigma.
      const auto& amplitudes = record.post_mode_amplitudes[static_cast<std::size_t>(c)];
      std::size_t dominant = 0;
      double most = -1.0;
      for (std::size_t m = 0; m < amplitudes.size(); ++m) {
        const double energy = amplitudes[m] * amplitudes[m] / record.post_modes[m].decay_rate_per_s;
        if (record.post_modes[m].frequency_hz > 0.0 && energy > most) {
          most = energy;
          dominant = m;
        }
      }
      channels[names[c]] = {{"units", units[c]},
                            {"post_impact_mode_amplitudes", amplitudes},
                            {"dominant_mode", dominant},
                            {"dominant_frequency_hz", record.post_modes[dominant].frequency_hz},
                            {"damping_ratio", record.post_modes[dominant].damping_ratio}};
    }
    return nlohmann::json{{"file", file},
                          {"impact_time_s", record.impact_time_s},
                          {"impact_speed_m_s", record.impact_speed_m_s},
                          {"min_contact_force_n", record.min_contact_force_n},
                          {"free_flight_modes", ModesJson(record.free_modes)},
                          {"post_impact_modes", ModesJson(record.post_modes)},
                          {"channels", channels},
                          {"arm", ArmJson(arm)}};
  };
  BeamLogSummary summary;
  summary.rows = static_cast<int>(rows);
  summary.experiment_impact_s = exp.impact_time_s;
  summary.simulation_impact_s = sim.impact_time_s;
  summary.truth = {{"schema", "impactlab-logs-truth"},
                   {"version", 1},
                   {"seed", options.seed},
                   {"log_id", id},
                   {"sample_rate_hz", options.sample_rate_hz},
                   {"duration_s", options.duration_s},
                   {"sensors",
                    {{"counts_per_rev", sensors.counts_per_rev},
                     {"gear_ratio", sensors.gear_ratio},
                     {"a1_sensitivity_v_per_g", sensors.a1_sensitivity_v_per_g},
                     {"a2_sensitivity_v_per_g", sensors.a2_sensitivity_v_per_g},
                     {"a1_noise_v", options.noise_factor * sensors.a1_noise_v},
                     {"a2_noise_v", options.noise_factor * sensors.a2_noise_v},
                     {"adc_lsb_v", sensors.adc_lsb_v},
                     {"a1_position", sensors.a1_position},
                     {"a2_inboard_m", sensors.a2_inboard_m}}},
                   {"experiment", source_json(exp, experiment_arm, experiment_file)},
                   {"simulation", source_json(sim, options.simulation, simulation_file)},
                   {"impact_offset_s", sim.impact_time_s - exp.impact_time_s},
                   {"defects", defects}};
  return summary;
}

}  // namespace impactlab
