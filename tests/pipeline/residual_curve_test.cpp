// The residual panel's values are the results' own: the measured
// displacement less the fitted model's response, made by the pipeline and
// kept in the results file, so the report draws them and computes nothing.
#include <algorithm>
#include <filesystem>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

TEST_CASE("residual curve: measured less the model, interpolated, within the model's span") {
  const Curve model{{0.0, 0.5, 1.0}, {0.0, 1.0, 2.0}};  // 2 t
  const Curve measured{{-0.1, 0.25, 0.75, 1.0, 1.2}, {1.0, 1.0, 1.0, 1.0, 1.0}};
  const Curve residual = ResidualCurve(measured, model);
  REQUIRE(residual.time_s == std::vector<double>{0.25, 0.75, 1.0});
  CHECK(residual.value[0] == Approx(0.5));
  CHECK(residual.value[1] == Approx(-0.5));
  CHECK(residual.value[2] == Approx(-1.0));
  CHECK(ResidualCurve(measured, Curve{{0.0}, {0.0}}).time_s.empty());  // no span to read
}

TEST_CASE("residual curve: a reduced run keeps its residual history, and the file keeps it") {
  testing::TempDir dir;
  SynthOptions synth;
  synth.preset = "quick";
  synth.csv_run = true;
  GenerateSession(dir.path() / "session", synth);
  const SessionResult result = ReduceSession(ReadManifest(dir.path() / "session").session, {});
  const auto file = dir.path() / "results.h5";
  WriteResults(result, file);
  const SessionResult read = ReadResults(file);
  int runs_with_residual = 0;
  for (const RunResult& run : result.runs) {
    if (run.fits.model_response.time_s.empty()) continue;
    const Curve& residual = run.fits.model_residual;
    REQUIRE_FALSE(residual.time_s.empty());
    // At the measured displacement's own times, within the response's span.
    const std::vector<double>& measured = run.measured.measured_displacement.time_s;
    CHECK(std::includes(measured.begin(), measured.end(), residual.time_s.begin(),
                        residual.time_s.end()));
    CHECK(residual.time_s.front() >= run.fits.model_response.time_s.front());
    CHECK(residual.time_s.back() <= run.fits.model_response.time_s.back());
    const RunResult* back = read.FindRun(run.id);
    REQUIRE(back != nullptr);
    CHECK(back->fits.model_residual.time_s == residual.time_s);
    CHECK(back->fits.model_residual.value == residual.value);
    ++runs_with_residual;
  }
  CHECK(runs_with_residual > 0);
}

}  // namespace
}  // namespace impactlab
