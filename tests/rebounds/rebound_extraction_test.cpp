#include "rebounds/rebound_extraction.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <random>

#include <catch2/catch.hpp>

#include "model/kelvin_voigt.h"
#include "model/rebound_history.h"
#include "tests/support/thesis_pendulum.h"

namespace impactlab {
namespace {

using testing::kBarMass;
using testing::kPendulum;

struct Truth {
  ReboundSequence sequence;
  DisplacementHistory history;
};

// Ground truth from the model: a history sampled every dt with noise.
Truth Simulate(double x0, double dt, double noise, unsigned seed) {
  const KelvinVoigtContactLaw law({kBarMass, 462000.0, 10.0}, Separation::kKinematic);
  Truth truth;
  truth.sequence = SimulateRebounds(kPendulum, law, x0, 5);
  const SampledHistory s = SampleHistory(truth.sequence, kPendulum, law, dt);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise);
  truth.history.time_s = s.time;
  for (double x : s.displacement) truth.history.displacement.push_back(x + n(rng));
  return truth;
}

// As Simulate, with AR(1) noise of sigma `noise` whose correlation falls by
// e every `correlation_s` seconds: a digitized trace errs smoothly over
// neighbouring samples.
Truth SimulateCorrelated(double x0, double dt, double noise, double correlation_s, unsigned seed) {
  Truth truth = Simulate(x0, dt, 0.0, seed);
  const double rho = std::exp(-dt / correlation_s);
  std::mt19937 rng(seed);
  std::normal_distribution<double> e(0.0, noise * std::sqrt(1.0 - rho * rho));
  double state = 0.0;
  for (double& x : truth.history.displacement) x += (state = rho * state + e(rng));
  return truth;
}

TEST_CASE("rebounds: noiseless maxima and peak times are found far below the sample spacing") {
  const Truth truth = Simulate(1.519, 2e-3, 0.0, 1);
  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number);
    CHECK(rb.xmax.value == Approx(truth.sequence.xmax[rb.number]).epsilon(1e-9));
    CHECK(rb.t_peak.value == Approx(truth.sequence.peak_time[rb.number]).margin(1e-8));
    CHECK(rb.duration.value == Approx(truth.sequence.duration[rb.number]).epsilon(2e-3));
  }
  REQUIRE(r.impact_times.size() >= 5);
  CHECK(r.impact_times[0] == Approx(truth.sequence.impact_time[0]).margin(2e-3));
}

TEST_CASE("rebounds: with noise the maxima stay within a few reported sigmas") {
  const double x0 = 0.405, noise = 0.002;
  const Truth truth = Simulate(x0, 1e-3, noise, 3);
  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number);
    const double error = rb.xmax.value - truth.sequence.xmax[rb.number];
    CHECK(rb.xmax.sigma > 0.0);
    CHECK(rb.xmax.sigma < noise);  // hundreds of samples average the noise down
    CHECK(std::abs(error) < 4.0 * rb.xmax.sigma);
    CHECK(rb.fit_rms == Approx(noise).epsilon(0.2));
  }
}

TEST_CASE("rebounds: with noise correlated along the trace the maxima's pulls stay near 1") {
  // A digitized trace errs smoothly over neighbouring samples: AR(1) noise
  // with a correlation time of 10 ms (five samples). Treating its samples as
  // independent would understate each maximum's sigma about 3x.
  double sum_pull2 = 0.0;
  int count = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const Truth truth = SimulateCorrelated(0.405, 2e-3, 0.002, 10e-3, seed);
    const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
    for (const ExtractedRebound& rb : r.rebounds) {
      const double pull = (rb.xmax.value - truth.sequence.xmax[rb.number]) / rb.xmax.sigma;
      sum_pull2 += pull * pull;
      ++count;
    }
  }
  REQUIRE(count >= 80);
  const double pull_rms = std::sqrt(sum_pull2 / count);
  CHECK(pull_rms > 0.6);
  CHECK(pull_rms < 1.4);
}

// The release's X0 from the fall's fit, under the same errors: a fit over a
// quarter swing follows part of their slow wander, so the residuals' own
// correlation falls off early, and the inflation it gives understated the
// amplitude's sigma (pull RMS 1.56 over these 60 seeds, now 1.32; the per-bar
// releases of randomised seeds 1001-2034: 54 % within one sigma). Its
// variance from the errors' autocovariance, as a peak's, holds it.
TEST_CASE("rebounds: with noise correlated along the trace the release's pull stays near 1") {
  constexpr double kX0 = 0.405;
  double sum_pull2 = 0.0;
  int count = 0;
  for (unsigned seed = 1; seed <= 60; ++seed) {
    const Truth truth = SimulateCorrelated(kX0, 2e-3, 0.002, 20e-3, seed);
    const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
    REQUIRE(r.release.sigma > 0.0);
    const double pull = (r.release.value - kX0) / r.release.sigma;
    sum_pull2 += pull * pull;
    ++count;
  }
  const double pull_rms = std::sqrt(sum_pull2 / count);
  INFO("release pull RMS " << pull_rms);
  CHECK(pull_rms > 0.6);
  CHECK(pull_rms < 1.4);
}

// Drops the samples of `h` within [from, to] s: a faint stretch of a photo.
// Every maximum read from a noiseless history, against the model's.
void CheckMaximaAgainstTruth(const ReboundExtraction& r, const ReboundSequence& s) {
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number);
    CHECK(rb.xmax.value == Approx(s.xmax[rb.number]).epsilon(1e-7));
  }
}

void DropSamples(DisplacementHistory& h, double from, double to) {
  DisplacementHistory kept;
  for (std::size_t i = 0; i < h.time_s.size(); ++i) {
    if (h.time_s[i] >= from && h.time_s[i] <= to) continue;
    kept.time_s.push_back(h.time_s[i]);
    kept.displacement.push_back(h.displacement[i]);
  }
  h = kept;
}

TEST_CASE("rebounds: durations read across gaps at the impacts carry honest errors") {
  // A digitized photo loses tens of milliseconds of trace at each impact
  // (the bars' traces meet there): the flanks' crossings are read from
  // above the gap. Over 30 noisy histories (white noise 0.1 % of X0, gaps
  // of 30-60 ms either side of every impact) the durations' errors stay a
  // fraction of a millisecond with pull RMS 1.36 (0.96-1.18 on the
  // generator's digitized styles, 0.89 on the external sessions); X0's 0.79.
  double pull2 = 0.0, release_pull2 = 0.0;
  std::vector<double> errors;
  int n = 0, releases = 0;
  std::mt19937 gaps(7);
  std::uniform_real_distribution<double> gap(0.03, 0.06);
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const double x0 = 0.323;
    Truth truth = Simulate(x0, 2e-3, 1e-3 * x0, seed);
    const ReboundSequence& s = truth.sequence;
    for (double t : s.impact_time) DropSamples(truth.history, t - gap(gaps), t + gap(gaps));
    const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
    for (const ExtractedRebound& rb : r.rebounds) {
      const double error = rb.duration.value - s.duration[rb.number];
      REQUIRE(rb.duration.sigma > 0.0);
      errors.push_back(std::abs(error));
      pull2 += error * error / (rb.duration.sigma * rb.duration.sigma);
      ++n;
    }
    REQUIRE(r.release.sigma > 0.0);
    const double miss = (r.release.value - x0) / r.release.sigma;
    release_pull2 += miss * miss;
    ++releases;
  }
  std::sort(errors.begin(), errors.end());
  const double pull_rms = std::sqrt(pull2 / n);
  const double release_pull_rms = std::sqrt(release_pull2 / releases);
  INFO(n << " durations: pull RMS " << pull_rms << ", median error " << errors[errors.size() / 2]
         << " s; release pull RMS " << release_pull_rms);
  CHECK(n >= 120);
  CHECK(pull_rms > 0.7);
  CHECK(pull_rms < 1.4);
  CHECK(errors[errors.size() / 2] < 2e-4);
  CHECK(release_pull_rms < 1.6);
}

TEST_CASE("rebounds: a falling flank seen only above the swing's amplitude gives a bounded error") {
  // A bar read 4 % of X0 high throughout (its peak fits carry that offset)
  // whose falling flanks are lost below 90 % of each crest: the only samples
  // left on them lie above the fitted amplitude, where the swing has no
  // phase. Their crossing is unknown, not known to 1e13 s (randomised seed
  // 1021's run 0.713 stated duration errors of 3.7e13 s). (The durations
  // themselves are off by tens of ms here: the shift moves every crossing of
  // X = 0, an error of the cell curve's, which AddCurveSigma states from the
  // curve's band in a reduce and which this history has none of.)
  const double x0 = 0.323, shift = 0.04 * x0;
  Truth truth = Simulate(x0, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  DisplacementHistory kept;
  for (std::size_t i = 0; i < truth.history.time_s.size(); ++i) {
    const double t = truth.history.time_s[i], x = truth.history.displacement[i];
    const auto next = std::upper_bound(s.impact_time.begin(), s.impact_time.end(), t);
    const auto n = static_cast<std::size_t>(next - s.impact_time.begin());
    const bool falling = n >= 1 && n < s.impact_time.size() && n < s.peak_time.size() &&
                         t > s.peak_time[n] && x < 0.9 * s.xmax[n];
    const bool just_after = next != s.impact_time.begin() && t < *(next - 1) + 4e-3;
    if (falling || just_after) continue;
    kept.time_s.push_back(t);
    kept.displacement.push_back(x + shift);
  }
  const ReboundExtraction r = ExtractRebounds(kept, kPendulum, {});
  REQUIRE(r.rebounds.size() >= 3);
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number << ": duration " << rb.duration.value << " ± " << rb.duration.sigma
                    << " s, truth " << s.duration[rb.number]);
    CHECK(std::isfinite(rb.duration.sigma));
    CHECK(rb.duration.sigma < s.duration[rb.number]);
  }
}

TEST_CASE("rebounds: a swing slower than the pendulum's is read as it is, not as the model's") {
  // The crossings use the pendulum's frequency to carry each sample to X = 0;
  // a history on a time axis 2 % long (a mistyped sweep, a disturbed swing)
  // must still read 2 % longer durations, or no duration could ever show an
  // anomaly.
  Truth truth = Simulate(0.323, 2e-3, 0.0, 1);
  for (double& t : truth.history.time_s) t *= 1.02;
  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  REQUIRE(r.rebounds.size() >= 4);
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number);
    // 2.3 %: carrying each sample to X = 0 at the pendulum's frequency
    // (2 % too high for these data) adds 0.3 % of its own.
    CHECK(rb.duration.value / truth.sequence.duration[rb.number] == Approx(1.02).margin(0.005));
  }
}

TEST_CASE("rebounds: gaps at an impact, at a peak or over a whole rebound keep the numbering") {
  Truth truth = Simulate(0.323, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  // A digitized photo loses its faint parts: here the samples around impact
  // 2 (merging rebounds 1 and 2 for a threshold), the top of rebound 3
  // (splitting it), and rebound 4 entirely.
  DropSamples(truth.history, s.impact_time[1] - 0.04, s.impact_time[1] + 0.05);
  DropSamples(truth.history, s.peak_time[3] - 0.05, s.peak_time[3] + 0.04);
  DropSamples(truth.history, s.start_time[4] - 0.01, s.start_time[4] + s.duration[4] + 0.01);
  // A stray fragment of rebound 2's tail, cut off from it by a gap.
  DropSamples(truth.history, s.impact_time[2] - 0.06, s.impact_time[2] - 0.02);

  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  std::vector<int> numbers;
  for (const ExtractedRebound& rb : r.rebounds) {
    numbers.push_back(rb.number);
    INFO("rebound " << rb.number);
    CHECK(rb.xmax.value == Approx(s.xmax[rb.number]).epsilon(1e-7));
    CHECK(rb.t_peak.value == Approx(s.peak_time[rb.number]).margin(1e-6));
  }
  CHECK(numbers == std::vector<int>{1, 2, 3, 5});
}

TEST_CASE("rebounds: a history missing the release's top and its first impact is still numbered") {
  Truth truth = Simulate(0.115, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  // The photo shows the fall only from 85 % of X0 on (0.135 s after release),
  // and nothing around the first impact, so rebound 1's peak is the largest
  // sample after the first one.
  DropSamples(truth.history, -1.0, 0.135);
  DropSamples(truth.history, s.impact_time[0] - 0.05, s.impact_time[0] + 0.05);

  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  CHECK(r.impact_times[0] == Approx(s.impact_time[0]).margin(1e-3));
  CheckMaximaAgainstTruth(r, s);
}

TEST_CASE(
    "rebounds: a gap from the release's fall into the next rebound's rise is no longer fall") {
  Truth truth = Simulate(0.713, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  // Nothing from 65 % of the fall to 45 % of rebound 1's rise: the first
  // sample after the gap is lower than the last before it, as if still falling.
  DropSamples(truth.history, 0.205, s.impact_time[0] + 0.146);

  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  CHECK(r.rebounds[0].number == 1);
  CHECK(r.impact_times[0] == Approx(s.impact_time[0]).margin(1e-3));
  CheckMaximaAgainstTruth(r, s);
}

TEST_CASE("rebounds: a short arc of the fall gives X0 near the release at t = 0") {
  // As randomised seeds 1018's and 1034's runs 0.713 read their right bars:
  // the hold and the fall's first 77 ms lost, then 35 ms of fall, then
  // nothing until past the first impact. Over so short an arc the fall's
  // amplitude and phase trade off against the reading's slow wander; the
  // release at t = 0 (the traces' time origin) holds the phase: over these
  // 40 seeds X0 errs by 0.67 % of X0 RMS, pull RMS 1.01 (a free phase: 3.4 %
  // and 2.6).
  constexpr double kX0 = 0.713;
  double sum_error2 = 0.0, sum_pull2 = 0.0;
  int count = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    Truth truth = SimulateCorrelated(kX0, 1e-3, 0.004, 20e-3, seed);
    DropSamples(truth.history, -1.0, 0.077);
    DropSamples(truth.history, 0.112, truth.sequence.impact_time[0] + 0.2);
    const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
    REQUIRE(r.release.sigma > 0.0);
    const double error = r.release.value - kX0;
    sum_error2 += error * error;
    sum_pull2 += std::pow(error / r.release.sigma, 2);
    ++count;
  }
  const double error_rms = std::sqrt(sum_error2 / count);
  const double pull_rms = std::sqrt(sum_pull2 / count);
  INFO("release error RMS " << 100.0 * error_rms / kX0 << " % of X0, pull RMS " << pull_rms);
  CHECK(error_rms < 1.5e-2 * kX0);
  CHECK(pull_rms < 1.4);
}

TEST_CASE("rebounds: a fall read from 72 % of X0, then a gap into rebound 1's rise, gives X0") {
  Truth truth = Simulate(0.405, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  const double quarter = s.impact_time[0];  // the release's fall, t = 0 to the first impact
  // As randomised seed 1034's run 0.405 read its right bar: the fall from
  // 72 % of X0 (its top and hold lost) down to 41 %, then nothing until
  // rebound 1 has risen to about 45 % of its peak, lower than the fall's
  // last sample, as if the bar were still falling.
  const double from = quarter * std::acos(0.72) * 2.0 / std::numbers::pi;
  const double to = quarter * std::acos(0.41) * 2.0 / std::numbers::pi;
  DropSamples(truth.history, -1.0, from);
  DropSamples(truth.history, to, s.impact_time[0] + 0.12);

  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  CHECK(r.release.value == Approx(0.405).epsilon(2e-3));
  CHECK(r.impact_times[0] == Approx(s.impact_time[0]).margin(2e-3));
  REQUIRE(r.rebounds.size() == 5);
  CheckMaximaAgainstTruth(r, s);
}

TEST_CASE("rebounds: a history that begins after the first impact is numbered from the release") {
  Truth truth = Simulate(0.323, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  // The release's whole fall lost (left out as a line followed instead of
  // the trace, or under a mark): the history begins on rebound 1's rise.
  // The sweep is triggered at the release, t = 0, so the first impact is
  // due a quarter period later, and the first rebound seen is rebound 1,
  // not the release.
  DropSamples(truth.history, -1.0, s.impact_time[0] + 0.03);

  const ReboundExtraction r = ExtractRebounds(truth.history, kPendulum, {});
  REQUIRE(r.ok);
  CHECK(r.release.sigma == 0.0);  // X0 is not known from this history
  std::vector<int> numbers;
  for (const ExtractedRebound& rb : r.rebounds) {
    numbers.push_back(rb.number);
    INFO("rebound " << rb.number);
    CHECK(rb.xmax.value == Approx(s.xmax[rb.number]).epsilon(1e-7));
    CHECK(rb.t_peak.value == Approx(s.peak_time[rb.number]).margin(1e-6));
  }
  CHECK(numbers == std::vector<int>{1, 2, 3, 4, 5});
}

// The history up to `end_s` only: a sweep that ends before the record does.
DisplacementHistory EndingAt(const DisplacementHistory& h, double end_s) {
  DisplacementHistory kept;
  for (std::size_t i = 0; i < h.time_s.size() && h.time_s[i] <= end_s; ++i) {
    kept.time_s.push_back(h.time_s[i]);
    kept.displacement.push_back(h.displacement[i]);
  }
  return kept;
}

TEST_CASE("rebounds: the last rebound, its peak 0.25 s before the record ends, is measured") {
  // A 4 s sweep of the thesis's pendulum holds rebound 5's peak (3.75 s) and
  // a third of a half swing past it: the falling flank down to half height.
  const Truth truth = Simulate(0.323, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  const DisplacementHistory cut = EndingAt(truth.history, s.peak_time[5] + 0.25);
  const ReboundExtraction r = ExtractRebounds(cut, kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  const ExtractedRebound& last = r.rebounds.back();
  CHECK(last.number == 5);
  CHECK(last.xmax.value == Approx(s.xmax[5]).epsilon(1e-7));
  CHECK(last.t_peak.value == Approx(s.peak_time[5]).margin(1e-6));
  // The falling flank reaches below 30 % of the amplitude: the end crossing
  // is measured from it, not assumed.
  CHECK(last.duration.value == Approx(s.duration[5]).epsilon(2e-3));
}

TEST_CASE("rebounds: a last rebound cut off past its peak has an honest, larger sigma") {
  // Pulls of rebound 5 over noisy histories ending at several points past its
  // peak: about 1 (the sigma is honest), and the sigma grows as less of the
  // falling flank is on the record (fewer samples, one-sided).
  const double x0 = 0.323, noise = 0.002;
  const Truth reference = Simulate(x0, 2e-3, 0.0, 1);
  const double h5 = reference.sequence.duration[5];  // rebound 5's half swing
  double previous_sigma = 0.0;
  for (const double past : {0.45, 0.33, 0.2, 0.1, 0.05}) {
    INFO("record ends " << past << " of a half swing past the peak");
    double pull2 = 0.0, sigma_sum = 0.0, full_sigma_sum = 0.0;
    int found = 0;
    constexpr int kSeeds = 100;
    for (unsigned seed = 1; seed <= kSeeds; ++seed) {
      const Truth truth = Simulate(x0, 2e-3, noise, 100 + seed);
      const ReboundSequence& s = truth.sequence;
      const ReboundExtraction r =
          ExtractRebounds(EndingAt(truth.history, s.peak_time[5] + past * h5), kPendulum, {});
      if (r.rebounds.empty() || r.rebounds.back().number != 5) continue;
      ++found;
      const Estimate& xmax = r.rebounds.back().xmax;
      pull2 += std::pow((xmax.value - s.xmax[5]) / xmax.sigma, 2);
      sigma_sum += xmax.sigma;
      const ReboundExtraction whole = ExtractRebounds(truth.history, kPendulum, {});
      REQUIRE(whole.rebounds.back().number == 5);
      full_sigma_sum += whole.rebounds.back().xmax.sigma;
    }
    CHECK(found == kSeeds);
    const double pull_rms = std::sqrt(pull2 / std::max(1, found));
    CHECK(pull_rms > 0.8);
    CHECK(pull_rms < 1.25);
    CHECK(sigma_sum > full_sigma_sum);  // fewer samples: a larger sigma, never a smaller one
    CHECK(sigma_sum > previous_sigma);
    previous_sigma = sigma_sum;
  }
}

TEST_CASE("rebounds: a record ending before, or at, the last peak adds no rebound") {
  const Truth truth = Simulate(0.323, 2e-3, 0.0, 1);
  const ReboundSequence& s = truth.sequence;
  for (const double end : {s.peak_time[5] - 0.2, s.peak_time[5] - 0.01, s.peak_time[5] + 2e-3,
                           s.start_time[5] + 0.02}) {
    INFO("record ends at " << end << " s, rebound 5's peak at " << s.peak_time[5] << " s");
    const ReboundExtraction r = ExtractRebounds(EndingAt(truth.history, end), kPendulum, {});
    REQUIRE(r.rebounds.size() == 4);
    CHECK(r.rebounds.back().number == 4);
    CHECK(r.rebounds.back().xmax.value == Approx(s.xmax[4]).epsilon(1e-7));
    CHECK(r.impact_times.size() <= 6);  // no impact walked past the record's end
  }
}

TEST_CASE("rebounds: averaging right and left halves the difference between them") {
  const Truth right = Simulate(0.6, 1e-3, 0.0, 1);
  DisplacementHistory left = right.history;
  for (double& x : left.displacement) x *= 1.02;  // a cell that reads 2 % high
  const DisplacementHistory average = AverageHistories(right.history, left);
  const ReboundExtraction r = ExtractRebounds(average, kPendulum, {});
  CHECK(r.rebounds[0].xmax.value == Approx(1.01 * right.sequence.xmax[1]).epsilon(1e-6));
}

// A slow sweep's chopped trace: dashes 75 ms long every 100 ms (0.2 division
// slots at 0.5 s/div), the first starting `phase_s` into the history.
DisplacementHistory Chopped(const DisplacementHistory& h, double phase_s) {
  DisplacementHistory out;
  for (std::size_t i = 0; i < h.time_s.size(); ++i) {
    if (std::fmod(h.time_s[i] + phase_s, 0.1) >= 0.075) continue;
    out.time_s.push_back(h.time_s[i]);
    out.displacement.push_back(h.displacement[i]);
  }
  return out;
}

TEST_CASE("rebounds: averaging chopped traces read at different times keeps the maxima") {
  // Each bar's samples fill the other's 25 ms gaps: a straight line across
  // a gap at a peak would cut under it by X'' h^2 / 8, 0.14 % of the maximum.
  const Truth truth = Simulate(0.6, 8e-3, 0.0, 1);
  const DisplacementHistory right = Chopped(truth.history, 0.0);
  const DisplacementHistory left = Chopped(truth.history, 0.05);
  const ReboundExtraction r = ExtractRebounds(AverageHistories(right, left), kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number);
    CHECK(rb.xmax.value == Approx(truth.sequence.xmax[rb.number]).epsilon(2e-5));
  }
}

// Bars chopped on one beam: each drawn only in its own half of every 72 ms
// slot, so the two are never read at the same time, densely within a dash.
DisplacementHistory Alternating(const DisplacementHistory& h, double phase_s) {
  DisplacementHistory out;
  for (std::size_t i = 0; i < h.time_s.size(); ++i) {
    if (std::fmod(h.time_s[i] + phase_s, 0.072) >= 0.036) continue;
    out.time_s.push_back(h.time_s[i]);
    out.displacement.push_back(h.displacement[i]);
    out.sigma.push_back(h.sigma.empty() ? 1e-4 : h.sigma[i]);
  }
  return out;
}

TEST_CASE("rebounds: bars drawn in alternate chopper slots are averaged across each other's gaps") {
  // Each bar's 36 ms gaps are 7 of its samples wide: without a bridge no time
  // is readable on both, and a chord across a gap at a peak cuts 0.28 % under.
  const Truth truth = Simulate(0.6, 5e-3, 0.0, 1);
  const DisplacementHistory right = Alternating(truth.history, 0.0);
  const DisplacementHistory left = Alternating(truth.history, 0.036);
  CHECK(AverageHistories(right, left, 0.0).time_s.size() < 10);  // only where slots touch
  const DisplacementHistory average = AverageHistories(right, left, 0.075);
  // All but the impacts' neighbourhoods, where no cubic runs through a corner.
  CHECK(average.time_s.size() > 0.8 * (right.time_s.size() + left.time_s.size()));
  const ReboundExtraction r = ExtractRebounds(average, kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  for (const ExtractedRebound& rb : r.rebounds) {
    INFO("rebound " << rb.number);
    CHECK(rb.xmax.value == Approx(truth.sequence.xmax[rb.number]).epsilon(2e-5));
  }
}

TEST_CASE("rebounds: a bridged average's sigma holds its noise and a wider gap stays a gap") {
  const double noise = 0.002;
  Truth truth = Simulate(0.6, 5e-3, noise, 7);
  truth.history.sigma.assign(truth.history.time_s.size(), noise);
  const Truth exact = Simulate(0.6, 5e-3, 0.0, 7);
  const DisplacementHistory right = Alternating(truth.history, 0.0);
  const DisplacementHistory left = Alternating(truth.history, 0.036);
  const DisplacementHistory average = AverageHistories(right, left, 0.075);
  // Errors of the bridged average against the truth, in its own sigmas, away
  // from the impacts: a corner at the edge of a bridge's reach bends the
  // cubic by a few sigma before the chi^2 test can tell (the maxima, which the
  // average is read for, lie half a swing from any corner).
  const auto near_impact = [&](double t) {
    for (double impact : truth.sequence.impact_time) {
      if (std::abs(t - impact) < 0.1) return true;
    }
    return false;
  };
  double sum2 = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < average.time_s.size(); ++i) {
    if (near_impact(average.time_s[i])) continue;
    const auto at = static_cast<std::size_t>(std::lower_bound(exact.history.time_s.begin(),
                                                              exact.history.time_s.end(),
                                                              average.time_s[i] - 1e-12) -
                                             exact.history.time_s.begin());
    if (at >= exact.history.time_s.size() ||
        std::abs(exact.history.time_s[at] - average.time_s[i]) > 1e-12)
      continue;
    const double pull =
        (average.displacement[i] - exact.history.displacement[at]) / average.sigma[i];
    sum2 += pull * pull, ++n;
  }
  REQUIRE(n > 100);
  CHECK(std::sqrt(sum2 / n) == Approx(1.0).margin(0.3));
  // Gaps of 36 ms with a bridge of 30 ms: nothing is common to both bars
  // but where their slots touch.
  CHECK(AverageHistories(right, left, 0.030).time_s.size() < 10);
}

TEST_CASE("rebounds: two samples read at almost the same time do not upset the average") {
  // A cubic through them would weigh their difference by hundreds.
  const Truth truth = Simulate(0.6, 8e-3, 0.0, 1);
  DisplacementHistory right = truth.history;
  const DisplacementHistory left = Simulate(0.6, 7e-3, 0.0, 1).history;  // read between them
  for (double peak : {truth.sequence.peak_time[1], truth.sequence.peak_time[2]}) {
    const auto at = static_cast<std::size_t>(
        std::lower_bound(right.time_s.begin(), right.time_s.end(), peak) - right.time_s.begin());
    right.time_s.insert(right.time_s.begin() + at + 1, right.time_s[at] + 1e-5);
    right.displacement.insert(right.displacement.begin() + at + 1, right.displacement[at] + 1e-3);
  }
  const ReboundExtraction r = ExtractRebounds(AverageHistories(right, left), kPendulum, {});
  REQUIRE(r.rebounds.size() == 5);
  CHECK(r.rebounds[0].xmax.value == Approx(truth.sequence.xmax[1]).epsilon(2e-4));
  CHECK(r.rebounds[1].xmax.value == Approx(truth.sequence.xmax[2]).epsilon(2e-4));
}

TEST_CASE("contact_pulse: a sampled step gives its width to a fraction of the sample spacing") {
  Trace trace;
  const double rise = 123.4e-6, width = 353.35e-6, dt = 1e-6;
  for (double t = 0.0; t < 1e-3; t += dt) {
    // A finite rise time of 5 us, resolved by the samples.
    const auto step = [](double s) { return std::clamp(s / 5e-6 + 0.5, 0.0, 1.0); };
    trace.time_s.push_back(t);
    trace.volts.push_back(0.1 + 2.4 * (step(t - rise) - step(t - rise - width)));
  }
  const ContactPulseMeasurement measured = MeasureContactPulse(trace);
  REQUIRE(measured.ok);
  const ContactPulse& pulse = measured.pulse;
  CHECK(pulse.rise_s.value == Approx(rise).margin(1e-9));
  CHECK(pulse.width_s.value == Approx(width).margin(1e-9));
  CHECK(pulse.high_volts == Approx(2.5));
}

TEST_CASE("contact_pulse: a trace without a complete pulse is refused") {
  Trace flat;
  for (int i = 0; i < 100; ++i) {
    flat.time_s.push_back(i * 1e-6);
    flat.volts.push_back(i < 50 ? 0.0 : 2.0);  // rises and never falls
  }
  const ContactPulseMeasurement measured = MeasureContactPulse(flat);
  CHECK_FALSE(measured.ok);
  CHECK_THAT(measured.reason, Catch::Contains("does not end"));
}

TEST_CASE("contact_pulse: a flat trace is refused, saying it shows no step") {
  Trace flat;
  for (int i = 0; i < 100; ++i) {
    flat.time_s.push_back(i * 1e-6);
    flat.volts.push_back(0.1);
  }
  const ContactPulseMeasurement measured = MeasureContactPulse(flat);
  CHECK_FALSE(measured.ok);
  CHECK_THAT(measured.reason, Catch::Contains("no step"));
}

TEST_CASE("contact_pulse: a short stretch at the pulse's level before the pulse is passed over") {
  // A label written across the rest level reads as 15 us at the pulse's
  // level, 50 us before the 353 us pulse: timing the first would say 15 us.
  Trace trace;
  for (int us = 0; us < 1000; ++us) {
    const bool label = us >= 70 && us < 85;
    const bool pulse = us >= 135 && us < 488;
    trace.time_s.push_back(us * 1e-6);
    trace.volts.push_back(label || pulse ? 2.5 : 0.1);
  }
  const ContactPulseMeasurement measured = MeasureContactPulse(trace);
  REQUIRE(measured.ok);
  CHECK(measured.pulse.width_s.value == Approx(353e-6).margin(1e-6));
}

TEST_CASE(
    "contact_pulse: a trace at its pulse level in stretches none of which dominates is "
    "refused") {
  // Three stretches of 150 us: which is the contact the samples cannot say.
  Trace trace;
  for (int us = 0; us < 1000; ++us) {
    const bool high = (us >= 100 && us < 250) || (us >= 400 && us < 550) || (us >= 700 && us < 850);
    trace.time_s.push_back(us * 1e-6);
    trace.volts.push_back(high ? 2.5 : 0.1);
  }
  const ContactPulseMeasurement measured = MeasureContactPulse(trace);
  CHECK_FALSE(measured.ok);
  CHECK_THAT(measured.reason,
             Catch::Contains("more than one stretch") && Catch::Contains("150 of its 450"));
}

// Issue 14: a wrong unit or a typo in the time axis (time_per_div = 1e8, a
// CSV's time column in ns) once walked billions of empty swings (16.9 GB and
// 108 s before bad_alloc at 1e300). Refused at once, with the figures.
double SecondsToRefuse(const DisplacementHistory& h, std::string* message) {
  const auto start = std::chrono::steady_clock::now();
  const ReboundExtraction refused = ExtractRebounds(h, kPendulum, {});
  if (!refused.ok) *message = refused.reason;
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST_CASE("rebounds: a history spanning 1e9 s (time in ns) is refused at once, saying why") {
  DisplacementHistory h = Simulate(0.405, 1e-3, 0.0, 1).history;
  for (double& t : h.time_s) t *= 1e9;
  std::string message;
  CHECK(SecondsToRefuse(h, &message) < /*max_seconds=*/1.0);
  CHECK_THAT(message, Catch::Contains("swings out and back of this pendulum") &&
                          Catch::Contains("at most 1000 are expected"));
}

TEST_CASE(
    "rebounds: a history at 1e300 s, where a half swing no longer moves the clock, is refused") {
  for (const double scale : {1e8, 1e300}) {
    DisplacementHistory h = Simulate(0.405, 1e-3, 0.0, 1).history;
    for (double& t : h.time_s) t *= scale;
    std::string message;
    INFO("time scaled by " << scale);
    CHECK(SecondsToRefuse(h, &message) < /*max_seconds=*/1.0);
    CHECK_THAT(message, Catch::Contains("swings"));
  }
  // Time far from 0, a span of a few seconds: ulp(1e17) is 16 s, more than a
  // half swing, so the clock cannot advance; refused instead of looping.
  DisplacementHistory h = Simulate(0.405, 1e-3, 0.0, 1).history;
  for (double& t : h.time_s) t += 1e17;
  std::string message;
  CHECK(SecondsToRefuse(h, &message) < /*max_seconds=*/1.0);
}

TEST_CASE("rebounds: TraceSpanProblem passes real sweeps and names each limit it refuses") {
  // The thesis's sweeps: 10 divisions of 0.5 s (rebounds), 50 us (contact).
  CHECK(TraceSpanProblem(5.0, 0.0, 0, kPendulum).empty());
  CHECK(TraceSpanProblem(5.0, 5.0 / 600.0, 600, kPendulum).empty());
  CHECK(TraceSpanProblem(5e-4, 1e-6, 0, kPendulum).empty());
  CHECK_THAT(TraceSpanProblem(1e9, 0.0, 0, kPendulum), Catch::Contains("1e+09 s"));
  CHECK_THAT(TraceSpanProblem(10.0, 1e-9, 0, kPendulum),
             Catch::Contains("would need 1e+10 samples, more than the limit 1e+08"));
  CHECK_THAT(TraceSpanProblem(600.0, 0.0, 600, kPendulum), Catch::Contains("leave 0.75"));
  CHECK_THAT(TraceSpanProblem(std::nan(""), 0.0, 0, kPendulum), Catch::Contains("not a finite"));
  std::string error;
  CHECK(ReboundExtractionOptions{}.Check(&error));
}

}  // namespace
}  // namespace impactlab
