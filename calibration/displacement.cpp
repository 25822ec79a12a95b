#include "calibration/displacement.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace impactlab {

DisplacementHistory DisplacementFromVolts(const Trace& trace,
                                          const CalibrationResult& calibration) {
  if (trace.volts.empty()) throw std::invalid_argument("the trace has no samples");
  const PhotocellCurve& curve = calibration.curve;
  DisplacementHistory h;
  std::size_t dropped = 0;
  double v_lo = trace.volts.front(), v_hi = trace.volts.front();
  for (std::size_t i = 0; i < trace.volts.size(); ++i) {
    const double v = trace.volts[i];
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
    if (!curve.Covers(v)) {
      ++dropped;
      continue;
    }
    const double x = curve.DisplacementFromVolts(v);
    const double sigma_v =
        trace.sigma_volts.empty() ? calibration.residual_rms_volts : trace.sigma_volts[i];
    const double slope = std::abs(curve.SlopeAt(std::clamp(x, 0.0, curve.x_max())));
    h.time_s.push_back(trace.time_s[i]);
    h.displacement.push_back(x);
    h.sigma.push_back(std::hypot(curve.FitDisplacementSigma(v), sigma_v / slope));
  }
  if (dropped > trace.volts.size() / 50) {
    throw std::invalid_argument(fmt::format(
        "{} of {} samples ({:.4g} .. {:.4g} V) lie outside the calibrated range {:.4g} .. "
        "{:.4g} V: the calibration does not cover what this run needs",
        dropped, trace.volts.size(), v_lo, v_hi, curve.volts_min(), curve.volts_max()));
  }
  return h;
}

}  // namespace impactlab
