// The manipulator's small-vibration modes about a state (docs/two-link.md,
// "Modes"): the eigenvalues of the equations of motion linearised there, in
// free flight (16 states) or with the tip on the surface (14: the dependent
// coordinate and its speed follow from the loop closure). The Jacobian is by
// central differences of the exact right-hand side; the drives' voltages are
// held at the state's values. The constrained modes are what the logs'
// post-impact ring-down shows.
#pragma once

#include <vector>

#include "multibody/two_link_model.h"

namespace impactlab {

struct VibrationMode {
  double frequency_hz = 0.0;   // damped, Im(s) / 2 pi; 0 for a real pole
  double damping_ratio = 0.0;  // -Re(s) / |s|
  double decay_rate_per_s = 0.0;
};

// Oscillatory modes (Im s > 0) by frequency, then real poles; rigid-body
// zero eigenvalues (|s| below 1e-6 of the largest) are left out. Throws
// std::domain_error when the loop closure fails.
std::vector<VibrationMode> LinearisedModes(const TwoLinkModel& model, const TwoLinkVector& q,
                                           const TwoLinkVector& v, const DriveVoltages& voltages,
                                           bool constrained);

}  // namespace impactlab
