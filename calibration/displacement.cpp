#include "calibration/displacement.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace impactlab {

DisplacementConversion DisplacementFromVolts(const Trace& trace,
                                             const CalibrationResult& calibration) {
  DisplacementConversion out;
  if (trace.volts.empty()) {
    out.reason = "the trace has no samples";
    return out;
  }
  const PhotocellCurve& curve = calibration.curve;
  DisplacementHistory& h = out.history;
  double v_lo = trace.volts.front(), v_hi = trace.volts.front();
  for (std::size_t i = 0; i < trace.volts.size(); ++i) {
    const double v = trace.volts[i];
    v_lo = std::min(v_lo, v);
    v_hi = std::max(v_hi, v);
    if (!curve.Covers(v)) {
      ++out.dropped;
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
  if (out.dropped > trace.volts.size() / 50) {
    out.reason = fmt::format(
        "{} of {} samples ({:.4g} .. {:.4g} V) lie outside the calibrated range {:.4g} .. "
        "{:.4g} V: the calibration does not cover what this run needs",
        out.dropped, trace.volts.size(), v_lo, v_hi, curve.volts_min(), curve.volts_max());
    return out;
  }
  out.ok = true;
  return out;
}

}  // namespace impactlab
