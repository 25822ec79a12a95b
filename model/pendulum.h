// The free motion of one pendulum between impacts (thesis eq. 3-7, 21-25).
//
// Displacements are horizontal, X = L sin(theta), positive away from the
// position of static equilibrium (P.O.E.). Two conventions:
//  - exact (default): theta'' + (g/L) sin(theta) = 0, amplitude-dependent half
//    period 2 sqrt(L/g) K(sin(theta_m/2)), energy U = M g L (1 - cos theta_m).
//  - thesis: PENDUL's small-angle model, X = L theta, tau_r = pi sqrt(L/g),
//    speed through equilibrium X0 sqrt(g/L); only the energy of a measured
//    rebound uses 1 - cos(X/L) (eq. 35). It reproduces the thesis's tables.
// Every 1 - cos(x) is evaluated as 2 sin^2(x/2): no cancellation for small x.
#pragma once

#include <optional>
#include <string>

namespace impactlab {

enum class PendulumConvention { kExact, kThesis };

struct Pendulum {
  double length = 0.0;   // L, length units
  double gravity = 0.0;  // g, length/s^2
  PendulumConvention convention = PendulumConvention::kExact;
};

// sqrt(g/L), rad/s: the small-angle natural frequency.
double NaturalFrequency(const Pendulum& pendulum);

// Swing angle theta_m of a swing whose horizontal amplitude is `xmax`:
// asin(X/L) (exact) or X/L (thesis). Throws std::domain_error unless 0 <= X < L.
double SwingAngle(const Pendulum& pendulum, double xmax);

// Why no swing has the amplitude `xmax` (SwingAngle's message), empty when
// 0 <= X < L: for callers whose maxima are data, to refuse them as a value.
std::string SwingAmplitudeProblem(const Pendulum& pendulum, double xmax);

// Speed through equilibrium of a swing that reaches `xmax`: exact
// 2 sqrt(gL) sin(theta_m/2); thesis X sqrt(g/L) (PENDUL's x0' = X0 sqrt(g/L)).
double SpeedFromAmplitude(const Pendulum& pendulum, double xmax);

// Speed through equilibrium from the potential energy at a measured maximum,
// U = M g L (1 - cos theta_m) (eq. 33): 2 sqrt(gL) sin(theta_m/2) in both
// conventions (theta_m = X/L in the thesis's).
double SpeedFromPeakEnergy(const Pendulum& pendulum, double xmax);

// Inverse of SpeedFromAmplitude: the horizontal amplitude a swing through
// equilibrium at `speed` reaches. Exact: X = 2 L k sqrt(1 - k^2), k = v / (2 sqrt(gL));
// throws std::domain_error if the swing would pass the horizontal (k >= 1/sqrt 2).
double AmplitudeFromSpeed(const Pendulum& pendulum, double speed);

// Why no swing through equilibrium at `speed` stays below the horizontal
// (AmplitudeFromSpeed's message), empty when one does.
std::string SwingSpeedProblem(const Pendulum& pendulum, double speed);

// Duration of one swing out and back (a rebound) of amplitude `xmax`:
// 2 sqrt(L/g) K(sin(theta_m/2)) (exact) or pi sqrt(L/g) (thesis).
double HalfPeriod(const Pendulum& pendulum, double xmax);

// HalfPeriod of a measured maximum, or nothing where the convention has no
// swing of that amplitude (exact: X < 0, X >= L or unread): where HalfPeriod
// throws std::domain_error, for callers whose maxima are data.
std::optional<double> HalfPeriodIfSwings(const Pendulum& pendulum, double xmax);

// X(t) of a pendulum released from rest at `release_x` at t = 0, for 0 <= t up
// to its first arrival at equilibrium (a quarter period).
double ReleaseSwingDisplacement(const Pendulum& pendulum, double release_x, double t);

// X(t) of a rebound that leaves equilibrium at `speed` at t = 0, for 0 <= t <=
// HalfPeriod (positive, back to 0 at the end).
double ReboundDisplacement(const Pendulum& pendulum, double speed, double t);

// X and dX/dt together.
struct SwingState {
  double displacement = 0.0;  // X, length units
  double velocity = 0.0;      // dX/dt, length units per second
};

// ReboundDisplacement and its time derivative, from one evaluation of the
// elliptic functions: a rebound's peak fit needs both at every sample.
// Exact: sin(theta/2) = k sn(w0 t), theta' = 2 k w0 cn(w0 t), X' = L cos(theta) theta'.
SwingState ReboundState(const Pendulum& pendulum, double speed, double t);

}  // namespace impactlab
