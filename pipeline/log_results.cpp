#include "pipeline/log_results.h"

#include <fmt/format.h>

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
  if (a.comparison) {
    const LogComparison& c = *a.comparison;
    out.impact_offset_s = c.impact_offset_s;
    // The instants the offset compares, which are the same channel's in both
    // sources where one found the impact in both.
    if (!c.impact_channel.empty()) {
      const SourceAnalysis* analysed[] = {&a.experiment, &*a.simulation};
      const std::optional<Estimate>* compared[] = {&c.experiment_impact_s, &c.simulation_impact_s};
      for (std::size_t k = 0; k < out.sources.size() && k < 2; ++k) {
        LogSourceResult& s = out.sources[k];
        s.impact_time_s = *compared[k];
        if (analysed[k]->impact.method == c.impact_channel) continue;
        s.impact_method = fmt::format(
            "{}, the channel compared; this source's strongest jump is {}'s, at {:.5f} s",
            c.impact_channel, analysed[k]->impact.method, analysed[k]->impact.time_s.value);
      }
    }
    for (const ChannelComparison& row : c.channels) {
      out.comparison.push_back({row.channel, row.units, row.experiment_frequency_hz,
                                row.simulation_frequency_hz, row.frequency_difference_hz,
                                row.frequency_difference_percent, row.rms_difference,
                                row.rms_difference_unaligned});
    }
  }
  return out;
}

}  // namespace impactlab
