// End-to-end benchmark of `reduce` against the generator's truth: rebound
// maxima (% of X0) and contact time (%) errors, and run time per stage, over
// generated sessions of every photo style (docs/benchmarks.md).
//
//   bench_reduce [--styles clean,polaroid,phone,negative,lowres] [--seeds 2]
//                [--preset thesis|quick] [--nonlinearity 0.6] [--jobs 2] [--csv-run]
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <opencv2/imgcodecs.hpp>

#include "bench/bench_support.h"
#include "io/manifest.h"
#include "pipeline/process_memory.h"
#include "pipeline/reduce.h"
#include "synth/session_generator.h"

namespace impactlab {
namespace {

// An existing session (no truth): decoding its photos against reducing it,
// `repeats` times each, alternating, medians. Both run in this process, so
// neither pays the program's start.
int TimeSession(const std::filesystem::path& folder, int repeats, int jobs) {
  const Session session = ReadManifest(folder).session;
  std::vector<double> decode, reduce;
  for (int i = 0; i < repeats; ++i) {
    decode.push_back(DecodeSeconds(folder));
    ReduceOptions options;
    options.jobs = jobs;
    const auto start = std::chrono::steady_clock::now();
    const SessionResult result = ReduceSession(session, options);
    reduce.push_back(Seconds(start));
    const auto failed = std::count_if(result.runs.begin(), result.runs.end(),
                                      [](const RunResult& run) { return !run.ok; });
    if (failed > 0) fmt::print(stderr, "{} run(s) failed\n", failed);
  }
  const double d = Percentile(decode, 0.5), r = Percentile(reduce, 0.5);
  fmt::print("| session | decode s (1 thread) | reduce s ({} threads) | reduce/decode |\n", jobs);
  fmt::print("|---|---|---|---|\n");
  fmt::print("| {} | {:.3f} | {:.3f} | {:.2f} |\n", folder.string(), d, r, r / d);
  fmt::print("medians of {} (decode min {:.3f}, max {:.3f}; reduce min {:.3f}, max {:.3f})\n",
             repeats, Percentile(decode, 0.0), Percentile(decode, 1.0), Percentile(reduce, 0.0),
             Percentile(reduce, 1.0));
  return 0;
}

// One rebound's error, kept so --worst can say where the worst ones are.
struct XmaxError {
  double pct = 0.0;
  int seed = 0;
  std::string run;
  std::size_t rebound = 0;
};

// Bins of a true duration's distance from the half period, ms: [0, 2), [2, 5), ...
constexpr std::array<double, 4> kOffBinsMs = {2.0, 5.0, 10.0, 20.0};

std::size_t OffBin(double off_ms) {
  return static_cast<std::size_t>(
      std::upper_bound(kOffBinsMs.begin(), kOffBinsMs.end(), std::abs(off_ms)) -
      kOffBinsMs.begin());
}

struct StyleFigures {
  int runs = 0, ok = 0;
  std::vector<XmaxError> worst;
  std::vector<double> xmax_error_pct, contact_error_pct;
  std::vector<double> xmax_pull, contact_pull;  // error / stated sigma
  // Signed error as a share of the maximum itself: a gain error (a curve's
  // scale, a blurred trace's flattened peaks) shows here, not in the medians.
  std::vector<double> xmax_gain_error_pct;
  std::vector<double> duration_error_ms, duration_pull, peak_time_pull;
  // Anomaly flags: rebounds flagged; rebounds whose true duration is off the
  // free pendulum's half period by more than 3.5 of the stated sigmas (the
  // flag's threshold at 24 tests), and how many of those were flagged.
  int rebounds = 0, flagged = 0, disturbed = 0, disturbed_flagged = 0;
  // The detection rate by what the flag tests, from the truth alone: a true
  // maximum above its predecessor's, and a true duration off the free
  // pendulum's half period by kOffBinsMs (what the forcing did, not what the
  // reading saw).
  int rises = 0, rises_flagged = 0;
  std::array<int, 5> off_count{}, off_flagged{};
  double decode_s = 0, reduce_s = 0;
  StageSeconds stages;
};

}  // namespace
}  // namespace impactlab

int main(int argc, char** argv) {
  using namespace impactlab;
  KeepFreedMemoryForReuse();  // as the CLI does; the decoding timed below gains from it too
  HeapInHugePages();
  CLI::App app{"End-to-end reduce benchmark against generator truth"};
  std::vector<std::string> styles = {"clean", "polaroid", "phone", "negative", "lowres"};
  int seeds = 2, jobs = 2, worst = 0;
  SynthOptions synth;
  synth.preset = "thesis";
  app.add_option("--styles", styles)->delimiter(',');
  app.add_option("--seeds", seeds);
  app.add_option("--preset", synth.preset);
  app.add_option("--nonlinearity", synth.photocell_nonlinearity);
  app.add_option("--jobs", jobs);
  app.add_flag("--csv-run", synth.csv_run);
  app.add_flag("--wire-anomalies", synth.wire_anomalies,
               "Support-wire forcing (thesis App. F): the anomaly flag's detection rate");
  app.add_option("--worst", worst, "List the N worst Xmax errors per style on stderr");
  std::string session;
  int repeats = 7;
  app.add_option("--session", session,
                 "Time an existing session folder instead (decode against reduce, no truth)");
  app.add_option("--repeats", repeats, "With --session: timed repetitions (medians shown)")
      ->check(CLI::Range(1, 100));
  CLI11_PARSE(app, argc, argv);
  if (!session.empty()) return TimeSession(session, repeats, jobs);

  // One folder per process: two benchmarks at once must not share sessions.
  const auto scratch =
      std::filesystem::temp_directory_path() / fmt::format("impactlab-bench-reduce-{}", ::getpid());
  fmt::print(
      "| style | runs ok | Xmax err median (% X0) | p95 | max | Xmax gain err median (% Xmax) | "
      "Xmax pull RMS (within 1, 2) | contact err median (%) | worst | contact pull RMS | "
      "duration err median (ms) | duration pull RMS | peak time pull RMS | flagged / rebounds | "
      "flagged / disturbed | decode s | reduce s | reduce/decode | load s | calibrate s | "
      "extract s | fit s |\n");
  fmt::print(
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
      "\n");
  std::vector<std::string> detection;  // a row per style of the anomaly flag's detection
  for (const std::string& style : styles) {
    StyleFigures f;
    for (int seed = 1; seed <= seeds; ++seed) {
      std::filesystem::remove_all(scratch);
      synth.style = *ParsePhotoStyle(style);
      synth.seed = 1000 + seed;
      const SynthSummary summary = GenerateSession(scratch / "s", synth);
      f.decode_s += DecodeSeconds(scratch / "s");
      ReduceOptions options;
      options.jobs = jobs;
      const auto start = std::chrono::steady_clock::now();
      const Session session = ReadManifest(scratch / "s").session;
      const SessionResult result = ReduceSession(session, options);
      f.reduce_s += Seconds(start);
      const Pendulum pendulum{session.apparatus->pendulum_length, session.apparatus->gravity,
                              PendulumConvention::kExact};
      for (const auto& truth : summary.truth["runs"]) {
        const RunResult* run = result.FindRun(truth["id"]);
        if (run == nullptr || truth["form"] == "typed-in") continue;
        ++f.runs;
        f.stages.load += run->seconds.load;
        f.stages.calibrate += run->seconds.calibrate;
        f.stages.extract += run->seconds.extract;
        f.stages.fit += run->seconds.fit;
        if (!run->ok) {
          fmt::print(stderr, "{} seed {} run {}: {}\n", style, seed, run->id, run->reason);
          continue;
        }
        ++f.ok;
        const double x0 = truth["initial_displacement"];
        const auto& xmax = truth["rebounds"]["xmax"];
        const RunMeasurement& m = run->measured;
        const auto& duration = truth["rebounds"]["duration"];
        const auto& t_peak = truth["rebounds"]["t_peak"];
        std::vector<bool> flagged(m.xmax.size(), false);
        for (const std::string& a : run->anomalies) {
          const auto n = static_cast<std::size_t>(std::atoi(a.c_str() + a.find(' ') + 1));
          if (n < flagged.size()) flagged[n] = true;
        }
        for (std::size_t n = 0; n < m.xmax.size() && n < duration.size(); ++n) {
          ++f.rebounds;
          f.flagged += flagged[n];
          if (n < m.rebound_duration_sigma.size() && m.rebound_duration_sigma[n] > 0.0) {
            const double error = m.rebound_duration[n] - duration[n].get<double>();
            f.duration_error_ms.push_back(1e3 * std::abs(error));
            f.duration_pull.push_back(error / m.rebound_duration_sigma[n]);
            const double off =
                duration[n].get<double>() - HalfPeriod(pendulum, xmax[n].get<double>());
            if (std::abs(off) > 3.5 * m.rebound_duration_sigma[n]) {
              ++f.disturbed;
              f.disturbed_flagged += flagged[n];
            }
            const std::size_t bin = OffBin(1e3 * off);
            ++f.off_count[bin];
            f.off_flagged[bin] += flagged[n];
          }
          if (n >= 1 && n < xmax.size() && xmax[n].get<double>() > xmax[n - 1].get<double>()) {
            ++f.rises;
            f.rises_flagged += flagged[n];
          }
          if (n < m.t_peak_sigma.size() && m.t_peak_sigma[n] > 0.0) {
            f.peak_time_pull.push_back((m.t_peak[n] - t_peak[n].get<double>()) / m.t_peak_sigma[n]);
          }
        }
        for (std::size_t n = 0; n < run->measured.xmax.size() && n < xmax.size(); ++n) {
          const double pct = 100.0 * std::abs(run->measured.xmax[n] - xmax[n].get<double>()) / x0;
          f.xmax_error_pct.push_back(pct);
          f.xmax_gain_error_pct.push_back(100.0 *
                                          (run->measured.xmax[n] / xmax[n].get<double>() - 1.0));
          f.worst.push_back({pct, seed, run->id, n});
          if (n < run->measured.xmax_sigma.size() && run->measured.xmax_sigma[n] > 0.0) {
            f.xmax_pull.push_back((run->measured.xmax[n] - xmax[n].get<double>()) /
                                  run->measured.xmax_sigma[n]);
          }
        }
        if (run->measured.contact_time) {
          const double tau = truth["contact"]["duration_s"];
          f.contact_error_pct.push_back(100.0 * std::abs(*run->measured.contact_time - tau) / tau);
          if (run->measured.contact_time_sigma > 0.0) {
            f.contact_pull.push_back((*run->measured.contact_time - tau) /
                                     run->measured.contact_time_sigma);
          }
          if (worst > 0) {
            fmt::print(stderr, "  {} seed {} run {} contact: {:+.4f} % (sigma {:.4f} %)\n", style,
                       synth.seed, run->id, 100.0 * (*run->measured.contact_time - tau) / tau,
                       100.0 * run->measured.contact_time_sigma / tau);
          }
        }
      }
    }
    fmt::print(
        "| {} | {}/{} | {:.4f} | {:.4f} | {:.4f} | {:+.4f} | {:.2f} ({:.0f} %, {:.0f} %) | {:.3f} "
        "| {:.3f} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {}/{} | {}/{} | {:.2f} | {:.2f} | {:.2f} "
        "| {:.2f} | {:.2f} | {:.2f} | {:.3f} |\n",
        style, f.ok, f.runs, Percentile(f.xmax_error_pct, 0.5), Percentile(f.xmax_error_pct, 0.95),
        Percentile(f.xmax_error_pct, 1.0), Percentile(f.xmax_gain_error_pct, 0.5), Rms(f.xmax_pull),
        100.0 * ShareWithin(f.xmax_pull, 1.0), 100.0 * ShareWithin(f.xmax_pull, 2.0),
        Percentile(f.contact_error_pct, 0.5), Percentile(f.contact_error_pct, 1.0),
        Rms(f.contact_pull), Percentile(f.duration_error_ms, 0.5), Rms(f.duration_pull),
        Rms(f.peak_time_pull), f.flagged, f.rebounds, f.disturbed_flagged, f.disturbed,
        f.decode_s / seeds, f.reduce_s / seeds, f.reduce_s / std::max(f.decode_s, 1e-9),
        f.stages.load / seeds, f.stages.calibrate / seeds, f.stages.extract / seeds,
        f.stages.fit / seeds);
    std::fflush(stdout);
    const auto share = [](int flagged, int of) {
      return of == 0 ? std::string("—")
                     : fmt::format("{}/{} ({:.0f} %)", flagged, of, 100.0 * flagged / of);
    };
    std::string row = fmt::format("| {} | {} |", style, share(f.rises_flagged, f.rises));
    for (std::size_t b = 0; b < f.off_count.size(); ++b) {
      row += fmt::format(" {} |", share(f.off_flagged[b], f.off_count[b]));
    }
    detection.push_back(row);
    std::sort(f.worst.begin(), f.worst.end(),
              [](const XmaxError& a, const XmaxError& b) { return a.pct > b.pct; });
    for (int i = 0; i < worst && i < static_cast<int>(f.worst.size()); ++i) {
      fmt::print(stderr, "  {} seed {} run {} rebound {}: {:.4f} % of X0\n", style,
                 1000 + f.worst[i].seed, f.worst[i].run, f.worst[i].rebound, f.worst[i].pct);
    }
  }
  // Flagged among the rebounds the truth says were disturbed, by how much.
  fmt::print(
      "\n| style | flagged / true maxima above their predecessor | flagged / true durations off "
      "the half period by < 2 ms | 2–5 ms | 5–10 ms | 10–20 ms | > 20 ms |\n"
      "|---|---|---|---|---|---|---|\n");
  for (const std::string& row : detection) fmt::print("{}\n", row);
  std::filesystem::remove_all(scratch);
  return 0;
}
