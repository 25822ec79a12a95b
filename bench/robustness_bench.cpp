// Robustness over randomised photos (docs/benchmarks.md, "Robustness"):
// sessions in the randomised style (render/randomised_style.cpp, every factor
// of the look drawn per photo from wide ranges) are generated, reduced as
// bench_reduce does, and scored against the generator's truth: overall, then
// per factor of the look (terciles of a number, or its categories), so that
// one sees which factor breaks what, then the failures grouped by message.
//
//   bench_robustness [--photos 204] [--seed 1] [--jobs 2] [--per-photo]
//                    [--only SEED,...] [--keep DIR]
//
// A session is the quick preset (two runs; a run photo and two calibration
// photos each). A calibration photo that fails is charged to itself, and its
// run's photo counts as not reached; a run that fails otherwise is charged to
// its run photo. Accuracy (Xmax, contact time, pulls) belongs to run photos.
// A run photo that reduced without its contact time (its contact trace not
// read: the run's maxima stand, a warning says why) counts as reduced, its
// contact time as lost: counted and grouped by the warning's reason.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <unistd.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bench/bench_support.h"
#include "io/manifest.h"
#include "pipeline/process_memory.h"
#include "pipeline/reduce.h"
#include "synth/session_generator.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A rebound is expected on the photo when its peak and a quarter swing after
// it (about 0.19 s) are on the slow sweep, which ends 4.9 s after release.
constexpr double kSweepEndS = 4.9;
constexpr double kFlankS = 0.2;

enum class Outcome { kOk, kFailed, kNotReached };

struct PhotoRecord {
  std::uint64_t seed = 0;
  std::string id;          // run id, or calibration id
  bool run_photo = false;  // else a calibration photo
  json look;               // the truth's "look"
  Outcome outcome = Outcome::kNotReached;
  std::string failure;
  // Run photos that reduced: per expected rebound, error in % of X0 and pull.
  std::vector<double> xmax_error_pct, xmax_pull;
  int rebounds_missed = 0;
  std::optional<double> contact_error_pct, contact_pull;
  // A run that reduced without the contact time its truth has: why (the
  // run's warning naming its contact trace, or that none does).
  std::optional<std::string> contact_lost;
};

// Percentile, but "no data" where there is none (bench_support's says 0).
double Quantile(const std::vector<double>& v, double p) {
  return v.empty() ? NAN : Percentile(v, p);
}

// Scores one reduced session against its truth: one record per photo.
std::vector<PhotoRecord> Score(std::uint64_t seed, const json& truth, const SessionResult& result) {
  std::map<std::string, json> calibration_looks;
  for (const json& c : truth["calibrations"]) {
    if (c.contains("photo")) calibration_looks[c["id"]] = c["photo"]["look"];
  }
  std::vector<PhotoRecord> records;
  for (const json& t : truth["runs"]) {
    if (t["form"] != "photo") continue;
    const RunResult* run = result.FindRun(t["id"].get<std::string>());
    const std::string id = t["id"];
    PhotoRecord photo;
    photo.seed = seed;
    photo.id = id;
    photo.run_photo = true;
    photo.look = t["photo"]["look"];
    // Its calibrations: failed when the run's failure names their photo, or
    // a warning does (a calibration the run failed before it asked for).
    bool calibrations_ok = true;
    for (const std::string cell : {"R-", "L-"}) {
      PhotoRecord cal;
      cal.seed = seed;
      cal.id = cell + id;
      cal.look = calibration_looks[cell + id];
      cal.outcome = Outcome::kOk;
      const std::string photo_path = "calibration/" + cell + id + ".";
      if (run != nullptr && !run->ok && run->reason.find(photo_path) != std::string::npos) {
        cal.outcome = Outcome::kFailed;
        cal.failure = run->reason;
        calibrations_ok = false;
      }
      for (const std::string& w : result.warnings) {
        if (cal.outcome != Outcome::kOk || w.find(photo_path) == std::string::npos) continue;
        cal.outcome = Outcome::kFailed;
        cal.failure = w;
      }
      records.push_back(std::move(cal));
    }
    if (run == nullptr) {
      photo.outcome = Outcome::kFailed;
      photo.failure = "the run is missing from the results";
    } else if (!run->ok) {
      photo.outcome = calibrations_ok ? Outcome::kFailed : Outcome::kNotReached;
      photo.failure = run->reason;
    } else {
      photo.outcome = Outcome::kOk;
      const double x0 = t["initial_displacement"];
      const json& xmax = t["rebounds"]["xmax"];
      const json& t_peak = t["rebounds"]["t_peak"];
      for (std::size_t n = 0; n < xmax.size(); ++n) {
        if (t_peak[n].get<double>() + kFlankS > kSweepEndS) break;
        if (n >= run->measured.xmax.size()) {
          ++photo.rebounds_missed;
          continue;
        }
        const double error = run->measured.xmax[n] - xmax[n].get<double>();
        photo.xmax_error_pct.push_back(100.0 * std::abs(error) / x0);
        if (run->measured.xmax_sigma[n] > 0.0)
          photo.xmax_pull.push_back(error / run->measured.xmax_sigma[n]);
      }
      if (run->measured.contact_time) {
        const double tau = t["contact"]["duration_s"];
        const double error = *run->measured.contact_time - tau;
        photo.contact_error_pct = 100.0 * std::abs(error) / tau;
        if (run->measured.contact_time_sigma > 0.0)
          photo.contact_pull = error / run->measured.contact_time_sigma;
      } else if (t.contains("contact")) {
        // Lost: never scored as ok silently. The warning names the run's
        // contact trace (pipeline/trace_run.h).
        const std::string key = fmt::format("run \"{}\".traces.contact", id);
        photo.contact_lost = "no warning says why";
        for (const std::string& w : result.warnings) {
          if (w.find(key) != std::string::npos) photo.contact_lost = w;
        }
      }
    }
    records.push_back(std::move(photo));
  }
  return records;
}

// What a group of photos achieved.
struct Figures {
  int ok = 0, failed = 0, not_reached = 0, missed = 0, contact_lost = 0;
  std::vector<double> xmax_error, xmax_pull, contact_error, contact_pull;

  void Add(const PhotoRecord& r) {
    if (r.outcome == Outcome::kOk) ++ok;
    if (r.outcome == Outcome::kFailed) ++failed;
    if (r.outcome == Outcome::kNotReached) ++not_reached;
    missed += r.rebounds_missed;
    if (r.contact_lost) ++contact_lost;
    xmax_error.insert(xmax_error.end(), r.xmax_error_pct.begin(), r.xmax_error_pct.end());
    xmax_pull.insert(xmax_pull.end(), r.xmax_pull.begin(), r.xmax_pull.end());
    if (r.contact_error_pct) contact_error.push_back(*r.contact_error_pct);
    if (r.contact_pull) contact_pull.push_back(*r.contact_pull);
  }
  double SuccessPct() const { return ok + failed > 0 ? 100.0 * ok / (ok + failed) : NAN; }
};

// A factor's bins: a number's terciles over the photos that have it, or its categories.
struct FactorBins {
  std::string name;
  std::vector<std::string> labels;
  std::vector<Figures> figures;
  double spread = 0.0;  // largest difference of success rates between bins, %
};

std::string Format(double v) {
  if (std::isnan(v)) return "—";
  const double a = std::abs(v);
  return a >= 100 ? fmt::format("{:.0f}", v)
         : a >= 1 ? fmt::format("{:.2f}", v)
                  : fmt::format("{:.3g}", v);
}

FactorBins BinFactor(const std::string& name, const std::vector<PhotoRecord>& records) {
  FactorBins bins;
  bins.name = name;
  std::vector<double> values;
  bool categorical = false;
  for (const PhotoRecord& r : records) {
    if (!r.look.contains(name)) continue;
    if (r.look[name].is_string()) categorical = true;
    if (r.look[name].is_number()) values.push_back(r.look[name].get<double>());
  }
  if (categorical) {
    std::map<std::string, Figures> by;
    for (const PhotoRecord& r : records) {
      if (r.look.contains(name) && r.look[name].is_string()) by[r.look[name]].Add(r);
    }
    for (auto& [label, f] : by) {
      bins.labels.push_back(label);
      bins.figures.push_back(f);
    }
  } else {
    std::sort(values.begin(), values.end());
    const auto zeros = std::count(values.begin(), values.end(), 0.0);
    std::vector<double> distinct = values;
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    if (zeros * 7 > static_cast<long>(values.size()) && distinct.size() > 4) {
      // Often exactly 0 (none: lossless, no glare, no tilt), at least 1 in
      // 7: that bin, then the halves of the rest.
      const std::vector<double> rest(values.begin() + zeros, values.end());
      const double half = Percentile(rest, 0.5);
      bins.labels = {"0", fmt::format("≤ {}", Format(half)), fmt::format("> {}", Format(half))};
      bins.figures.resize(3);
      for (const PhotoRecord& r : records) {
        if (!r.look.contains(name)) continue;
        const double v = r.look[name].get<double>();
        bins.figures[v == 0.0 ? 0 : v <= half ? 1 : 2].Add(r);
      }
    } else if (distinct.size() <= 4) {
      values = distinct;
      // Few distinct values (bit depth, counts): one bin each.
      for (const double v : values) {
        bins.labels.push_back(Format(v));
        bins.figures.emplace_back();
      }
      for (const PhotoRecord& r : records) {
        if (!r.look.contains(name)) continue;
        const auto at = std::find(values.begin(), values.end(), r.look[name].get<double>());
        bins.figures[at - values.begin()].Add(r);
      }
    } else {
      const double t1 = Percentile(values, 1.0 / 3), t2 = Percentile(values, 2.0 / 3);
      bins.labels = {fmt::format("< {}", Format(t1)),
                     fmt::format("{} – {}", Format(t1), Format(t2)),
                     fmt::format("> {}", Format(t2))};
      bins.figures.resize(3);
      for (const PhotoRecord& r : records) {
        if (!r.look.contains(name)) continue;
        const double v = r.look[name].get<double>();
        bins.figures[v < t1 ? 0 : v <= t2 ? 1 : 2].Add(r);
      }
    }
  }
  double lo = 100.0, hi = 0.0;
  for (const Figures& f : bins.figures) {
    if (f.ok + f.failed < 3) continue;  // too few to say
    lo = std::min(lo, f.SuccessPct());
    hi = std::max(hi, f.SuccessPct());
  }
  bins.spread = std::max(0.0, hi - lo);
  return bins;
}

// A failure message without the file it names, paths and numbers, so that
// like ones group whichever photo they came from.
std::string FailureKind(const std::string& message) {
  std::string kind = std::regex_replace(message, std::regex(R"(^[^ ]*\.(jpg|png|tif|toml): )"), "");
  kind = std::regex_replace(kind, std::regex(R"([^ "']*/)"), "");
  kind = std::regex_replace(kind, std::regex(R"(-?[0-9]+(\.[0-9]+)?(e-?[0-9]+)?)"), "#");
  return kind.size() > 160 ? kind.substr(0, 160) + "…" : kind;
}

void PrintOverall(const std::vector<PhotoRecord>& records, double seconds) {
  Figures all, runs, calibrations;
  for (const PhotoRecord& r : records) {
    all.Add(r);
    (r.run_photo ? runs : calibrations).Add(r);
  }
  fmt::print("## Overall\n\n");
  fmt::print(
      "| photos | run photos reduced | calibration photos read | success rate | "
      "rebounds missed | Xmax err % X0 median / p95 / max | Xmax pull RMS (n; within "
      "1σ, 2σ) | contact err % median / worst | contact pull RMS (n; within 1σ, 2σ) | "
      "contact times lost | s per photo |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|---|\n");
  fmt::print(
      "| {} | {}/{} ({} not reached) | {}/{} | {:.1f} % | {} | {} / {} / {} | {} ({}; {:.0f} %, "
      "{:.0f} %) | {} / {} | {} ({}; {:.0f} %, {:.0f} %) | {} | {:.2f} |\n\n",
      records.size(), runs.ok, runs.ok + runs.failed + runs.not_reached, runs.not_reached,
      calibrations.ok, calibrations.ok + calibrations.failed, all.SuccessPct(), all.missed,
      Format(Quantile(all.xmax_error, 0.5)), Format(Quantile(all.xmax_error, 0.95)),
      Format(Quantile(all.xmax_error, 1.0)), Format(Rms(all.xmax_pull)), all.xmax_pull.size(),
      100 * ShareWithin(all.xmax_pull, 1), 100 * ShareWithin(all.xmax_pull, 2),
      Format(Quantile(all.contact_error, 0.5)), Format(Quantile(all.contact_error, 1.0)),
      Format(Rms(all.contact_pull)), all.contact_pull.size(),
      100 * ShareWithin(all.contact_pull, 1), 100 * ShareWithin(all.contact_pull, 2),
      runs.contact_lost, seconds / std::max<std::size_t>(1, records.size()));
}

void PrintFactors(const std::vector<PhotoRecord>& records) {
  std::set<std::string> names;
  for (const PhotoRecord& r : records) {
    for (const auto& [name, value] : r.look.items()) {
      // Arrays (band positions) and the chopper's phase say nothing binned.
      if ((value.is_number() || value.is_string()) && name != "chop_phase_div") names.insert(name);
    }
  }
  std::vector<FactorBins> factors;
  for (const std::string& name : names) factors.push_back(BinFactor(name, records));
  // The factors whose bins differ most in success first: what breaks most.
  std::stable_sort(factors.begin(), factors.end(),
                   [](const FactorBins& a, const FactorBins& b) { return a.spread > b.spread; });
  fmt::print("## Per factor (success over all photos; accuracy over run photos)\n\n");
  fmt::print(
      "| factor | bin | photos | success % | Xmax err median % X0 | p95 | Xmax pull RMS | "
      "missed | contact err median % | contact pull RMS |\n");
  fmt::print("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const FactorBins& bins : factors) {
    for (std::size_t i = 0; i < bins.labels.size(); ++i) {
      const Figures& f = bins.figures[i];
      fmt::print("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", i == 0 ? bins.name : "",
                 bins.labels[i], f.ok + f.failed, Format(f.SuccessPct()),
                 Format(Quantile(f.xmax_error, 0.5)), Format(Quantile(f.xmax_error, 0.95)),
                 Format(Rms(f.xmax_pull)), f.missed, Format(Quantile(f.contact_error, 0.5)),
                 Format(Rms(f.contact_pull)));
    }
  }
  fmt::print("\n");
}

// The failures (or, `contact_lost`, the contact times lost by runs that
// reduced), grouped by message.
void PrintFailures(const std::vector<PhotoRecord>& records, bool contact_lost) {
  std::map<std::string, std::pair<int, std::string>> kinds;  // kind -> count, an example photo
  for (const PhotoRecord& r : records) {
    if (contact_lost ? !r.contact_lost : r.outcome != Outcome::kFailed) continue;
    auto& [count, example] = kinds[FailureKind(contact_lost ? *r.contact_lost : r.failure)];
    if (count++ == 0) example = fmt::format("seed {} {}", r.seed, r.id);
  }
  std::vector<std::pair<int, std::string>> sorted;
  for (const auto& [kind, entry] : kinds) sorted.push_back({entry.first, kind});
  std::sort(sorted.rbegin(), sorted.rend());
  fmt::print("## {}, grouped (numbers as #)\n\n| photos | {} | e.g. |\n|---|---|---|\n",
             contact_lost ? "Contact times lost (the runs reduced)" : "Failures",
             contact_lost ? "why" : "failure");
  for (const auto& [count, kind] : sorted) {
    std::string cell = kind;
    std::replace(cell.begin(), cell.end(), '|', '/');
    fmt::print("| {} | {} | {} |\n", count, cell, kinds[kind].second);
  }
  fmt::print("\n");
}

}  // namespace
}  // namespace impactlab

int main(int argc, char** argv) {
  using namespace impactlab;
  KeepFreedMemoryForReuse();
  HeapInHugePages();
  CLI::App app{"Robustness of the reduction over randomised photos, per factor of their look"};
  int photos = 204, jobs = 2;
  std::uint64_t seed = 1;
  bool per_photo = false;
  std::vector<std::uint64_t> only;
  std::string keep;
  app.add_option("--photos", photos, "At least this many photos (6 per session)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  app.add_option("--seed", seed, "Sessions use seeds 1000 seed + 1, + 2, ...")
      ->capture_default_str();
  app.add_option("--jobs", jobs, "Sessions generated and reduced at once")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  app.add_flag("--per-photo", per_photo, "A line per photo on stderr: its outcome and errors");
  app.add_option("--only", only, "Only these sessions' seeds (e.g. 1027,1028), not --photos'")
      ->delimiter(',');
  app.add_option("--keep", keep,
                 "Keep each session's folder and truth here (DIR/sSEED), to reduce or digitize "
                 "it again");
  CLI11_PARSE(app, argc, argv);

  constexpr int kPhotosPerSession = 6;
  std::vector<std::uint64_t> seeds = only;
  if (seeds.empty()) {
    for (int i = 0; i < (photos + kPhotosPerSession - 1) / kPhotosPerSession; ++i) {
      seeds.push_back(1000 * seed + static_cast<std::uint64_t>(i) + 1);
    }
  }
  const int sessions = static_cast<int>(seeds.size());
  // One folder per process: two benchmarks at once must not share sessions.
  const fs::path scratch =
      keep.empty()
          ? fs::temp_directory_path() / fmt::format("impactlab-bench-robustness-{}", ::getpid())
          : fs::path(keep);
  std::vector<PhotoRecord> records;
  std::mutex mutex;
  std::atomic<int> next{0};
  const auto start = std::chrono::steady_clock::now();
  auto work = [&] {
    for (int i = next++; i < sessions; i = next++) {
      SynthOptions synth;
      synth.preset = "quick";
      synth.style = PhotoStyle::kRandomised;
      synth.seed = seeds[static_cast<std::size_t>(i)];
      const fs::path folder = scratch / fmt::format("s{}", synth.seed);
      std::vector<PhotoRecord> scored;
      try {
        const SynthSummary summary = GenerateSession(folder, synth);
        if (!keep.empty()) {
          std::ofstream(scratch / fmt::format("s{}.truth.json", synth.seed))
              << summary.truth.dump(1);
        }
        ReduceOptions options;
        options.products = Products::kRebounds;  // the maxima and contact times; no fits
        const SessionResult result = ReduceSession(ReadManifest(folder).session, options);
        scored = Score(synth.seed, summary.truth, result);
      } catch (const std::exception& error) {
        fmt::print(stderr, "seed {}: the session failed as a whole: {}\n", synth.seed,
                   error.what());
      }
      if (keep.empty()) fs::remove_all(folder);
      std::lock_guard lock(mutex);
      for (PhotoRecord& r : scored) {
        if (per_photo) {
          fmt::print(stderr, "seed {} {} {}: {} {}\n", r.seed, r.run_photo ? "run" : "calibration",
                     r.id,
                     r.outcome == Outcome::kOk       ? "ok"
                     : r.outcome == Outcome::kFailed ? "FAILED"
                                                     : "not reached",
                     r.outcome == Outcome::kOk
                         ? fmt::format("Xmax err max {} % X0, missed {}{}",
                                       Format(Quantile(r.xmax_error_pct, 1.0)), r.rebounds_missed,
                                       r.contact_error_pct
                                           ? fmt::format(", contact err {} %, pull {}",
                                                         Format(*r.contact_error_pct),
                                                         r.contact_pull ? Format(*r.contact_pull)
                                                                        : std::string("—"))
                                       : r.contact_lost ? ", contact time LOST: " + *r.contact_lost
                                                        : std::string())
                         : r.failure);
        }
        records.push_back(std::move(r));
      }
    }
  };
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(work);
  for (std::thread& t : threads) t.join();
  if (keep.empty()) fs::remove_all(scratch);
  const double seconds = Seconds(start);

  fmt::print("# bench_robustness: {} sessions (seeds {}..{}), {} photos, {:.0f} s with {} jobs\n\n",
             sessions, seeds.front(), seeds.back(), records.size(), seconds, jobs);
  PrintOverall(records, seconds * jobs);
  PrintFactors(records);
  PrintFailures(records, false);
  PrintFailures(records, true);
  return 0;
}
