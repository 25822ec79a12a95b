#include "pipeline/two_link_fit_run.h"

#include <numbers>
#include <vector>

#include "multibody/two_link_channels.h"

namespace impactlab {

TwoLinkMeasurement TwoLinkMeasurementOfLog(const Log& log, const LogSeries& experiment) {
  TwoLinkMeasurement m;
  m.time_s = experiment.time_s;
  const double t0 = m.time_s.empty() ? 0.0 : m.time_s.front();
  for (double& t : m.time_s) t -= t0;
  for (std::size_t c = 0; c < log.channels.size(); ++c) {
    const LogChannel& channel = log.channels[c];
    const std::vector<double>& values = experiment.values[c];
    const double step = channel.counts_per_rev ? 2.0 * std::numbers::pi /
                                                     (*channel.counts_per_rev * channel.gear_ratio)
                                               : 0.0;
    if (channel.name == kTwoLinkEncoderAChannel) {
      m.q1_rad = values;
      m.encoder_a_step_rad = step;
    } else if (channel.name == kTwoLinkEncoderBChannel) {
      m.q4_rad = values;
      m.encoder_b_step_rad = step;
    }
    for (int a = 0; a < kTwoLinkAccelerometers; ++a) {
      if (channel.name == kTwoLinkAccelerometerChannels[a]) m.acceleration_m_s2[a] = values;
    }
  }
  return m;
}

TwoLinkFitRun FitTwoLinkToLog(const TwoLinkParameters& start, const Log& log,
                              const LogSeries& experiment, const TwoLinkFitOptions& options) {
  TwoLinkFitRun run;
  run.fit = FitTwoLinkSimulation(start, TwoLinkMeasurementOfLog(log, experiment), options);
  if (!run.fit.ok) {  // refused: nothing fitted to simulate
    run.fitted_simulation.ok = false;
    run.fitted_simulation.reason = "not simulated: " + run.fit.reason;
    return run;
  }
  const TwoLinkModel model(run.fit.fitted);
  run.fitted_simulation = SimulateTwoLink(model, run.fit.fitted.cases[options.case_number - 1], {});
  return run;
}

}  // namespace impactlab
