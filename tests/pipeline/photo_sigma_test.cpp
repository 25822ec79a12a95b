// A photo run's maxima carry the photo's mapping error whole: the share of
// the graticule's misfit at a point (a quarter of its residual, in volts
// through the trace's scale) is common to the samples round a peak, so a peak
// fit averages none of it away, and the maximum's sigma holds it through the
// cell curve's slope.
#include <algorithm>
#include <cmath>

#include <catch2/catch.hpp>

#include "calibration/photocell_calibration.h"
#include "io/manifest.h"
#include "pipeline/photo_traces.h"
#include "pipeline/reduce.h"
#include "pipeline/stage_options.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

TEST_CASE("photo_sigma: each bar's maxima hold the run photo's mapping error through the slope") {
  testing::TempDir dir;
  SynthOptions synth;
  synth.preset = "quick";
  synth.style = PhotoStyle::kPolaroid;
  synth.seed = 11;
  GenerateSession(dir.path() / "s", synth);
  const Session session = ReadManifest(dir.path() / "s").session;
  ReduceOptions options;
  options.products = Products::kRebounds;
  const SessionResult result = ReduceSession(session, options);
  int checked = 0;
  for (const Run& run : session.runs) {
    if (!run.photo) continue;
    const RunResult* reduced = result.FindRun(run.id);
    REQUIRE(reduced != nullptr);
    INFO("run " << run.id << ": " << reduced->Status());
    REQUIRE(reduced->ok);
    // The photo as the reduce read it, with the run's own settings.
    const StageOptions stage =
        EntryStageOptions(SessionStageOptions(StageOptions{}, session, {}), run.settings, {});
    std::map<std::string, TraceSettings> traces;
    for (const auto& [name, settings] : run.traces) traces[name] = settings;
    const DigitizedPhoto photo =
        DigitizeSessionPhoto(*run.photo, session, traces, stage.digitize, false);
    for (const CellCalibration& cal : reduced->measured.calibrations) {
      const std::optional<BarRebounds>& bar =
          cal.cell == "right" ? reduced->measured.right : reduced->measured.left;
      REQUIRE(bar.has_value());
      const double mapping = photo.mapping_sigma_volts.at(cal.cell);
      // A quarter of the graticule residual over the px per division, in volts.
      CHECK(mapping > 0.0);
      CHECK(mapping < 0.01 * std::abs(run.traces.at(cal.cell).volts_per_div));
      const PhotocellCurve curve(cal.release_x, cal.chebyshev, cal.chebyshev_covariance.values,
                                 0.0);
      for (std::size_t n = 0; n < bar->xmax.size(); ++n) {
        const double x = bar->xmax[n];
        const double slope = std::abs(curve.SlopeAt(std::clamp(x, 0.0, curve.x_max())));
        // Both shared errors, the curve's and the mapping's, are in the sigma whole.
        const double shared = std::hypot(curve.DisplacementSigmaAt(x), mapping / slope);
        CHECK(bar->xmax_sigma[n] >= shared * (1.0 - 1e-9));
        ++checked;
      }
    }
  }
  CHECK(checked >= 6);
}

}  // namespace
}  // namespace impactlab
