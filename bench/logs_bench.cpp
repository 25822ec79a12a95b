// Benchmark and stress test of the log stage (docs/logs.md, "Benchmarks"):
//   1. Monte-Carlo RMSE of the damped-mode fit's frequency and damping ratio,
//      and of the FFT peak's frequency, against the Cramér-Rao bound, versus
//      SNR, record length and sampling rate;
//   2. noise-free bias of both, in bins;
//   3. the impact instant's error on `synth-logs` sessions (the two-link arm),
//      in samples;
//   4. throughput: reading (rows and values per second), spectra (samples per
//      second), and a whole AnalyseLog on a long log with its peak memory.
//
//   bench_logs [--trials 200] [--rows 10000000] [--quick]
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/log_reader.h"
#include "io/manifest.h"
#include "signal/cramer_rao.h"
#include "signal/damped_modes.h"
#include "signal/log_analysis.h"
#include "signal/spectrum.h"
#include "synth/arm_logs.h"

namespace {

using namespace impactlab;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// CPU time of this process, s: "per core" rates must not count the time the
// shared machine gave to others.
double CpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

struct Case {
  double snr_db, rate_hz;
  std::size_t samples;
};

std::vector<double> Samples(const DampedCosine& s, double rate_hz, std::size_t n) {
  std::vector<double> y(n);
  const double omega = kTwoPi * s.frequency_hz;
  const double sigma = omega * s.damping_ratio / std::sqrt(1.0 - s.damping_ratio * s.damping_ratio);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    y[i] = s.amplitude * std::exp(-sigma * t) * std::cos(omega * t + s.phase_rad);
  }
  return y;
}

// Table 1: one row per case.
void CrbRow(const Case& c, int trials, std::mt19937_64& engine) {
  const double f = 11.5, zeta = 0.02, amplitude = 1.0;
  const double eta = std::pow(10.0, c.snr_db / 10.0);
  const double noise = amplitude / std::sqrt(2.0 * eta);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> phase(-std::numbers::pi, std::numbers::pi);
  double e2f = 0, e2z = 0, biasf = 0, e2fft = 0, crb_f = 0, crb_z = 0, ms = 0;
  int failed = 0;
  for (int trial = 0; trial < trials; ++trial) {
    const DampedCosine signal{amplitude, phase(engine), f, zeta};
    std::vector<double> y = Samples(signal, c.rate_hz, c.samples);
    for (double& v : y) v += noise * normal(engine);
    const CramerRaoBound bound = DampedCosineCrb(signal, c.rate_hz, c.samples, noise);
    crb_f += bound.frequency_hz * bound.frequency_hz;
    crb_z += bound.damping_ratio * bound.damping_ratio;
    const DampedModeFit fit = FitDampedModes(y, c.rate_hz, {});
    ms += fit.fit_ms;
    if (!fit.ok || fit.modes.empty()) {
      ++failed;
      continue;
    }
    const double ef = fit.modes[0].frequency_hz.value - f;
    const double ez = fit.modes[0].damping_ratio.value - zeta;
    e2f += ef * ef;
    e2z += ez * ez;
    biasf += ef;
    SpectrumOptions spectrum;
    spectrum.detrend = Detrend::kMean;
    const Spectrum s = ComputeSpectrum(y, c.rate_hz, spectrum);
    const double eff = s.peaks.empty() ? 1.0 : s.peaks[0].frequency_hz - f;
    e2fft += eff * eff;
  }
  const int ok = trials - failed;
  const double rf = std::sqrt(e2f / ok), rz = std::sqrt(e2z / ok);
  const double bf = std::sqrt(crb_f / trials), bz = std::sqrt(crb_z / trials);
  fmt::print(
      "| {:6.0f} | {:7.0f} | {:6d} | {:9.3g} | {:6.2f} | {:9.3g} | {:6.2f} | {:+6.2f} | {:8.2f} | "
      "{:5.1f} | {:3d} |\n",
      c.snr_db, c.rate_hz, c.samples, bf, rf / bf, bz, rz / bz, biasf / ok / bf,
      std::sqrt(e2fft / ok) / bf, ms / trials, failed);
}

void CrbTables(int trials) {
  std::mt19937_64 engine(2024);
  fmt::print("\n## 1. Damped-mode fit against the Cramér–Rao bound\n\n");
  fmt::print(
      "f = 11.5 Hz, zeta = 0.02, A = 1, random phase; SNR = A^2 / (2 sigma^2) at the start;\n"
      "{} trials per row; fit = pencil + Ceres with the analysis defaults (2 modes, 2\n"
      "decays, offset); FFT = Hann, x8 padding, Newton on the DTFT.\n\n",
      trials);
  const char* header =
      "| SNR dB | rate Hz |      N | CRB f Hz  | f/CRB | CRB zeta  | zeta/CRB | bias f/CRB | FFT "
      "f/CRB | ms/fit | fail |\n"
      "|-------:|--------:|-------:|----------:|------:|----------:|---------:|-----------:|-------"
      "---:|-------:|-----:|\n";
  fmt::print("By SNR (rate 1000 Hz, N = 2000):\n\n{}", header);
  for (double snr : {0.0, 10.0, 20.0, 30.0, 40.0}) CrbRow({snr, 1000.0, 2000}, trials, engine);
  fmt::print("\nBy record length (SNR 20 dB, rate 1000 Hz):\n\n{}", header);
  for (std::size_t n : {250, 500, 1000, 2000, 4000}) CrbRow({20.0, 1000.0, n}, trials, engine);
  fmt::print("\nBy sampling rate (SNR 20 dB, 2 s):\n\n{}", header);
  for (double rate : {100.0, 250.0, 1000.0, 4000.0}) {
    CrbRow({20.0, rate, static_cast<std::size_t>(2.0 * rate)}, trials, engine);
  }
}

void BiasTable() {
  fmt::print("\n## 2. Noise-free bias, in bins (bin = rate / N)\n\n");
  fmt::print("| signal | N | worst FFT bias | worst fit bias |\n|---|---:|---:|---:|\n");
  const double rate = 1000.0;
  for (double zeta : {0.0, 0.02}) {
    for (std::size_t n : {512, 2000}) {
      const double bin = rate / static_cast<double>(n);
      double worst_fft = 0.0, worst_fit = 0.0;
      for (int k = 0; k < 20; ++k) {
        const double f = (20.0 + k * 0.05) * bin;
        const std::vector<double> y = Samples({1.0, 0.3 + k, f, zeta}, rate, n);
        SpectrumOptions spectrum;
        spectrum.detrend = Detrend::kMean;
        const Spectrum s = ComputeSpectrum(y, rate, spectrum);
        worst_fft = std::max(worst_fft, std::abs(s.peaks.at(0).frequency_hz - f) / bin);
        const DampedModeFit fit = FitDampedModes(y, rate, {});
        worst_fit = std::max(worst_fit, std::abs(fit.modes.at(0).frequency_hz.value - f) / bin);
      }
      fmt::print("| zeta = {} | {} | {:.2g} | {:.2g} |\n", zeta, n, worst_fft, worst_fit);
    }
  }
}

void ImpactTable(int seeds) {
  fmt::print("\n## 3. Impact instant on synth-logs sessions of the two-link arm (1 kHz)\n\n");
  fmt::print(
      "| noise x | logs | RMS error, samples | worst, samples | method "
      "|\n|---:|---:|---:|---:|---|\n");
  const fs::path root = fs::temp_directory_path() / fmt::format("impactlab-bench-{}", ::getpid());
  std::mt19937_64 engine(7);
  std::uniform_real_distribution<double> delay(0.0, 0.05);
  for (double noise : {1.0, 5.0, 20.0}) {
    double sum2 = 0.0, worst = 0.0;
    std::string method;
    for (int seed = 0; seed < seeds; ++seed) {
      ArmLogOptions options;
      options.seed = static_cast<std::uint64_t>(seed + 1);
      options.noise_factor = noise;
      options.duration_s = 3.0;
      options.experiment_start_delay_s += delay(engine);  // the impact anywhere in a sample
      const fs::path folder = root / fmt::format("n{}-s{}", noise, seed);
      const double impact_s = WriteTwoLinkSession(folder, ArmLogSession(options))
                                  .truth[options.log_id]["experiment"]["impact_time_s"];
      Log log = ReadManifest(folder).session.logs.at(0);
      log.simulation.reset();
      const LogAnalysis analysis = AnalyseLog(log, LogFileRecords(log, {}), {});
      const double error = analysis.experiment.impact.found
                               ? (analysis.experiment.impact.time_s.value - impact_s) * 1000.0
                               : 1e9;
      sum2 += error * error;
      worst = std::max(worst, std::abs(error));
      method = analysis.experiment.impact.method;
    }
    fmt::print("| {} | {} | {:.2f} | {:.2f} | {} |\n", noise, seeds, std::sqrt(sum2 / seeds), worst,
               method);
  }
  fs::remove_all(root);
}

// A long synthetic log: a joint turning, then an impact at `impact_s` with a
// ring-down at 11.5 Hz on the accelerometer; counts and volts as a logger writes.
void WriteLongLog(const fs::path& file, long long rows, double rate_hz, double impact_s) {
  std::ofstream out(file, std::ios::binary);
  out << "t,enc1,acc1,acc2\n";
  std::mt19937_64 engine(1);
  std::normal_distribution<double> normal;
  std::string buffer;
  const double sigma = kTwoPi * 11.5 * 0.02;
  for (long long i = 0; i < rows; ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    const double after = t - impact_s;
    const double angle = after < 0.0 ? 0.5 * t
                                     : 0.5 * impact_s + 0.002 * std::sin(kTwoPi * 11.5 * after) *
                                                            std::exp(-sigma * after);
    double a =
        after < 0.0 ? 0.0 : 30.0 * std::exp(-sigma * after) * std::cos(kTwoPi * 11.5 * after);
    if (after >= 0.0 && after < 1.0 / rate_hz) a += 300.0;  // the impulse's sample
    const double volts = a / kStandardGravity * 0.1 + 0.002 * normal(engine);
    fmt::format_to(std::back_inserter(buffer), "{:.7f},{},{:.5f},{:.5f}\n", t,
                   static_cast<long long>(std::floor(angle * 4096 * 50 / kTwoPi)), volts,
                   0.001 * normal(engine));
    if (buffer.size() > (1 << 22)) {
      out << buffer;
      buffer.clear();
    }
  }
  out << buffer;
}

void ThroughputTable(long long rows) {
  fmt::print("\n## 4. Throughput (one core)\n\n");
  const double rate = 100000.0, impact_s = 0.6 * static_cast<double>(rows) / rate;
  const fs::path file =
      fs::temp_directory_path() / fmt::format("impactlab-bench-{}.csv", ::getpid());
  auto started = Clock::now();
  WriteLongLog(file, rows, rate, impact_s);
  const double write_s = Seconds(started);
  const double mb = static_cast<double>(fs::file_size(file)) / 1e6;

  Log log;
  log.id = "long";
  log.experiment = file;
  log.time_column = "t";
  log.channels = {LogChannel{"q1", "enc1", 4096.0, 50.0, std::nullopt},
                  LogChannel{"a1", "acc1", std::nullopt, 1.0, 0.1},
                  LogChannel{"a2", "acc2", std::nullopt, 1.0, 0.005}};
  started = Clock::now();
  const double read_cpu = CpuSeconds();
  long long seen = 0;
  const LogReadReport report = ReadLogCsv(
      file, "t", log.channels, LogSource::kExperiment, {},
      [&](const LogBlock& block) { seen += static_cast<long long>(block.time_s.size()); });
  const double read_s = CpuSeconds() - read_cpu;
  const double read_wall_s = Seconds(started);
  fmt::print("CPU time of this process (wall time in brackets: the machine is shared).\n\n");
  fmt::print("| stage | size | CPU s [wall s] | rate per core |\n|---|---|---:|---|\n");
  fmt::print("| write the test log (not timed work) | {} rows, {:.0f} MB | {:.2f} | |\n", rows, mb,
             write_s);
  fmt::print(
      "| read (parse, convert, rules) | {} rows x 4 columns | {:.2f} [{:.2f}] | {:.1f} M rows/s, "
      "{:.1f} M values/s, {:.0f} MB/s |\n",
      report.samples, read_s, read_wall_s, seen / read_s / 1e6, 4.0 * seen / read_s / 1e6,
      mb / read_s);

  const double rss_before = PeakRssMb();
  started = Clock::now();
  const double analyse_cpu = CpuSeconds();
  const LogAnalysis analysis = AnalyseLog(log, LogFileRecords(log, {}), {});
  const double analyse_s = CpuSeconds() - analyse_cpu;
  const double analyse_wall_s = Seconds(started);
  fmt::print(
      "| AnalyseLog (2 passes, decimated x{}) | {} rows | {:.2f} [{:.2f}] | {:.1f} M rows/s; peak "
      "RSS {:.0f} MB (before: {:.0f} MB) |\n",
      analysis.experiment.decimation, rows, analyse_s, analyse_wall_s, rows / analyse_s / 1e6,
      PeakRssMb(), rss_before);
  if (analysis.ok) {
    const ChannelAnalysis& a1 = analysis.experiment.channels[1];
    fmt::print(
        "\nlong log: impact {:.6f} s (true {:.6f} s, {:+.2f} samples); a1 {:.5f} Hz, zeta {:.5f} "
        "(true 11.5, 0.02)\n",
        analysis.experiment.impact.time_s.value, impact_s,
        (analysis.experiment.impact.time_s.value - impact_s) * rate,
        a1.dominant_frequency_hz ? a1.dominant_frequency_hz->value : 0.0,
        a1.damping_ratio ? a1.damping_ratio->value : 0.0);
    for (const std::string& note : a1.notes) fmt::print("  a1: {}\n", note);
  } else {
    fmt::print("\nlong log failed: {}\n", analysis.reason);
  }
  fmt::print("\n| stage | size | CPU s (median) | rate per core |\n|---|---|---:|---|\n");
  for (std::size_t n : {std::size_t{1} << 16, std::size_t{1} << 20, std::size_t{1} << 22}) {
    std::vector<double> y = Samples({1.0, 0.0, 123.4, 0.0}, 10000.0, n);
    std::mt19937_64 engine(3);
    std::normal_distribution<double> normal;
    for (double& v : y) v += 0.1 * normal(engine);
    // One warm-up call (the workspace grows to this size), then the median
    // of the timed calls: the machine is shared.
    if (ComputeSpectrum(y, 10000.0, {}).peaks.empty()) std::abort();
    std::vector<double> times;
    started = Clock::now();
    while (Seconds(started) < 2.0 || times.size() < 3) {
      const double call = CpuSeconds();
      if (ComputeSpectrum(y, 10000.0, {}).peaks.empty()) std::abort();
      times.push_back(CpuSeconds() - call);
    }
    std::nth_element(times.begin(), times.begin() + static_cast<std::ptrdiff_t>(times.size() / 2),
                     times.end());
    const double per = times[times.size() / 2];
    fmt::print(
        "| spectrum (Hann, padding, Welch, peaks, DTFT refine) | {} samples | {:.4f} | {:.1f} M "
        "samples/s |\n",
        n, per, static_cast<double>(n) / per / 1e6);
  }

  fs::remove(file);
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 200;
  long long rows = 10'000'000;
  int seeds = 20;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--trials" && i + 1 < argc)
      trials = std::atoi(argv[++i]);
    else if (arg == "--rows" && i + 1 < argc)
      rows = std::atoll(argv[++i]);
    else if (arg == "--quick") {
      trials = 30;
      rows = 1'000'000;
      seeds = 5;
    } else {
      std::fprintf(stderr, "usage: bench_logs [--trials N] [--rows N] [--quick]\n");
      return 2;
    }
  }
  fmt::print("# impactlab log stage benchmark\n");
  CrbTables(trials);
  BiasTable();
  ImpactTable(seeds);
  ThroughputTable(rows);
  return 0;
}
