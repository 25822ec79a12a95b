#include "fit/kelvin_voigt_response.h"

#include "model/kelvin_voigt.h"

namespace impactlab {

std::vector<double> ModelPeakTimes(const Pendulum& pendulum, const FittedRun& run,
                                   const KelvinVoigtTwoPointFit& fit) {
  const int a = fit.rebounds_used[0];
  const double xa = run.xmax[a];
  const double tau_c = fit.contact_time.value_or(0.0);
  const double log_e = fit.log_restitution.value;
  double t = 0.5 * HalfPeriod(pendulum, run.initial_displacement);
  std::vector<double> peaks;
  // With first_rebound = 0 the release swing is rebound 0: its maximum is X0, at release.
  if (run.first_rebound == 0) peaks.push_back(0.0);
  const int last = static_cast<int>(run.xmax.size()) - 1;
  // PENDUL rebound N (N >= 1) is session rebound N - first_rebound.
  for (int n = 1 - run.first_rebound; n <= last; ++n) {
    const double duration = HalfPeriod(pendulum, PredictMaximum(pendulum, xa, a, n, log_e));
    t += tau_c;
    if (n >= 0) peaks.push_back(t + 0.5 * duration);
    t += duration;
  }
  return peaks;
}

// The fastest of the model's swings ModelPeakTimes asks for is the first,
// PENDUL rebound 1 (session rebound 1 - first_rebound): the model dissipates.
std::string ModelPeakTimesProblem(const Pendulum& pendulum, const FittedRun& run,
                                  const KelvinVoigtTwoPointFit& fit) {
  const int a = fit.rebounds_used[0];
  return PredictMaximumProblem(pendulum, run.xmax[a], a, 1 - run.first_rebound,
                               fit.log_restitution.value);
}

std::string ModelResponseProblem(const Pendulum& pendulum, const FittedRun& run,
                                 const KelvinVoigtTwoPointFit& fit) {
  const int a = fit.rebounds_used[0];
  return PredictMaximumProblem(pendulum, run.xmax[a], a, -run.first_rebound,
                               fit.log_restitution.value);
}

SampledHistory ModelResponse(const Pendulum& pendulum, double mass, const FittedRun& run,
                             const KelvinVoigtTwoPointFit& fit) {
  const int a = fit.rebounds_used[0];
  const double release =
      PredictMaximum(pendulum, run.xmax[a], a, -run.first_rebound, fit.log_restitution.value);
  const KelvinVoigtContactLaw law({mass, fit.stiffness->value, fit.damping->value}, fit.separation);
  const int rebounds = static_cast<int>(run.xmax.size()) + run.first_rebound - 1;
  const ReboundSequence sequence = SimulateRebounds(pendulum, law, release, rebounds);
  const double end = sequence.start_time.back() + sequence.duration.back();
  return SampleHistory(sequence, pendulum, law, end / 3000.0);
}

}  // namespace impactlab
