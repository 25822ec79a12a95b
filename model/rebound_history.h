// Impacting penduli: free swings joined by impacts (thesis eq. 20-30, Figure 6).
//
// Numbering follows the thesis's Figure 6 (PENDUL): rebound 0 is the release
// swing from X0, impact N precedes rebound N (N = 1, 2, ...). Each impact keeps
// the fraction e of the speed through equilibrium; the rebound amplitudes then
// follow from the pendulum (exact or thesis convention). Peaks are exact: a
// rebound's maximum is its amplitude, reached at half its duration.
// Session numbering (Figure 15, `first_rebound`) is applied by the caller.
#pragma once

#include <vector>

#include "model/contact.h"
#include "model/pendulum.h"

namespace impactlab {

struct ReboundSequence {
  // Index N = 0, 1, ..., count: amplitude and timing of rebound N.
  std::vector<double> xmax;        // X_N max, length units (xmax[0] = X0)
  std::vector<double> peak_time;   // time of X_N max since release, s
  std::vector<double> start_time;  // rebound N leaves equilibrium (N >= 1); 0 for N = 0
  std::vector<double> duration;    // rebound N's swing out and back, s (N = 0: quarter swing)
  // Index N - 1 for impact N = 1, ..., count.
  std::vector<double> impact_time;   // impact N begins, s since release
  std::vector<double> impact_speed;  // speed through equilibrium into impact N
  std::vector<double> exit_speed;    // speed through equilibrium out of impact N
  ContactResponse contact;           // tau_c, e (the same for every impact of a linear law)
};

// Amplitudes and times of `rebound_count` rebounds after release from
// `release_x` at t = 0. A rebound whose speed would carry the pendulum past
// the horizontal throws std::domain_error.
ReboundSequence SimulateRebounds(const Pendulum& pendulum, const ContactLaw& contact,
                                 double release_x, int rebound_count);

// X(t) of that history at any t >= 0: the release swing, -x(t') during each
// impact (compression, thesis eq. 20), rebounds in between, and 0 after the
// last simulated rebound. Under force separation the residual compression at
// separation (a few microinches for steel) is not carried into the rebound.
double HistoryDisplacement(const ReboundSequence& sequence, const Pendulum& pendulum,
                           const ContactLaw& contact, double t);

struct SampledHistory {
  std::vector<double> time;          // s
  std::vector<double> displacement;  // length units
};

// The history sampled every `time_step` from 0 through the end of the last rebound.
SampledHistory SampleHistory(const ReboundSequence& sequence, const Pendulum& pendulum,
                             const ContactLaw& contact, double time_step);

}  // namespace impactlab
