// Digitizer benchmark: run time per photo (decoding reported apart) against
// error (trace centre RMS in pixels and in % of full scale, contact pulse
// width), over generated photos of every style, sweeping the settings that
// trade speed for accuracy. A plain program printing tables (docs/digitizing.md
// shows its output); not a test.
//
//   build/bench/bench_digitize [--seeds 3] [--reps 3] [--width 0] [--quick]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/core.h>
#include <CLI/CLI.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "digitize/digitize.h"
#include "render/oscillograph.h"
#include "tests/digitize/photo_scenes.h"

namespace impactlab {
namespace {

constexpr PhotoStyle kStyles[] = {PhotoStyle::kClean, PhotoStyle::kPolaroid, PhotoStyle::kPhone,
                                  PhotoStyle::kNegative, PhotoStyle::kLowres};

struct Case {
  PhotoStyle style;
  std::uint64_t seed;
  RenderedPhoto photo;
  std::filesystem::path file;  // the photo as the user would have it: PNG or JPEG
};

struct Setting {
  std::string name;
  std::function<void(DigitizeOptions&)> apply;
};

// Errors and times of one setting on one style, pooled over seeds.
struct Tally {
  double centre_sum2 = 0.0, fs_sum2 = 0.0, pulse_sum2 = 0.0;
  std::size_t centre_n = 0, pulse_n = 0, failures = 0, far = 0;
  double contact_sum2 = 0.0;
  std::size_t contact_n = 0;
  double coverage_sum = 0.0;
  std::size_t coverage_n = 0;
  std::vector<double> ms, decode_ms;

  double CentreRms() const { return centre_n ? std::sqrt(centre_sum2 / centre_n) : NAN; }
  double FsRms() const { return centre_n ? std::sqrt(fs_sum2 / centre_n) : NAN; }
  double ContactRms() const { return contact_n ? std::sqrt(contact_sum2 / contact_n) : NAN; }
  double PulseRms() const { return pulse_n ? std::sqrt(pulse_sum2 / pulse_n) : NAN; }
  double Coverage() const { return coverage_n ? coverage_sum / coverage_n : NAN; }
  static double Median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
};

// This thread's CPU time, milliseconds: the benchmark runs on machines shared
// with other work, and CPU time is what "on one core" means.
double CpuMilliseconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * t.tv_sec + 1e-6 * t.tv_nsec;
}

void Measure(const testing::RunScene& run, const Case& c, const DigitizeOptions& options, int reps,
             Tally& tally) {
  DigitizeResult result;
  for (int rep = 0; rep < reps; ++rep) {
    const double start = CpuMilliseconds();
    Photo photo;
    try {
      photo = LoadPhoto(c.file);
    } catch (const std::exception&) {
      ++tally.failures;
      return;
    }
    const double decoded = CpuMilliseconds();
    tally.decode_ms.push_back(decoded - start);
    result = DigitizePhoto(photo, {10, 8}, run.requests, options);
    if (!result.ok) {
      ++tally.failures;
      return;
    }
    tally.ms.push_back(CpuMilliseconds() - decoded);
  }
  for (std::size_t t = 0; t < result.traces.size(); ++t) {
    const testing::TraceScore score =
        testing::ScoreTrace(result.traces[t], c.photo, run.scene.traces[t], {10, 8});
    tally.far += score.far_samples;
    if (result.traces[t].settings.impact) {
      tally.contact_sum2 += score.rms_px * score.rms_px * score.samples;
      tally.contact_n += score.samples;
    } else {
      tally.centre_sum2 += score.rms_px * score.rms_px * score.samples;
      tally.fs_sum2 += score.rms_percent_fs * score.rms_percent_fs * score.samples;
      tally.centre_n += score.samples;
      tally.coverage_sum += score.coverage;
      ++tally.coverage_n;
    }
    if (result.pulses[t]) {
      const double truth = testing::kPulseFallS - testing::kPulseRiseS;
      const double error = 100.0 * (result.pulses[t]->pulse.width_s.value - truth) / truth;
      tally.pulse_sum2 += error * error;
      ++tally.pulse_n;
    } else if (result.traces[t].settings.impact) {
      ++tally.failures;
    }
  }
}

}  // namespace
}  // namespace impactlab

int main(int argc, char** argv) {
  using namespace impactlab;
  int seeds = 3, reps = 3, width = 0;
  bool quick = false;
  CLI::App app{"Digitizer benchmark: time against error per photo style and setting"};
  app.add_option("--seeds", seeds, "Photos per style (seeds 1..N)")->capture_default_str();
  app.add_option("--reps", reps, "Timed repetitions per photo (the median is shown)")
      ->capture_default_str();
  app.add_option("--width", width, "Photo width, px (0: the style's: 2000, lowres 1000)")
      ->capture_default_str();
  app.add_flag("--quick", quick, "Default settings only");
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(1);  // one core, as the targets are stated

  // The photos, written as files (JPEG where the style is a JPEG, else PNG).
  const testing::RunScene run = testing::StandardRunScene();
  const std::filesystem::path folder = std::filesystem::temp_directory_path() /
                                       fmt::format("impactlab-bench-digitize-{}", ::getpid());
  std::filesystem::create_directories(folder);
  std::vector<Case> cases;
  for (const PhotoStyle style : kStyles) {
    for (int seed = 1; seed <= seeds; ++seed) {
      RenderOptions options;
      options.style = style;
      options.seed = seed;
      options.width_px = width;
      Case c{style, static_cast<std::uint64_t>(seed), RenderOscillograph(run.scene, options), {}};
      const bool jpeg = style == PhotoStyle::kPhone || style == PhotoStyle::kLowres;
      c.file = folder / fmt::format("{}-{}.{}", PhotoStyleName(style), seed, jpeg ? "jpg" : "png");
      // The JPEG styles already went through the codec: quality 100 keeps them.
      cv::imwrite(c.file.string(), c.photo.image, {cv::IMWRITE_JPEG_QUALITY, 100});
      cases.push_back(std::move(c));
    }
  }
  // One untimed run first, so that start-up costs (first touches of the
  // libraries' code and memory) stay out of the medians.
  {
    Tally warm;
    Measure(run, cases.front(), DigitizeOptions{}, 1, warm);
  }

  std::vector<Setting> settings = {{"default", [](DigitizeOptions&) {}}};
  if (!quick) {
    auto add = [&](std::string name, std::function<void(DigitizeOptions&)> f) {
      settings.push_back({std::move(name), std::move(f)});
    };
    add("detect_width 320", [](DigitizeOptions& o) { o.graticule.detect_width_px = 320; });
    add("detect_width 800", [](DigitizeOptions& o) { o.graticule.detect_width_px = 800; });
    add("grid samples/div 2", [](DigitizeOptions& o) { o.graticule.samples_per_div = 2; });
    add("grid samples/div 10", [](DigitizeOptions& o) { o.graticule.samples_per_div = 10; });
    add("grid average 0", [](DigitizeOptions& o) { o.graticule.line_average_div = 0.0; });
    add("method gaussian", [](DigitizeOptions& o) { o.traces.method = SubpixelMethod::kGaussian; });
    add("method parabola", [](DigitizeOptions& o) { o.traces.method = SubpixelMethod::kParabola; });
    add("centroid level 0.3", [](DigitizeOptions& o) { o.traces.centroid_level = 0.3; });
    add("centroid level 0.7", [](DigitizeOptions& o) { o.traces.centroid_level = 0.7; });
    add("profile 1.5 widths", [](DigitizeOptions& o) { o.traces.profile_half_widths = 1.5; });
    add("profile 4 widths", [](DigitizeOptions& o) { o.traces.profile_half_widths = 4.0; });
    add("samples/px 0.5", [](DigitizeOptions& o) { o.traces.samples_per_px = 0.5; });
    add("samples/px 2", [](DigitizeOptions& o) { o.traces.samples_per_px = 2.0; });
    add("grid model on", [](DigitizeOptions& o) { o.traces.grid_model = true; });
    add("grid ignored", [](DigitizeOptions& o) { o.traces.grid_reach_widths = 0.0; });
  }

  // Settings interleaved photo by photo: other work on the machine then
  // slows them all alike.
  std::map<std::string, std::map<PhotoStyle, Tally>> tallies;
  for (const Case& c : cases) {
    for (const Setting& setting : settings) {
      DigitizeOptions options;
      setting.apply(options);
      Measure(run, c, options, reps, tallies[setting.name][c.style]);
    }
  }
  std::filesystem::remove_all(folder);

  fmt::print(
      "Digitizer benchmark: {} photo(s) per style, {} timed repetition(s) each, one core "
      "(times are this thread's CPU time, medians).\n",
      seeds, reps);
  fmt::print(
      "Scene: right and left traces chopped on one beam, contact pulse of 352 us; "
      "photos {} px wide (lowres {} px).\n\n",
      width ? width : 2000, width ? width : 1000);
  fmt::print("Default settings, per style:\n\n");
  fmt::print(
      "| style    | centre RMS px | % full scale | contact RMS px | pulse width error % | "
      "coverage | ms beyond decoding | decode ms | failures |\n");
  fmt::print(
      "|----------|--------------:|-------------:|---------------:|--------------------:|"
      "---------:|-------------------:|----------:|---------:|\n");
  for (const PhotoStyle style : kStyles) {
    const Tally& t = tallies["default"][style];
    fmt::print(
        "| {:<8} | {:13.3f} | {:12.3f} | {:14.3f} | {:19.3f} | {:8.2f} | {:18.1f} | {:9.1f} | "
        "{:8} |\n",
        PhotoStyleName(style), t.CentreRms(), t.FsRms(), t.ContactRms(), t.PulseRms(), t.Coverage(),
        Tally::Median(t.ms), Tally::Median(t.decode_ms), t.failures + t.far);
  }
  if (settings.size() > 1) {
    fmt::print(
        "\nSettings against speed and error (pooled over styles; worst style in brackets):\n\n");
    fmt::print(
        "| setting             | ms beyond decoding | centre RMS px (worst)  | pulse error % "
        "(worst) | coverage | failures |\n");
    fmt::print(
        "|---------------------|-------------------:|-----------------------:|"
        "----------------------:|---------:|---------:|\n");
    for (const Setting& setting : settings) {
      std::vector<double> ms;
      double rms = 0.0, worst_rms = 0.0, pulse = 0.0, worst_pulse = 0.0, coverage = 0.0;
      std::size_t failures = 0;
      for (const PhotoStyle style : kStyles) {
        const Tally& t = tallies[setting.name][style];
        const double m = Tally::Median(t.ms);
        if (std::isfinite(m)) ms.push_back(m);
        rms += t.CentreRms() / std::size(kStyles);
        worst_rms = std::max(worst_rms, t.CentreRms());
        pulse += t.PulseRms() / std::size(kStyles);
        worst_pulse = std::max(worst_pulse, t.PulseRms());
        coverage += t.Coverage() / std::size(kStyles);
        failures += t.failures + t.far;
      }
      double mean_ms = 0.0;
      for (const double m : ms) mean_ms += m / ms.size();
      fmt::print(
          "| {:<19} | {:18.1f} | {:8.3f} ({:8.3f})    | {:9.3f} ({:8.3f})  | {:8.2f} | {:8} |\n",
          setting.name, mean_ms, rms, worst_rms, pulse, worst_pulse, coverage, failures);
    }
  }
  fmt::print(
      "\ncentre RMS: distance of each sample (time, volts through the manifest's settings "
      "and the true mapping) to the true beam centre line, displacement traces; % full "
      "scale: volts error at the sample's time over 8 divisions; failures: photos not "
      "digitized plus samples further than 3 px from the truth.\n");
  return 0;
}
