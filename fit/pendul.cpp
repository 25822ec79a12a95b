#include "fit/pendul.h"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab {

PendulResponse PendulResponseFor(const Pendulum& pendulum, const KelvinVoigt& parameters,
                                 Separation separation, double release_x, int rebound_count) {
  const KelvinVoigtContactLaw law(parameters, separation);
  PendulResponse out;
  out.parameters = parameters;
  out.damping_ratio = RatesOf(parameters).damping_ratio;
  out.sequence = SimulateRebounds(pendulum, law, release_x, rebound_count);
  out.contact = out.sequence.contact;
  const double first_amplitude = rebound_count > 0 ? out.sequence.xmax[1] : out.sequence.xmax[0];
  out.rebound_time = HalfPeriod(pendulum, first_amplitude);
  return out;
}

PendulFit PendulFromMeasurements(const Pendulum& pendulum, double mass,
                                 const ReboundMeasurements& measured,
                                 const TwoPointOptions& options, int rebound_count) {
  if (!measured.contact_time) {
    throw std::invalid_argument("PENDUL option 1 needs the contact time tau_c");
  }
  // PENDUL's maxima are typed in by hand: one that is not a positive number
  // is a mistyped argument, not data the model refuses.
  for (std::size_t n = 0; n < measured.xmax.size(); ++n) {
    if (!(measured.xmax[n] > 0.0) || !std::isfinite(measured.xmax[n])) {
      throw std::invalid_argument(
          fmt::format("rebound {} maximum must be a positive number, got {}", n, measured.xmax[n]));
    }
  }
  PendulFit out;
  out.fit = FitKelvinVoigtTwoPoint(pendulum, mass, measured, options);
  if (!out.fit.ok) throw std::domain_error(out.fit.reason);
  const KelvinVoigt parameters{mass, out.fit.stiffness->value, out.fit.damping->value};
  out.response = PendulResponseFor(pendulum, parameters, options.separation,
                                   out.fit.predicted_xmax.front().value, rebound_count);
  return out;
}

std::vector<PendulResponse> PendulPredict(const Pendulum& pendulum, const PendulFit& fitted,
                                          const std::vector<double>& release_x, int rebound_count) {
  std::vector<PendulResponse> out;
  for (double x0 : release_x) {
    out.push_back(PendulResponseFor(pendulum, fitted.response.parameters, fitted.fit.separation, x0,
                                    rebound_count));
  }
  return out;
}

}  // namespace impactlab
