// Least-squares fit benchmark: parameter recovery and wall time per fit for
// the Kelvin-Voigt and Poynting-Thomson least-squares fits, on data generated
// by the project's own models (thesis bar and pendulum). A plain program that
// prints tables; docs/fitting.md quotes its output.
//
// Targets: Kelvin-Voigt well under 1 ms per run, Poynting-Thomson under 20 ms.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "fit/kelvin_voigt_least_squares.h"
#include "fit/poynting_thomson_least_squares.h"
#include "model/kelvin_voigt.h"
#include "model/poynting_thomson.h"
#include "model/rebound_history.h"

namespace {

using namespace impactlab;

constexpr double kG = 385.644;   // in/s^2
const double kMass = 2.23 / kG;  // lbf s^2/in
const Pendulum kExact{22.0, kG, PendulumConvention::kExact};
const Pendulum kThesis{22.0, kG, PendulumConvention::kThesis};

// Median wall time of `f` in microseconds over `reps` calls (after one warm-up).
double MedianMicros(const std::function<void()>& f, int reps) {
  f();
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto start = std::chrono::steady_clock::now();
    f();
    t.push_back(std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
                    .count());
  }
  std::nth_element(t.begin(), t.begin() + reps / 2, t.end());
  return t[static_cast<std::size_t>(reps / 2)];
}

double Rel(double got, double want) { return std::abs(got / want - 1.0); }

ReboundMeasurements Measure(const ReboundSequence& seq, int count, double sigma) {
  ReboundMeasurements m;
  m.xmax.assign(seq.xmax.begin() + 1, seq.xmax.begin() + 1 + count);
  m.xmax_sigma.assign(static_cast<std::size_t>(count), sigma);
  m.contact_time = seq.contact.contact_time;
  m.contact_time_sigma = 1e-6;
  return m;
}

void KelvinVoigtTable() {
  fmt::print("Kelvin-Voigt least squares (K = 462000 lbf/in, C = 9 lbf s/in, release 0.5 in)\n");
  fmt::print("{:<34} {:>6} {:>11} {:>11} {:>11} {:>10} {:>9}\n", "case", "maxima", "rel err zeta",
             "rel err K", "rel err C", "time us", "iters");
  const KelvinVoigt truth{kMass, 462000.0, 9.0};
  for (const auto& [name, pendulum] :
       {std::pair{"exact pendulum", kExact}, std::pair{"thesis pendulum", kThesis}}) {
    for (const Separation sep : {Separation::kKinematic, Separation::kForce}) {
      for (const int count : {4, 8, 16}) {
        const ReboundSequence seq =
            SimulateRebounds(pendulum, KelvinVoigtContactLaw(truth, sep), 0.5, count + 1);
        const ReboundMeasurements m = Measure(seq, count, 1e-3);
        KelvinVoigtLeastSquaresOptions options;
        options.separation = sep;
        KelvinVoigtLeastSquaresFit fit;
        const double us = MedianMicros(
            [&] { fit = FitKelvinVoigtLeastSquares(pendulum, kMass, m, options); }, 200);
        fmt::print("{:<34} {:>6} {:>11.2e} {:>11.2e} {:>11.2e} {:>10.1f} {:>9}\n",
                   fmt::format("{}, {}", name, SeparationName(sep)), count,
                   Rel(fit.damping_ratio.value, RatesOf(truth).damping_ratio),
                   Rel(fit.stiffness->value, truth.stiffness),
                   Rel(fit.damping->value, truth.damping), us, fit.status.iterations);
      }
    }
  }
  // Noise: RMS error over the reported sigma (1 means the sigmas are right).
  const ReboundSequence seq =
      SimulateRebounds(kExact, KelvinVoigtContactLaw(truth, Separation::kKinematic), 0.5, 9);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 1.0);
  double sum_zeta = 0.0, sum_k = 0.0;
  int inside = 0;
  const int reps = 1000;
  for (int rep = 0; rep < reps; ++rep) {
    ReboundMeasurements m = Measure(seq, 8, 2e-3);
    for (double& x : m.xmax) x += 2e-3 * noise(rng);
    *m.contact_time += 1e-6 * noise(rng);
    const KelvinVoigtLeastSquaresFit fit = FitKelvinVoigtLeastSquares(kExact, kMass, m, {});
    const double ez =
        (fit.damping_ratio.value - RatesOf(truth).damping_ratio) / fit.damping_ratio.sigma;
    const double ek = (fit.stiffness->value - truth.stiffness) / fit.stiffness->sigma;
    sum_zeta += ez * ez;
    sum_k += ek * ek;
    inside += std::abs(ez) <= 1.0;
  }
  fmt::print(
      "noise 2e-3 in on 8 maxima, 1 us on tau_c, {} fits: RMS(err/sigma) zeta {:.3f}, K {:.3f}; "
      "zeta within 1 sigma {:.1f} %\n\n",
      reps, std::sqrt(sum_zeta / reps), std::sqrt(sum_k / reps), 100.0 * inside / reps);
}

std::vector<PoyntingThomsonRun> PtRuns(const PoyntingThomson& truth, Separation sep,
                                       const std::vector<double>& releases, bool tau, bool peak) {
  const PoyntingThomsonContactLaw law(truth, sep);
  std::vector<PoyntingThomsonRun> runs;
  for (std::size_t r = 0; r < releases.size(); ++r) {
    const ReboundSequence seq = SimulateRebounds(kExact, law, releases[r], 7);
    PoyntingThomsonRun run;
    run.name = fmt::format("run{}", r);
    run.pendulum = kExact;
    run.measured = Measure(seq, 6, 1e-3);
    if (!tau) run.measured.contact_time.reset();
    if (peak) {
      run.peak_compression =
          PeakCompressionMeasurement{0, law.Respond(seq.impact_speed[1]).peak_compression, 1e-6};
    }
    runs.push_back(run);
  }
  return runs;
}

void PoyntingThomsonTable() {
  fmt::print(
      "Poynting-Thomson least squares (truth K1 = 3e5, K2 = 2.5e5 lbf/in, C = 9 lbf s/in)\n");
  fmt::print("{:<44} {:>5} {:>10} {:>10} {:>10} {:>9} {:>6} {:>5}\n", "data", "rank", "rel err K1",
             "rel err K2", "rel err C", "time ms", "iters", "ok");
  const PoyntingThomson truth{kMass, 3.0e5, 2.5e5, 9.0};
  struct Case {
    std::string name;
    std::vector<double> releases;
    bool tau, peak;
    Separation sep;
  };
  const std::vector<Case> cases = {
      {"1 run: maxima + tau_c + peak, kinematic", {0.4}, true, true, Separation::kKinematic},
      {"1 run: maxima + tau_c + peak, force", {0.4}, true, true, Separation::kForce},
      {"3 runs: maxima + tau_c + peak, force", {0.2, 0.4, 0.7}, true, true, Separation::kForce},
      {"1 run: maxima only, force", {0.4}, false, false, Separation::kForce},
      {"3 runs: maxima + tau_c, kinematic", {0.2, 0.4, 0.7}, true, false, Separation::kKinematic},
  };
  for (const Case& c : cases) {
    const auto runs = PtRuns(truth, c.sep, c.releases, c.tau, c.peak);
    PoyntingThomsonLeastSquaresOptions options;
    options.mass = kMass;
    options.separation = c.sep;
    if (!c.tau) options.initial = PoyntingThomson{kMass, 2e5, 4e5, 12.0};
    PoyntingThomsonLeastSquaresFit fit;
    const double us =
        MedianMicros([&] { fit = FitPoyntingThomsonLeastSquares(runs, options); }, 21);
    fmt::print("{:<44} {:>5} {:>10.2e} {:>10.2e} {:>10.2e} {:>9.2f} {:>6} {:>5}\n", c.name,
               fit.identifiability.rank, Rel(fit.stiffness1.value, truth.stiffness1),
               Rel(fit.stiffness2.value, truth.stiffness2), Rel(fit.damping.value, truth.damping),
               us / 1000.0, fit.status.iterations, fit.ok ? "yes" : "no");
    if (!fit.ok) fmt::print("    -> {}\n", fit.reason);
  }
  // Far starts (factors of 100 on each parameter).
  fmt::print("\nstarted far away (1 run, maxima + tau_c + peak, force):\n");
  const auto runs = PtRuns(truth, Separation::kForce, {0.4}, true, true);
  for (const auto& f : std::vector<std::array<double, 3>>{{100, 0.01, 100},
                                                          {0.01, 100, 0.01},
                                                          {100, 100, 100},
                                                          {0.01, 0.01, 0.01},
                                                          {100, 1, 0.01}}) {
    PoyntingThomsonLeastSquaresOptions options;
    options.mass = kMass;
    options.separation = Separation::kForce;
    options.initial = PoyntingThomson{kMass, truth.stiffness1 * f[0], truth.stiffness2 * f[1],
                                      truth.damping * f[2]};
    const PoyntingThomsonLeastSquaresFit fit = FitPoyntingThomsonLeastSquares(runs, options);
    fmt::print(
        "  start x({:g}, {:g}, {:g}): {:<3} rel err K1 {:.1e} K2 {:.1e} C {:.1e}, chi2 {:.2e}, "
        "{} iterations, {:.2f} ms{}\n",
        f[0], f[1], f[2], fit.ok ? "ok" : "NOT", Rel(fit.stiffness1.value, truth.stiffness1),
        Rel(fit.stiffness2.value, truth.stiffness2), Rel(fit.damping.value, truth.damping),
        fit.chi2, fit.status.iterations, fit.status.seconds * 1e3,
        fit.ok ? "" : " (" + fit.reason + ")");
  }
  // Noise.
  const auto clean = PtRuns(truth, Separation::kForce, {0.3, 0.5}, true, true);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::array<double, 3> sum{};
  std::array<int, 3> inside{};
  const int reps = 300;
  PoyntingThomsonLeastSquaresOptions options;
  options.mass = kMass;
  options.separation = Separation::kForce;
  for (int rep = 0; rep < reps; ++rep) {
    auto noisy = clean;
    for (auto& run : noisy) {
      for (double& x : run.measured.xmax) x += 1e-3 * noise(rng);
      *run.measured.contact_time += 1e-6 * noise(rng);
      run.peak_compression->value += 1e-6 * noise(rng);
    }
    const PoyntingThomsonLeastSquaresFit fit = FitPoyntingThomsonLeastSquares(noisy, options);
    const std::array<double, 3> err = {
        (fit.stiffness1.value - truth.stiffness1) / fit.stiffness1.sigma,
        (fit.stiffness2.value - truth.stiffness2) / fit.stiffness2.sigma,
        (fit.damping.value - truth.damping) / fit.damping.sigma};
    for (std::size_t i = 0; i < 3; ++i) {
      sum[i] += err[i] * err[i];
      inside[i] += std::abs(err[i]) <= 1.0;
    }
  }
  fmt::print(
      "\nnoise (2 runs; 1e-3 in maxima, 1 us tau_c, 1e-6 in peak), {} fits: RMS(err/sigma) "
      "K1 {:.3f} K2 {:.3f} C {:.3f}; within 1 sigma {:.1f} / {:.1f} / {:.1f} %\n\n",
      reps, std::sqrt(sum[0] / reps), std::sqrt(sum[1] / reps), std::sqrt(sum[2] / reps),
      100.0 * inside[0] / reps, 100.0 * inside[1] / reps, 100.0 * inside[2] / reps);
}

void ContactTable() {
  fmt::print("Poynting-Thomson contact response (one impact), median time per call\n");
  fmt::print("{:<40} {:>12} {:>12}\n", "regime", "kinematic us", "force us");
  const double k = 4.6e5, wn = std::sqrt(k / kMass);
  const auto model = [&](double beta, double kappa1) {
    return PoyntingThomson{kMass, kappa1 * k, (1 - kappa1) * k, (1 - kappa1) * k / (beta * wn)};
  };
  const std::vector<std::pair<std::string, PoyntingThomson>> cases = {
      {"complex pair (K1 3e5, K2 5e5, C 20)", {kMass, 3e5, 5e5, 20.0}},
      {"three real roots (beta 5, kappa1 1e-3)", model(5.0, 1e-3)},
      {"1e-9 from the double root (r = 0.2)", model(3.5, 0.0342857142857 * (1 + 1e-9))},
      {"Kelvin-Voigt limit (K2 = 1e6 K1)", {kMass, 4.6e5, 4.6e11, 13.3}},
  };
  for (const auto& [name, m] : cases) {
    const auto time = [&](Separation sep) {
      try {
        PoyntingThomsonContact(m, 1.0, sep);
      } catch (const NoSeparationError&) {
        return -1.0;
      }
      return MedianMicros([&] { PoyntingThomsonContact(m, 1.0, sep); }, 2001);
    };
    const double kin = time(Separation::kKinematic), force = time(Separation::kForce);
    fmt::print("{:<40} {:>12} {:>12.1f}\n", name,
               kin < 0 ? std::string("never ends") : fmt::format("{:.1f}", kin), force);
  }
  fmt::print("\n");
}

}  // namespace

int main() {
  ContactTable();
  KelvinVoigtTable();
  PoyntingThomsonTable();
  return 0;
}
