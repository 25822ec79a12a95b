#include "pipeline/log_results.h"

#include "signal/log_analysis.h"

namespace impactlab {
namespace {

// The source's channels are moved out of `s`, kept as the analysis returned them.
LogSourceResult SummariseSource(SourceAnalysis& s, const char* name) {
  LogSourceResult out;
  out.source = name;
  if (s.impact.found) {
    out.impact_time_s = s.impact.time_s;
    out.impact_method = s.impact.method;
  } else {
    out.impact_method = s.impact.reason;
  }
  out.channels = std::move(s.channels);
  return out;
}

}  // namespace

const SegmentSpectrum* KeptSpectrum(const ChannelAnalysis& c) {
  for (const char* segment : {"post_impact", "whole"}) {
    for (const SegmentSpectrum& s : c.spectra) {
      if (s.segment == segment && !s.spectrum.frequency_hz.empty()) return &s;
    }
  }
  return nullptr;
}

LogResult ReduceLog(const Log& log, const LogAnalysisOptions& options) {
  LogAnalysis a = AnalyseLog(log, LogFileRecords(log, options.read), options);
  LogResult out;
  out.id = a.log_id;
  out.ok = a.ok;
  out.reason = a.reason;
  if (!a.ok) return out;
  out.sources.push_back(SummariseSource(a.experiment, "experiment"));
  if (a.simulation) out.sources.push_back(SummariseSource(*a.simulation, "simulation"));
  out.comparison = std::move(a.comparison);
  return out;
}

}  // namespace impactlab
