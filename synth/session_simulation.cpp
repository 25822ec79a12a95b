#include "synth/session_simulation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace impactlab {
namespace {

// The contact circuit's levels, V, and the delayed sweep's window.
constexpr double kContactLowV = 0.05, kContactHighV = 2.45;
constexpr double kContactTimePerDiv = 50e-6;        // s/div
constexpr double kContactLeadS = 100e-6;            // the sweep starts this long before impact
constexpr double kContactWindowDiv = 10.5;          // the sweep's length, divisions
constexpr double kContactSampleIntervalS = 0.5e-6;  // a digital scope's sampling

// The 1-2-5 step at or above `raw`, as a scope's volts/div switch offers.
double NiceStep(double raw) {
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * decade >= raw * (1.0 - 1e-12)) return m * decade;
  }
  return 10.0 * decade;
}

// Volts/div and zero position that put the trace's volts inside the band.
TraceSettings FitToBand(const std::vector<double>& volts, const std::array<double, 2>& band,
                        double time_per_div, double t0_div) {
  const auto [v_lo, v_hi] = std::minmax_element(volts.begin(), volts.end());
  TraceSettings s;
  s.time_per_div = time_per_div;
  s.t0_div = t0_div;
  s.band_div = band;
  s.volts_per_div = NiceStep((*v_hi - *v_lo) / (0.85 * (band[1] - band[0])));
  s.zero_div = 0.5 * (band[0] + band[1]) - 0.5 * (*v_lo + *v_hi) / s.volts_per_div;
  return s;
}

// The cell's volts for the displacements, with its electronic noise.
std::vector<double> Noisy(const SimulatedPhotocell& cell, const std::vector<double>& x,
                          double noise_fraction, std::uint64_t seed) {
  const std::vector<double> v = cell.Volts(x);
  const double span = std::abs(cell.Volts(cell.x_hi()) - cell.Volts(cell.x_lo()));
  return AddGaussianNoise(v, noise_fraction * span, seed);
}

// Each bar released alone from its X0, the sweep triggered at the release.
SimulatedCalibration SimulateCalibration(const CalibrationPlan& plan,
                                         const SimulatedPhotocell& cell, double release_x,
                                         double noise_fraction) {
  CalibrationSweepOptions sweep_options;
  sweep_options.release_x = release_x;
  sweep_options.duration_s = 0.5;
  sweep_options.sample_rate_hz = 4000.0;
  CalibrationSweep sweep = MakeCalibrationSweep(cell, sweep_options);
  SimulatedCalibration calibration;
  calibration.release_x = release_x;
  calibration.trace.volts = Noisy(cell, sweep.x, noise_fraction, plan.noise_seed);
  calibration.trace.settings = FitToBand(calibration.trace.volts, plan.band_div, 0.05, 0.0);
  calibration.trace.time_s = std::move(sweep.time_s);
  return calibration;
}

// The fast delayed sweep on the second beam, from shortly before the shown
// impact; the contact circuit is high while the bars touch.
ScopeTrace ContactStep(const RunPlan& plan, const ImpactTruth& shown) {
  const double window_start = shown.start_time_s - kContactLeadS;
  const double window_end = window_start + kContactWindowDiv * kContactTimePerDiv;
  ScopeTrace contact;
  contact.time_s = {window_start,     shown.start_time_s, shown.start_time_s,
                    shown.end_time_s, shown.end_time_s,   window_end};
  contact.volts = {kContactLowV,  kContactLowV, kContactHighV,
                   kContactHighV, kContactLowV, kContactLowV};
  TraceSettings& s = contact.settings;
  s.time_per_div = kContactTimePerDiv;
  s.volts_per_div = 2.0;
  s.zero_div = -3.9;
  s.band_div = plan.bands.contact;
  s.t0_div = -window_start / s.time_per_div;
  s.impact = kSynthShownImpact;
  if (plan.contact_low_position) {
    // The step spans its drawn share of the band.
    const double height = plan.bands.contact[1] - plan.bands.contact[0];
    s.volts_per_div =
        NiceStep((kContactHighV - kContactLowV) / (plan.bands.contact_step_fraction * height));
    s.zero_div = plan.bands.contact[0] + *plan.contact_low_position * height -
                 kContactLowV / s.volts_per_div;
  }
  return contact;
}

Trace SampleContact(const ScopeTrace& step, const ImpactTruth& shown) {
  Trace samples;
  for (double t = step.time_s.front(); t < step.time_s.back(); t += kContactSampleIntervalS) {
    samples.time_s.push_back(t);
    const bool touching = t >= shown.start_time_s && t < shown.end_time_s;
    samples.volts.push_back(touching ? kContactHighV : kContactLowV);
  }
  return samples;
}

}  // namespace

SimulatedRun SimulateRun(const RunPlan& plan) {
  SimulatedRun run;
  run.experiment = SimulateExperiment(plan.experiment);
  const ExperimentResult& r = run.experiment;
  // The session's options are the user's: a run they do not let the model
  // simulate is outside its domain, and no session is made of it.
  if (!r.ok) throw std::domain_error(r.reason);
  run.initial_displacement = 0.5 * (r.right.release_x + r.left.release_x);
  run.right_cell = SimulatedPhotocell::FromSeed(plan.right_cell_seed, plan.photocells);
  run.left_cell = SimulatedPhotocell::FromSeed(plan.left_cell_seed, plan.photocells);
  run.shown_impact = r.impacts.at(kSynthShownImpact - 1);
  if (plan.form == RunForm::kTyped) return run;

  for (const CalibrationPlan& calibration : plan.calibrations) {
    const bool right = calibration.cell == "right";
    run.calibrations.push_back(
        SimulateCalibration(calibration, right ? run.right_cell : run.left_cell,
                            right ? r.right.release_x : r.left.release_x, plan.trace_noise));
  }

  // The slow sweep: 0.5 s/div from 0.1 s before the release, about six rebounds.
  std::vector<double> time = {-0.1}, xr = {r.right.release_x}, xl = {r.left.release_x};
  time.insert(time.end(), r.samples.time_s.begin(), r.samples.time_s.end());
  xr.insert(xr.end(), r.samples.x_right.begin(), r.samples.x_right.end());
  xl.insert(xl.end(), r.samples.x_left.begin(), r.samples.x_left.end());
  run.right.volts = Noisy(run.right_cell, xr, plan.trace_noise, plan.right_noise_seed);
  run.left.volts = Noisy(run.left_cell, xl, plan.trace_noise, plan.left_noise_seed);
  run.right.settings = FitToBand(run.right.volts, plan.bands.right, 0.5, 0.2);
  run.left.settings = FitToBand(run.left.volts, plan.bands.left, 0.5, 0.2);
  run.right.time_s = time;
  run.left.time_s = std::move(time);

  run.contact = ContactStep(plan, run.shown_impact);
  if (plan.form == RunForm::kCsv)
    run.contact_samples = SampleContact(run.contact, run.shown_impact);
  return run;
}

}  // namespace impactlab
