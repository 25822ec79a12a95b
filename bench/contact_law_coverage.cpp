// Do the contact-law fits' standard errors keep their promise? Over many
// sessions drawn from each law (synth/law_session.h: six runs, five maxima and
// one contact time each, Gaussian reading errors of the stated sigmas), the
// fraction of fits whose 68 % and 95 % intervals (1 and 1.96 sigma) hold the
// truth, per parameter, with the pulls' RMS and the fit's run time, and how
// often the reported 68 % interval (linear, or from the chi^2 profile where
// chi^2 is not quadratic) holds it (docs/benchmarks.md). Then the same with reading errors three
// times the stated sigmas: the stated errors must under-cover, the Birge-scaled ones (ScatterCheck)
// cover again.
//
//   bench_contact_law_coverage [--sessions 1000] [--seed 1] [--error-scale 3]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>

#include "fit/contact_law_fit.h"
#include "model/kelvin_voigt.h"
#include "model/power_law_contact.h"
#include "synth/law_session.h"

namespace impactlab {
namespace {

const Pendulum kPendulum{22.0, 385.644};
const double kMass = 2.23 / 385.644;

struct Case {
  std::string name;
  ContactLawKind kind;
  std::unique_ptr<ContactLaw> law;
  std::map<std::string, double> truth;  // parameter -> true value
};

struct Tally {
  int fits = 0, inside68 = 0, inside95 = 0;
  int inside_interval = 0, profiles = 0;  // the 68 % interval (linear or profile)
  double pull_ss = 0.0;
};

std::vector<LawRun> AsLawRuns(const std::vector<LawSessionRun>& drawn) {
  std::vector<LawRun> runs;
  for (const LawSessionRun& d : drawn) {
    LawRun r;
    r.name = fmt::format("{}", d.initial_displacement);
    r.pendulum = kPendulum;
    r.mass = kMass;
    r.initial_displacement = d.initial_displacement;
    r.measured.xmax = d.xmax;
    r.measured.xmax_sigma = d.xmax_sigma;
    r.measured.contact_time = d.contact_time;
    r.measured.contact_time_sigma = d.contact_time_sigma;
    r.contact_rebound = d.contact_rebound;
    runs.push_back(r);
  }
  return runs;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace
}  // namespace impactlab

int main(int argc, char** argv) {
  using namespace impactlab;
  CLI::App app{"Coverage of the contact-law fits' standard errors"};
  int sessions = 1000;
  std::uint64_t seed = 1;
  double error_scale = 3.0;
  app.add_option("--sessions", sessions, "Sessions drawn per law")->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "First seed");
  app.add_option("--error-scale", error_scale,
                 "Second pass: reading errors this times the stated sigmas")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);

  const KelvinVoigt kv = KelvinVoigtFromRates(kMass, {std::sqrt(4.6e5 / kMass), 0.07});
  const HuntCrossley hc{kMass, 4.7e7, 1.5, 0.3};
  std::vector<Case> cases;
  cases.push_back({"kelvin-voigt",
                   ContactLawKind::kKelvinVoigt,
                   std::make_unique<KelvinVoigtContactLaw>(kv, Separation::kKinematic),
                   {{"damping_ratio", 0.07}, {"stiffness", kv.stiffness}}});
  cases.push_back({"hunt-crossley",
                   ContactLawKind::kHuntCrossley,
                   std::make_unique<HuntCrossleyContactLaw>(hc),
                   {{"damping_factor", hc.damping_factor}, {"hertz_stiffness", hc.stiffness}}});
  cases.push_back({"hunt-crossley-n",
                   ContactLawKind::kHuntCrossleyExponent,
                   std::make_unique<HuntCrossleyContactLaw>(hc),
                   {{"damping_factor", hc.damping_factor},
                    {"hertz_stiffness", hc.stiffness},
                    {"exponent", 1.5}}});

  const HertzDamper hd{kMass, 4.7e7, 1.5, 0.6};
  cases.push_back({"hertz-damper",
                   ContactLawKind::kHertzDamper,
                   std::make_unique<HertzDamperContactLaw>(hd, Separation::kKinematic),
                   {{"damping", hd.damping}, {"hertz_stiffness", hd.stiffness}}});

  ContactLawFitOptions options;
  options.leave_one_out = false;
  for (double scale : {1.0, error_scale}) {
    for (bool birge : {false, true}) {
      if (scale == 1.0 && birge) continue;
      fmt::print("\nreading errors {} x the stated sigmas; {} standard errors\n", scale,
                 birge ? "Birge-scaled" : "stated");
      fmt::print("{:<16} {:<16} {:>6} {:>8} {:>8} {:>9} {:>10} {:>8} {:>12} {:>9}\n", "law",
                 "parameter", "fits", "in 68%", "in 95%", "pull RMS", "fit ms", "failed",
                 "in interval", "profiles");
      for (const Case& c : cases) {
        std::map<std::string, Tally> tallies;
        std::vector<double> ms;
        int failed = 0;
        for (int s = 0; s < sessions; ++s) {
          LawSessionOptions draw;
          draw.seed = seed + static_cast<std::uint64_t>(s);
          draw.error_scale = scale;
          const auto runs = AsLawRuns(DrawLawSession(kPendulum, *c.law, draw));
          const auto start = std::chrono::steady_clock::now();
          const ContactLawFit fit = FitContactLaw(c.kind, runs, options);
          ms.push_back(
              1e3 *
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
          if (!fit.ok) {
            ++failed;
            continue;
          }
          for (const NamedEstimate& p : fit.parameters) {
            const auto truth = c.truth.find(p.name);
            if (truth == c.truth.end() || !(p.estimate.sigma > 0.0)) continue;
            const double sigma = p.estimate.sigma * (birge ? fit.scatter.Scale() : 1.0);
            const double pull = (p.estimate.value - truth->second) / sigma;
            Tally& t = tallies[p.name];
            ++t.fits;
            t.inside68 += std::abs(pull) <= 1.0;
            t.inside95 += std::abs(pull) <= 1.959964;
            t.pull_ss += pull * pull;
            for (const ParameterInterval& in : fit.intervals) {
              if (in.name != p.name) continue;
              t.inside_interval += in.lower <= truth->second && truth->second <= in.upper;
              t.profiles += in.profile;
            }
          }
        }
        for (const auto& [name, t] : tallies) {
          fmt::print(
              "{:<16} {:<16} {:>6} {:>7.1f}% {:>7.1f}% {:>9.3f} {:>10.2f} {:>8} {:>11.1f}% {:>9}\n",
              c.name, name, t.fits, 100.0 * t.inside68 / t.fits, 100.0 * t.inside95 / t.fits,
              std::sqrt(t.pull_ss / t.fits), Median(ms), failed, 100.0 * t.inside_interval / t.fits,
              t.profiles);
        }
      }
    }
  }
  return 0;
}
