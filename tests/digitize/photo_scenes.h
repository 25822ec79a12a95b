// Oscillograph scenes for the digitizer's tests and benchmark, and how to
// score a digitized trace against the renderer's truth. Header-only, shared
// by tests/digitize and bench/digitize_bench.cpp.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "digitize/digitize.h"
#include "render/oscillograph.h"

namespace impactlab::testing {

inline TraceSettings Settings(double time_per_div, double volts_per_div, double zero_div,
                              std::array<double, 2> band_div) {
  TraceSettings settings;
  settings.time_per_div = time_per_div;
  settings.volts_per_div = volts_per_div;
  settings.zero_div = zero_div;
  settings.band_div = band_div;
  return settings;
}

// A pendulum's displacement seen by a photocell over a 5 s sweep: the release
// swing down to the first impact, then half-sine rebounds of falling height,
// through a slightly curved photocell response. Volts.
inline double PhotocellVolts(double t, double x0_share, double period_s, double restitution,
                             double phase_s) {
  const double quarter = 0.25 * period_s, half = 0.5 * period_s;
  double x = 0.0;
  const double tt = t + phase_s;
  if (tt < quarter) {
    x = x0_share * std::cos(2.0 * std::numbers::pi * tt / period_s);
  } else {
    const int rebound = static_cast<int>((tt - quarter) / half);
    const double into = tt - quarter - rebound * half;
    x = x0_share * std::pow(restitution, rebound + 1) * std::sin(std::numbers::pi * into / half);
  }
  return 0.05 + 0.6 * x - 0.04 * x * x;
}

// The contact pulse of the standard scene: 1 us edges, half level crossed at
// these times.
constexpr double kPulseRiseS = 150.5e-6;
constexpr double kPulseFallS = 502.5e-6;

struct RunScene {
  OscillographScene scene;
  std::vector<TraceRequest> requests;  // what the manifest would say
};

// The contact trace's sweep in the contact pulse tests: 50 us/div, the
// contact starting 10 ms into the run's clock.
inline constexpr double kContactTimePerDiv = 50e-6;
inline constexpr double kContactStartS = 0.01;

// The clean style's render options (no print, no wear) at `width_px`, drawn
// from `seed`, one grey channel when `grey`: what a test varies is set on
// top.
inline RenderOptions CleanOptions(int width_px, unsigned seed, bool grey = false) {
  RenderOptions options;
  options.style = PhotoStyle::kClean;
  options.width_px = width_px;
  options.seed = seed;
  options.grey = grey;
  return options;
}

// A run photo as the thesis's: the right and left displacement traces chopped
// on one beam in their own bands, the contact pulse on a delayed sweep below.
inline RunScene StandardRunScene() {
  RunScene run;
  ScreenTrace right{"right", {}, {}, Settings(0.5, 0.2, 0.3, {0.0, 4.0}), BeamMode::kChopped, 0};
  ScreenTrace left{"left", {}, {}, Settings(0.5, 0.4, -2.2, {-2.4, 0.0}), BeamMode::kChopped, 0};
  constexpr int kSamples = 5000;
  for (int i = 0; i <= kSamples; ++i) {
    const double t = 5.0 * i / kSamples;
    right.time_s.push_back(t);
    right.volts.push_back(PhotocellVolts(t, 1.0, 1.5, 0.8, 0.0));
    left.time_s.push_back(t);
    left.volts.push_back(1.15 * PhotocellVolts(t, 0.95, 1.5, 0.78, 0.004));
  }
  ScreenTrace contact{
      "contact", {}, {}, Settings(100e-6, 1.0, -3.6, {-4.0, -2.4}), BeamMode::kContinuous, 1};
  contact.settings.impact = 2;
  for (int i = 0; i <= 1000; ++i) {
    const double t = i * 1e-6;
    contact.time_s.push_back(t);
    double v = 0.0;
    if (t >= 150e-6 && t < 502e-6) v = 1.0;
    contact.volts.push_back(v + 0.01 * std::sin(t * 2e5));
  }
  // The edges themselves, 1 us long, exactly.
  auto set = [&](double t, double v) {
    const int i = static_cast<int>(std::lround(t * 1e6));
    contact.volts[i] = v + 0.01 * std::sin(t * 2e5);
  };
  set(150e-6, 0.0), set(151e-6, 1.0), set(502e-6, 1.0), set(503e-6, 0.0);
  run.scene.traces = {right, left, contact};
  for (const ScreenTrace& trace : run.scene.traces)
    run.requests.push_back({trace.name, trace.settings});
  return run;
}

// The standard run photo with the session generator's contact trace: a
// 50 us/div delayed sweep, levels 0.05 and 2.45 V at 2 V/div (screen y
// -3.875 and -2.675), the rise at screen x `rise_div` and the fall at
// `fall_div`, both exactly vertical.
inline RunScene ContactPulseScene(double rise_div, double fall_div) {
  RunScene run = StandardRunScene();
  TraceSettings settings = Settings(kContactTimePerDiv, 2.0, -3.9, {-4.0, -2.8});
  settings.t0_div = rise_div - kContactStartS / kContactTimePerDiv;
  settings.impact = 2;
  const double window_start = kContactStartS - rise_div * kContactTimePerDiv;
  const double fall_s = kContactStartS + (fall_div - rise_div) * kContactTimePerDiv;
  ScreenTrace& contact = run.scene.traces[2];
  contact.time_s = {window_start, kContactStartS, kContactStartS,
                    fall_s,       fall_s,         window_start + 10.5 * kContactTimePerDiv};
  contact.volts = {0.05, 0.05, 2.45, 2.45, 0.05, 0.05};
  contact.settings = settings;
  run.requests[2].settings = settings;
  return run;
}

// ContactPulseScene's pulse with each edge an RC exponential of time
// constant `rc_s` from its switching instant (a real contact circuit's).
inline RunScene ContactRcScene(double rise_div, double fall_div, double rc_s) {
  RunScene run = ContactPulseScene(rise_div, fall_div);
  const double window_start = kContactStartS - rise_div * kContactTimePerDiv;
  const double fall_s = kContactStartS + (fall_div - rise_div) * kContactTimePerDiv;
  const double low = 0.05, high = 2.45;
  ScreenTrace& contact = run.scene.traces[2];
  contact.time_s.clear();
  contact.volts.clear();
  const double end = window_start + 10.5 * kContactTimePerDiv;
  for (double t = window_start; t <= end; t += 0.05e-6) {
    double v = low;
    if (t >= kContactStartS)
      v = low + (high - low) * (1.0 - std::exp(-(t - kContactStartS) / rc_s));
    if (t >= fall_s) {
      const double at_fall =
          low + (high - low) * (1.0 - std::exp(-(fall_s - kContactStartS) / rc_s));
      v = low + (at_fall - low) * std::exp(-(t - fall_s) / rc_s);
    }
    contact.time_s.push_back(t);
    contact.volts.push_back(v);
  }
  return run;
}

// How far the digitized centre line lies from the truth.
struct TraceScore {
  double rms_px = 0.0;  // distance to the true centre line, in photo pixels
  double max_px = 0.0;
  double rms_percent_fs = 0.0;  // volts error at the sample's time, % of the screen's full scale
  std::size_t samples = 0;
  std::size_t far_samples = 0;  // further than 3 px from the truth: made up or misplaced
  double coverage = 0.0;        // share of the drawn truth samples with a digitized sample near
};

// The largest distance between the fitted and the true image of the screen's
// points every half division. `truth`: anything with ImageFromScreen (the
// renderer's photo, a GraticuleMapping).
template <typename Truth>
double WorstMappingError(const GraticuleFit& fit, const Truth& truth) {
  double worst = 0.0;
  for (double x = 0.0; x <= fit.divisions[0]; x += 0.5) {
    for (double y = -0.5 * fit.divisions[1]; y <= 0.5 * fit.divisions[1]; y += 0.5) {
      worst = std::max(
          worst, cv::norm(fit.mapping.ImageFromScreen({x, y}) - truth.ImageFromScreen({x, y})));
    }
  }
  return worst;
}

// Distance from p to the polyline through `points`, whose segments are short.
inline double DistanceToPolyline(const std::vector<cv::Point2d>& points, cv::Point2d p,
                                 std::size_t& hint) {
  double best = std::numeric_limits<double>::max();
  const std::size_t n = points.size();
  // Search around the hint first; the samples come in order.
  const std::size_t lo = hint > 400 ? hint - 400 : 0, hi = std::min(n - 1, hint + 400);
  auto scan = [&](std::size_t from, std::size_t to) {
    for (std::size_t i = from; i < to; ++i) {
      const cv::Point2d a = points[i], ab = points[i + 1] - a;
      const double length2 = ab.dot(ab);
      const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
      const double d = cv::norm(p - (a + ab * t));
      if (d < best) best = d, hint = i;
    }
  };
  scan(lo, hi);
  if (best > 5.0) scan(0, n - 1);
  return best;
}

// Scores a digitized trace against the truth of the photo it came from: each
// sample's (time, volts) goes to the screen through the trace's settings and
// to the photo through the true mapping, and is compared with the true centre line.
inline TraceScore ScoreTrace(const DigitizedTrace& digitized, const RenderedPhoto& photo,
                             const ScreenTrace& source, std::array<int, 2> divisions) {
  TraceScore score;
  const TraceTruth* truth = nullptr;
  for (const TraceTruth& t : photo.traces) {
    if (t.name == digitized.name) truth = &t;
  }
  if (truth == nullptr || truth->centre_px.size() < 2) return score;
  const TraceSettings& s = digitized.settings;
  double sum2 = 0.0, sum2_fs = 0.0;
  std::size_t hint = 0;
  for (std::size_t i = 0; i < digitized.trace.time_s.size(); ++i) {
    const double t = digitized.trace.time_s[i], v = digitized.trace.volts[i];
    const cv::Point2d screen(s.t0_div + t / s.time_per_div, s.zero_div + v / s.volts_per_div);
    const double d = DistanceToPolyline(truth->centre_px, photo.ImageFromScreen(screen), hint);
    sum2 += d * d;
    score.max_px = std::max(score.max_px, d);
    score.far_samples += d > 3.0;
    // The signal at that time (linear between the source's samples).
    const auto it = std::lower_bound(source.time_s.begin(), source.time_s.end(), t);
    if (it != source.time_s.begin() && it != source.time_s.end()) {
      const std::size_t k = static_cast<std::size_t>(it - source.time_s.begin());
      const double f = (t - source.time_s[k - 1]) / (source.time_s[k] - source.time_s[k - 1]);
      const double truth_volts = source.volts[k - 1] + f * (source.volts[k] - source.volts[k - 1]);
      const double full_scale = divisions[1] * std::abs(s.volts_per_div);
      const double e = 100.0 * (v - truth_volts) / full_scale;
      sum2_fs += e * e;
    }
    ++score.samples;
  }
  if (score.samples > 0) {
    score.rms_px = std::sqrt(sum2 / score.samples);
    score.rms_percent_fs = std::sqrt(sum2_fs / score.samples);
  }
  // Coverage: drawn truth samples clear of the screen's edge with a digitized
  // sample within 0.02 division in x.
  std::vector<double> xs;
  for (const cv::Point2d& p : digitized.screen_div) xs.push_back(p.x);
  std::sort(xs.begin(), xs.end());
  std::size_t drawn = 0, covered = 0;
  for (std::size_t i = 0; i < truth->screen_div.size(); ++i) {
    if (!truth->drawn[i]) continue;
    ++drawn;
    const double x = truth->screen_div[i].x;
    const auto it = std::lower_bound(xs.begin(), xs.end(), x - 0.02);
    covered += it != xs.end() && *it <= x + 0.02;
  }
  score.coverage = drawn > 0 ? static_cast<double>(covered) / drawn : 0.0;
  return score;
}

// A straight line between two screen points, `thickness_px` wide, drawn at
// `level` of full scale: a scratch or a hair (bright on a dark print, dark on a negative's
// light ground), or a grid line redrawn.
inline void Scratch(cv::Mat& image, const RenderedPhoto& photo, cv::Point2d from_div,
                    cv::Point2d to_div, double level, int thickness_px = 1) {
  const cv::Point2d a = photo.ImageFromScreen(from_div), b = photo.ImageFromScreen(to_div);
  const double full = image.depth() == CV_16U ? 65535.0 : 255.0;
  cv::line(image, cv::Point(cvRound(a.x * 16), cvRound(a.y * 16)),
           cv::Point(cvRound(b.x * 16), cvRound(b.y * 16)), cv::Scalar::all(level * full),
           thickness_px, cv::LINE_AA, 4);
}

// Redraws the graticule's lines brighter, as on a print whose graticule was lit
// almost as brightly as the traces.
inline void BrightenGraticule(cv::Mat& image, const RenderedPhoto& photo, double level) {
  for (int i = 0; i <= 10; ++i) Scratch(image, photo, {1.0 * i, -4.0}, {1.0 * i, 4.0}, level);
  for (int j = -4; j <= 4; ++j) Scratch(image, photo, {0.0, 1.0 * j}, {10.0, 1.0 * j}, level);
}

}  // namespace impactlab::testing
