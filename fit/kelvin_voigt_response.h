// What a run's fitted Kelvin-Voigt model says about the run beyond its maxima:
// when each maximum falls, and the whole displacement history (thesis
// Figures 16-18, PENDUL option 2 with the fitted K and C).
#pragma once

#include <string>
#include <vector>

#include "fit/kelvin_voigt_two_point.h"
#include "model/pendulum.h"
#include "model/rebound_history.h"

namespace impactlab {

// The fitted run, as the model needs it: its maxima (session numbering), the
// release amplitude X0 and PENDUL's number of session rebound 0.
struct FittedRun {
  const std::vector<double>& xmax;
  double initial_displacement = 0.0;
  int first_rebound = 1;
};

// Times of the model's maxima since release, for a run whose maxima were
// typed in: a quarter swing from X0, then per impact tau_c and a swing of the
// model's amplitude (exact pendulum: durations depend on amplitude).
std::vector<double> ModelPeakTimes(const Pendulum& pendulum, const FittedRun& run,
                                   const KelvinVoigtTwoPointFit& fit);

// Why ModelPeakTimes has no times for the run (its model's first rebound
// from the release would swing past the horizontal), empty when it has.
std::string ModelPeakTimesProblem(const Pendulum& pendulum, const FittedRun& run,
                                  const KelvinVoigtTwoPointFit& fit);

// The fitted model's displacement history, released from the amplitude the
// fit extrapolates back to, sampled at 3000 points over its rebounds.
// `fit` must carry a stiffness and a damping (a contact time was given).
SampledHistory ModelResponse(const Pendulum& pendulum, double mass, const FittedRun& run,
                             const KelvinVoigtTwoPointFit& fit);

// Why ModelResponse has no history for the run (the release it extrapolates
// back to would be past the horizontal), empty when it has.
std::string ModelResponseProblem(const Pendulum& pendulum, const FittedRun& run,
                                 const KelvinVoigtTwoPointFit& fit);

}  // namespace impactlab
