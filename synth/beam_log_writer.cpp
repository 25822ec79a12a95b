#include "synth/beam_log_writer.h"

#include <fstream>
#include <iterator>

#include <fmt/format.h>

#include "io/errors.h"
#include "synth/log_file_internal.h"

namespace impactlab {
namespace {

std::ofstream OpenLog(const std::filesystem::path& file) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw InputError({file, "", std::nullopt}, "cannot write the file");
  fmt::format_to(std::ostreambuf_iterator<char>(out), "{},{},{},{}\n", kBeamLogTimeColumn,
                 kBeamLogEncoderColumn, kBeamLogA1Column, kBeamLogA2Column);
  return out;
}

}  // namespace

void WriteSimulationLog(const std::filesystem::path& file, const BeamRecord& record) {
  std::ofstream out = OpenLog(file);
  for (std::size_t i = 0; i < record.time_s.size(); ++i) {
    fmt::format_to(std::ostreambuf_iterator<char>(out), "{:.6f},{:.10g},{:.10g},{:.10g}\n",
                   record.time_s[i], record.angle_rad[i], record.a1_m_s2[i], record.a2_m_s2[i]);
  }
  synth_detail::CloseLog(out, file);
}

nlohmann::json WriteExperimentLog(const std::filesystem::path& file, const LoggedSamples& samples,
                                  bool inject_defects) {
  std::ofstream out = OpenLog(file);
  nlohmann::json defects = nlohmann::json::array();
  const std::size_t rows = samples.time_s.size();
  const std::size_t nan_row = rows / 5, duplicate_row = 2 * rows / 5, missing_row = 3 * rows / 5;
  long long line = 1;  // the header
  for (std::size_t i = 0; i < rows; ++i) {
    const double t = samples.time_s[i];
    std::string row = fmt::format("{:.6f},{},{:.6f},{:.6f}\n", t, samples.encoder_counts[i],
                                  samples.a1_v[i], samples.a2_v[i]);
    if (inject_defects && i == missing_row) {
      defects.push_back({{"kind", "missing sample"}, {"time_s", t}});
      continue;
    }
    if (inject_defects && i == nan_row) {
      row = fmt::format("{:.6f},{},nan,{:.6f}\n", t, samples.encoder_counts[i], samples.a2_v[i]);
      defects.push_back({{"kind", "NaN"}, {"line", line + 1}, {"column", kBeamLogA1Column}});
    }
    out << row;
    ++line;
    if (inject_defects && i == duplicate_row) {
      out << row;
      ++line;
      defects.push_back({{"kind", "duplicated time"}, {"line", line}});
    }
  }
  synth_detail::CloseLog(out, file);
  return defects;
}

}  // namespace impactlab
