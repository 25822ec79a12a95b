// A small randomised sample through the whole reduction, against the
// generator's truth: the share of photo runs that reduce and the error of
// every maximum they report. bench_robustness measures the same over hundreds
// of photos, per factor of their look (docs/benchmarks.md, "Robustness").
#include <cmath>
#include <string>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "synth/session_generator.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

// The thresholds are what the tool achieved when this test was written, at
// commit 62226ea: 2 of the 16 photo runs reduced, their maxima at most 0.22 %
// of X0 off. The digitizer is being improved in parallel (issue 15), so raise
// them as it gets better; they are a floor against regressions, not targets
// (issue 15's target is 99 % of photos reduced, maxima within 0.15 % p95).
constexpr double kMinShareReduced = 0.18;   // of the sample's photo runs (3 of 16)
constexpr double kMaxXmaxErrorPctX0 = 0.5;  // any reported maximum, % of X0
// ... but for at most kMaxBeyondFloor of the sample's maxima, each within
// kCoveredSigmas of its own stated error: a maximum read from one bar that
// read it badly, and says so (seed 7's run 0.405, read since its bars'
// releases give their common swing: rebound 0 from the right bar alone,
// 2.5 % of X0 off at a sigma of 5.4 %; every other maximum of the sample
// within the floor).
constexpr int kMaxBeyondFloor = 1;
constexpr double kCoveredSigmas = 3.0;

}  // namespace

TEST_CASE("synth: a randomised sample reduces, and its maxima follow the truth") {
  int runs = 0, reduced = 0, beyond_floor = 0;
  double worst_pct = 0.0;
  std::string failures;
  // Seeds 1..8 as they come; the photos are 1000 px wide to keep the test
  // within its time (the bench draws sizes 600-6000 px).
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    testing::TempDir dir;
    SynthOptions synth;
    synth.preset = "quick";
    synth.style = PhotoStyle::kRandomised;
    synth.seed = seed;
    synth.width_px = 1000;
    // The look as drawn, without the handling (marks about the traces, tape,
    // prints): the sample this floor was measured on. The handling's kinds
    // are measured by bench_robustness per factor.
    synth.photo_handling = false;
    const SynthSummary summary = GenerateSession(dir.path() / "s", synth);
    ReduceOptions options;
    options.products = Products::kRebounds;
    const SessionResult result = ReduceSession(ReadManifest(dir.path() / "s").session, options);
    for (const auto& truth : summary.truth["runs"]) {
      const RunResult* run = result.FindRun(truth["id"].get<std::string>());
      REQUIRE(run != nullptr);
      ++runs;
      if (!run->ok) {
        failures += "seed " + std::to_string(seed) + ": " + run->reason + "\n";
        continue;
      }
      ++reduced;
      const double x0 = truth["initial_displacement"];
      const auto& xmax = truth["rebounds"]["xmax"];
      for (std::size_t n = 0; n < run->measured.xmax.size() && n < xmax.size(); ++n) {
        const double error = std::abs(run->measured.xmax[n] - xmax[n].get<double>());
        const double pct = 100.0 * error / x0;
        INFO("seed " << seed << " run " << run->id << " rebound " << n << ": " << pct
                     << " % of X0, sigma " << 100.0 * run->measured.xmax_sigma[n] / x0);
        if (pct > kMaxXmaxErrorPctX0) {
          ++beyond_floor;
          CHECK(error <= kCoveredSigmas * run->measured.xmax_sigma[n]);
        }
        worst_pct = std::max(worst_pct, pct);
      }
    }
  }
  INFO(reduced << " of " << runs << " runs reduced, worst maximum " << worst_pct
               << " % of X0; failures:\n"
               << failures);
  CHECK(static_cast<double>(reduced) / runs >= kMinShareReduced);
  CHECK(beyond_floor <= kMaxBeyondFloor);
  WARN(reduced << " of " << runs << " runs reduced, worst maximum " << worst_pct << " % of X0\n"
               << failures);
}

}  // namespace impactlab
