// Dynamic photocell calibration (thesis Chapter III, program CALIBR; Figures
// 13-14), done with every sample instead of eleven hand-read points.
//
// One pendulum swings freely from X0, the sweep triggered at release. Over the
// first swing to the equilibrium crossing, every sample's voltage is paired
// with the ideal pendulum's displacement at its time (exact pendulum by
// default), and a smooth curve V(X) is fitted by least squares: a Chebyshev
// series on [0, X0] whose order the data choose (Bayesian information
// criterion). The noise is in the voltage, so V is regressed on X, not the
// reverse; the curve is then inverted. A curve that is not monotone over the
// swing is refused, unless a misread stretch of the trace (far off the curve
// through the rest) is why: then that stretch is left out and recorded. A
// conversion outside the calibrated voltages is refused.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "io/trace.h"
#include "model/pendulum.h"

namespace impactlab {

struct CalibrationOptions {
  int max_order = 9;  // highest polynomial order tried (1 = linear)
  // Samples closer than this to release are left out: the magnet releases
  // over a few milliseconds, s.
  double skip_after_release_s = 0.0;
  // Calibrated voltages may be extended by this fraction of their span when
  // converting (reading noise at the ends), 1.
  double range_margin = 0.01;

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("max_order", self.max_order, "highest polynomial order tried");
    visit("skip_after_release_s", self.skip_after_release_s, "samples left out after release, s");
    visit("range_margin", self.range_margin, "calibrated volts extended by this of the span, 1");
  }

  bool Check(std::string* error) const;
};

// X(V): the calibrated photocell, with its one-sigma band.
class PhotocellCurve {
 public:
  PhotocellCurve() = default;
  // `covariance`: the band's; `fit_covariance`: least squares' alone (empty:
  // the band's), which only weighs the samples converted (FitDisplacementSigma).
  PhotocellCurve(double x_max, std::vector<double> chebyshev, std::vector<double> covariance,
                 double range_margin, std::vector<double> fit_covariance = {});

  // V at displacement x (0 <= x <= x_max), and dV/dX.
  double VoltsAt(double x) const;
  double SlopeAt(double x) const;
  // The displacement at which the cell reads `volts`. Throws std::domain_error
  // outside the calibrated voltages (with the margin).
  double DisplacementFromVolts(double volts) const;
  // One-sigma uncertainty of DisplacementFromVolts from the curve alone.
  double DisplacementSigma(double volts) const;
  // The same at displacement x (0 <= x <= x_max): the curve's error there,
  // shared by every sample that reads near x (a rebound's maximum carries it
  // whole, however many samples its fit averages).
  double DisplacementSigmaAt(double x) const;
  // The same from least squares' covariance alone (inflated for the
  // residuals' correlation), without what the band adds for the curve's
  // dependence on single stretches and for errors every sample shares: a
  // converted sample's weight in the fits that read it (displacement.h), as
  // before the band was widened, so that widening it moves no measurement.
  double FitDisplacementSigma(double volts) const;
  bool Covers(double volts) const;

  double x_max() const { return x_max_; }
  double volts_min() const { return volts_min_; }
  double volts_max() const { return volts_max_; }
  int order() const { return static_cast<int>(chebyshev_.size()) - 1; }
  const std::vector<double>& chebyshev() const { return chebyshev_; }    // in u = 2X/x_max - 1
  const std::vector<double>& covariance() const { return covariance_; }  // row-major, V^2
  bool falling() const { return falling_; }                              // V falls as X grows

 private:
  double x_max_ = 0.0;
  std::vector<double> chebyshev_;
  std::vector<double> covariance_;      // row-major, (order+1)^2, V^2
  std::vector<double> fit_covariance_;  // the same shape; least squares' alone
  double SigmaAt(const std::vector<double>& covariance, double x_in) const;
  double volts_min_ = 0.0, volts_max_ = 0.0, margin_volts_ = 0.0;
  bool falling_ = true;
};

struct CalibrationResult {
  // Whether a curve was fitted; otherwise `reason` says why (too few samples
  // in the first swing, a cell that is not monotone, with where) and the
  // rest is unset.
  bool ok = false;
  std::string reason;
  PhotocellCurve curve;
  // The pairs the fit used (Figure 14's points) and their residuals.
  std::vector<double> time_s, ideal_displacement, volts, residual_volts;
  double residual_rms_volts = 0.0;
  double residual_rms_length = 0.0;  // the same, through the curve's slope
  int samples_used = 0;
  // Stretches of the first swing left out as misread ([from, to], s since
  // release): where no monotone curve fits every sample, the runs of samples
  // far off the curve through the rest (a tracking that followed a mark or a
  // scratch), when they are few. Empty otherwise.
  std::vector<std::array<double, 2>> left_out_s;
  std::vector<double> bic;  // per order tried, from 1
  // The factor the coefficient covariance was multiplied by because the
  // residuals are correlated along the trace (1 + 2 sum of their positive
  // autocorrelations; 1 for independent noise).
  double correlation_inflation = 1.0;
};

// A trace that cannot be calibrated is a result with `ok` false and the
// reason. Throws std::invalid_argument only for options that fail their
// Check (a caller's mistake).
// The curve's band (its covariance) is least squares' (inflated for the
// residuals' correlation), widened where the curve depends on one stretch of
// the trace more than that says (curve_band.h), plus `shared_sigma_volts`:
// an error every sample of the trace shares, which no fit can see (a
// digitized photo's mapping, a quarter of its graticule residual; 0 for a CSV).
CalibrationResult CalibratePhotocell(const Trace& trace, const Pendulum& pendulum, double release_x,
                                     const CalibrationOptions& options,
                                     double shared_sigma_volts = 0.0);

}  // namespace impactlab
