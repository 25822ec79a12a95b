// The two log files of a `synth-logs` session (docs/logs.md): the simulation's
// in SI, the experiment's in encoder counts and volts, both as CSV with the
// columns t, enc1, acc1, acc2 (the manifest's channels name them).
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "synth/beam_simulation.h"

namespace impactlab {

// The columns, as the manifest's [log.channels] name them.
inline constexpr const char* kBeamLogTimeColumn = "t";
inline constexpr const char* kBeamLogEncoderColumn = "enc1";
inline constexpr const char* kBeamLogA1Column = "acc1";
inline constexpr const char* kBeamLogA2Column = "acc2";

// Time to 6 decimals, angle (rad) and accelerations (m/s^2) to 10 significant
// digits. Throws InputError when the file cannot be written.
void WriteSimulationLog(const std::filesystem::path& file, const BeamRecord& record);

// Time and volts to 6 decimals, whole counts. With `inject_defects`, the row a
// fifth of the way in has NaN for acc1, the row two fifths in is written twice
// and the row three fifths in is left out. Returns the defects as written (the
// truth's "defects": {"kind", "line", "column"}, {"kind", "line"} or {"kind",
// "time_s"}). Throws InputError when the file cannot be written.
nlohmann::json WriteExperimentLog(const std::filesystem::path& file, const LoggedSamples& samples,
                                  bool inject_defects);

}  // namespace impactlab
