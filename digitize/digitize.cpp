// DigitizePhoto: the stages in order, timed; and the traces a manifest names.
#include <chrono>
#include <stdexcept>
#include <string>

#include "digitize/digitize.h"

namespace impactlab {

namespace {

double MillisecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

DigitizeResult DigitizePhoto(const Photo& photo, std::array<int, 2> divisions,
                             const std::vector<TraceRequest>& requests,
                             const DigitizeOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("digitize options: " + error);
  }
  DigitizeResult result;
  const PreparedPhoto prepared = PreparePhoto(photo, options.graticule);
  result.prepare_ms = prepared.prepare_ms;

  auto start = std::chrono::steady_clock::now();
  result.graticule = FindGraticule(prepared, divisions, options.graticule);
  result.graticule_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  result.traces = ExtractTraces(prepared, result.graticule, requests, options.traces);
  result.traces_ms = MillisecondsSince(start);

  start = std::chrono::steady_clock::now();
  for (const DigitizedTrace& trace : result.traces) {
    result.pulses.push_back(trace.settings.impact ? MeasurePulse(prepared, result.graticule, trace)
                                                  : std::nullopt);
  }
  result.pulse_ms = MillisecondsSince(start);
  return result;
}

std::string HintsUsed(const DigitizeResult& result) {
  std::string hints = result.graticule.from_corners_hint ? "graticule_corners" : "";
  for (const DigitizedTrace& trace : result.traces) {
    if (trace.from_points_hint) hints += (hints.empty() ? "" : ", ") + trace.name + ".points";
  }
  return hints;
}

std::vector<TraceRequest> TraceRequestsOf(const Run& run) {
  std::vector<TraceRequest> requests;
  for (const auto& [name, settings] : run.traces) {
    if (!settings.csv) requests.push_back({name, settings});
  }
  return requests;
}

std::vector<TraceRequest> TraceRequestsOf(const Calibration& calibration) {
  if (calibration.trace.csv) return {};
  return {{calibration.cell, calibration.trace}};
}

}  // namespace impactlab
