// Generated photo sessions, end to end: `reduce` on the generator's photos
// (every style, mixed with a CSV-trace run and a typed-in run) recovers the
// generator's rebound maxima and contact times; a broken photo fails its own
// run only.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "report/html_report.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

struct Errors {
  std::vector<double> xmax_pct_x0;  // |measured - true| / X0, %, every rebound of every run
  std::vector<double> contact_pct;  // |measured - true| / true, %, every run with a pulse
  int photo_runs = 0, ok_runs = 0;
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double Worst(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }

// A quick generated session (two photo runs, 1000 px) in `folder`.
SynthSummary GenerateQuick(const std::filesystem::path& folder, PhotoStyle style,
                           std::uint64_t seed, bool mixed) {
  SynthOptions synth;
  synth.preset = "quick";
  synth.style = style;
  synth.seed = seed;
  synth.csv_run = mixed;
  synth.typed_run = mixed;
  return GenerateSession(folder, synth);
}

// Reduces a quick generated session of `style`, mixed with a CSV-trace run and
// a typed-in run, and compares it with the truth.
Errors ReduceGenerated(PhotoStyle style, std::uint64_t seed) {
  testing::TempDir dir;
  const SynthSummary summary = GenerateQuick(dir.path() / "s", style, seed, true);
  ReduceOptions options;
  options.jobs = 2;
  const SessionResult result = ReduceSession(ReadManifest(dir.path() / "s").session, options);

  Errors errors;
  for (const auto& truth : summary.truth["runs"]) {
    const RunResult* run = result.FindRun(truth["id"]);
    REQUIRE(run != nullptr);
    INFO("run " << run->id << ": " << run->Status());
    REQUIRE(run->ok);
    if (truth["form"] == "typed-in") continue;  // rounded to 0.001 by design
    errors.photo_runs += truth["form"] == "photo";
    const double x0 = truth["initial_displacement"];
    const auto& xmax = truth["rebounds"]["xmax"];
    CHECK(run->measured.xmax.size() >= 3);
    for (std::size_t n = 0; n < run->measured.xmax.size() && n < xmax.size(); ++n) {
      errors.xmax_pct_x0.push_back(100.0 * std::abs(run->measured.xmax[n] - xmax[n].get<double>()) /
                                   x0);
    }
    if (run->measured.contact_time) {
      const double tau = truth["contact"]["duration_s"];
      errors.contact_pct.push_back(100.0 * std::abs(*run->measured.contact_time - tau) / tau);
    }
  }
  return errors;
}

// The quick preset's photos are 1000 px wide (lowres 500 px), half the
// thesis preset's, so a pixel's error weighs twice as much; the tolerances
// leave 1.4 to 2.6 times the errors this seed gives (the contact time's worst
// is often the CSV run's, measured on its samples). bench_reduce measures the
// thesis preset against the benchmark's targets (docs/benchmarks.md).
void CheckStyle(PhotoStyle style, double xmax_median, double xmax_worst, double contact_worst) {
  const Errors e = ReduceGenerated(style, 11);
  CHECK(e.photo_runs >= 2);
  REQUIRE(!e.xmax_pct_x0.empty());
  REQUIRE(!e.contact_pct.empty());
  CHECK(Median(e.xmax_pct_x0) < xmax_median);
  CHECK(Worst(e.xmax_pct_x0) < xmax_worst);
  CHECK(Worst(e.contact_pct) < contact_worst);
}

TEST_CASE("photo_session: clean photos reduce to the generator's maxima and contact time") {
  CheckStyle(PhotoStyle::kClean, 0.08, 0.2, 0.15);
}

TEST_CASE("photo_session: polaroid photos reduce to the generator's maxima and contact time") {
  CheckStyle(PhotoStyle::kPolaroid, 0.08, 0.3, 0.6);
}

TEST_CASE("photo_session: phone photos reduce to the generator's maxima and contact time") {
  CheckStyle(PhotoStyle::kPhone, 0.08, 0.4, 0.2);
}

TEST_CASE("photo_session: negative photos reduce to the generator's maxima and contact time") {
  CheckStyle(PhotoStyle::kNegative, 0.08, 0.2, 0.15);
}

TEST_CASE("photo_session: low-resolution photos reduce to the generator's maxima and contact") {
  CheckStyle(PhotoStyle::kLowres, 0.1, 0.4, 1.2);
}

TEST_CASE("photo_session: a broken photo fails its own run, naming the file, and the rest reduce") {
  testing::TempDir dir;
  GenerateQuick(dir.path() / "s", PhotoStyle::kClean, 5, true);
  const Session session = ReadManifest(dir.path() / "s").session;
  const Run& victim = *std::find_if(session.runs.begin(), session.runs.end(),
                                    [](const Run& r) { return r.photo.has_value(); });
  {
    // A transfer cut short: the photo's first bytes, then nothing.
    std::ifstream in(*victim.photo, std::ios::binary);
    std::string head(512, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    in.close();
    std::ofstream(*victim.photo, std::ios::binary | std::ios::trunc) << head;
  }
  const SessionResult result = ReduceSession(session, {});
  int ok = 0;
  for (const RunResult& run : result.runs) {
    if (run.id == victim.id) {
      CHECK_FALSE(run.ok);
      CHECK_THAT(run.reason, Catch::Contains(victim.photo->filename().string()));
    } else {
      CHECK(run.ok);
      ok += run.ok;
    }
  }
  CHECK(ok == static_cast<int>(result.runs.size()) - 1);
  CHECK(ok >= 2);
}

TEST_CASE(
    "photo_session: a run that fails after its photo was digitized keeps the photo's overlay") {
  testing::TempDir dir;
  GenerateQuick(dir.path() / "s", PhotoStyle::kClean, 4, false);
  const Session session = ReadManifest(dir.path() / "s").session;
  const Run& victim = *std::find_if(session.runs.begin(), session.runs.end(),
                                    [](const Run& r) { return r.photo.has_value(); });
  // Its right cell's calibration photo cut short: the run's own photo is
  // digitized first, then the calibration fails.
  const auto& calibration =
      *std::find_if(session.calibrations.begin(), session.calibrations.end(),
                    [&](const Calibration& c) { return c.id == victim.calibration.at("right"); });
  std::ofstream(*calibration.photo, std::ios::binary | std::ios::trunc) << "not a photo";
  const SessionResult result = ReduceSession(session, {});
  const RunResult& failed = *result.FindRun(victim.id);
  REQUIRE_FALSE(failed.ok);
  CHECK_THAT(failed.reason, Catch::Contains(calibration.photo->filename().string()));
  // The run's own photo, digitized, stays with the reason: in the results
  // file and on the report's page.
  REQUIRE(failed.measured.overlays.size() == 1);
  CHECK(failed.measured.overlays[0].jpeg.size() > 1000);
  WriteResults(result, dir.path() / "r.h5");
  const SessionResult read = ReadResults(dir.path() / "r.h5");
  REQUIRE(read.FindRun(victim.id)->measured.overlays.size() == 1);
  const std::string html = RenderHtmlReport(read);
  const std::size_t section = html.find("<h2 id=\"run-" + victim.id + "\">");
  REQUIRE(section != std::string::npos);
  CHECK(html.find(read.FindRun(victim.id)->measured.overlays[0].photo, section) !=
        std::string::npos);
}

TEST_CASE("photo_session: every photo's overlay, calibrations' too, reaches the HTML report") {
  testing::TempDir dir;
  GenerateQuick(dir.path() / "s", PhotoStyle::kPhone, 4, false);
  const Session session = ReadManifest(dir.path() / "s").session;
  WriteResults(ReduceSession(session, {}), dir.path() / "r.h5");
  const SessionResult read = ReadResults(dir.path() / "r.h5");
  const std::string html = RenderHtmlReport(read);
  int calibration_overlays = 0, spreads_measured = 0;
  for (const RunResult& run : read.runs) {
    REQUIRE(run.ok);
    REQUIRE(run.measured.overlays.size() == 1);
    // The displacement traces' spread, kept with its sigma where measured; the
    // contact pulse's levels never write fast enough to measure one.
    const PhotoOverlay& o = run.measured.overlays[0];
    REQUIRE(o.trace_spread_px2.size() == o.trace_names.size());
    REQUIRE(o.trace_spread_sigma_px2.size() == o.trace_names.size());
    for (std::size_t i = 0; i < o.trace_names.size(); ++i) {
      INFO(o.trace_names[i] << ": " << o.trace_spread_px2[i] << " +- "
                            << o.trace_spread_sigma_px2[i] << " px^2");
      if (o.trace_names[i] == "contact") {
        CHECK(o.trace_spread_px2[i] == 0.0);
      } else if (o.trace_spread_px2[i] > 0.0) {
        ++spreads_measured;
        CHECK(o.trace_spread_px2[i] < 10.0);
        CHECK(o.trace_spread_sigma_px2[i] > 0.0);
        CHECK(o.trace_spread_sigma_px2[i] < 0.5 * o.trace_spread_px2[i]);
      }
    }
    for (const CellCalibration& c : run.measured.calibrations) {
      REQUIRE(c.overlay);
      CHECK(c.overlay->jpeg.size() > 1000);
      CHECK_THAT(html, Catch::Contains(c.overlay->photo));
      ++calibration_overlays;
    }
  }
  CHECK(calibration_overlays == 2 * static_cast<int>(read.runs.size()));
  CHECK_THAT(html, Catch::Contains("Calibration photos, digitized"));
  // Most slow traces measure it (all but one of four here), and the report says so.
  CHECK(spreads_measured >= static_cast<int>(read.runs.size()));
  CHECK_THAT(html, Catch::Contains("spread whose pull inside curves was undone"));
}

}  // namespace
}  // namespace impactlab
