// A contact step on a digital scope's screen resting a tenth of a division
// above the graticule's bottom line, which on such a screen is the display's
// solid frame: the generator's digital thesis session, seed 4, run 1.519
// (its display's pixels pass for a print's screen). The tracking took the
// frame out of its strip only up to twice the dotted lines' height, and
// followed the frame instead of the rest level until well past the rise: the
// rise read 75 us late, the contact time 23 % short at 166 of its sigmas.

#include <cmath>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>

#include "digitize/digitize.h"
#include "synth/session_generator.h"
#include "tests/digitize/randomised_session.h"
#include "tests/support/temp_dir.h"

namespace impactlab {

TEST_CASE("digitize: a contact step resting just above a digital screen's frame is read on it") {
  cv::setNumThreads(1);
  testing::TempDir dir;
  const SynthSummary summary =
      GenerateSession(dir.path() / "s", testing::SynthOf("thesis", PhotoStyle::kDigital, 4));
  const testing::DigitizedRun run =
      testing::DigitizeGeneratedRun(dir.path() / "s", summary, "1.519");
  const DigitizeResult& result = run.result;
  INFO(result.Failure());
  REQUIRE(result.ok);
  CHECK(result.graticule.dotted);
  const std::size_t k = run.IndexOf("contact");
  const nlohmann::json* truth = run.truth;
  // The rest level is read at its own height before the rise (0.05 V), not
  // the frame's (-0.2 V).
  const DigitizedTrace& trace = result.traces[k];
  const double rise_s = (*truth)["contact"]["start_s"].get<double>();
  int before_rise = 0, on_rest = 0;
  for (std::size_t i = 0; i < trace.trace.time_s.size(); ++i) {
    if (trace.trace.time_s[i] > rise_s - 5e-6) continue;
    ++before_rise;
    on_rest += std::abs(trace.trace.volts[i] - 0.05) < 0.05;
  }
  REQUIRE(before_rise > 20);
  CHECK(on_rest > 0.9 * before_rise);
  REQUIRE(result.pulses[k]);
  const Estimate& width = result.pulses[k]->pulse.width_s;
  const double truth_s = (*truth)["contact"]["duration_s"].get<double>();
  INFO("width " << width.value * 1e6 << " +- " << width.sigma * 1e6 << " us, truth "
                << truth_s * 1e6);
  CHECK(std::abs(width.value - truth_s) < 0.005 * truth_s);
  CHECK(std::abs(width.value - truth_s) < 4.0 * width.sigma);
}

}  // namespace impactlab
