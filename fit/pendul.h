// PENDUL's three options (thesis Chapter IV, Appendix E) as library calls.
//
//  1. Kelvin-Voigt K, C, zeta and tau_r from measured maxima and tau_c, and the
//     response through the measured pair;
//  2. the response and tau_c, tau_r from given K, C;
//  3. parameters from one run predict the response to new initial displacements.
// List index = PENDUL's rebound number: the response starts from rebound 0.
#pragma once

#include <vector>

#include "fit/kelvin_voigt_two_point.h"
#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"

namespace impactlab {

struct PendulResponse {
  KelvinVoigt parameters;
  double damping_ratio = 0.0;
  ContactResponse contact;    // tau_c, e
  double rebound_time = 0.0;  // tau_r of the first rebound, s (amplitude-dependent when exact)
  ReboundSequence sequence;   // amplitudes and times of every rebound
};

// Option 2: the response to a release from `release_x`.
PendulResponse PendulResponseFor(const Pendulum& pendulum, const KelvinVoigt& parameters,
                                 Separation separation, double release_x, int rebound_count);

struct PendulFit {
  KelvinVoigtTwoPointFit fit;
  PendulResponse response;  // released from the fit's rebound 0, so it passes through the pair
};

// Option 1. Needs the contact time and positive maxima (typed in by hand);
// throws std::invalid_argument without them, and std::domain_error with the
// fit's reason when the fit refuses the maxima (a pair without dissipation,
// one past the horizontal).
PendulFit PendulFromMeasurements(const Pendulum& pendulum, double mass,
                                 const ReboundMeasurements& measured,
                                 const TwoPointOptions& options, int rebound_count);

// Option 3: option 1's parameters, one response per new release displacement.
std::vector<PendulResponse> PendulPredict(const Pendulum& pendulum, const PendulFit& fitted,
                                          const std::vector<double>& release_x, int rebound_count);

}  // namespace impactlab
