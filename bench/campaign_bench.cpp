// bench_campaign: `impactlab campaign` over many results files, its wall
// time (target < 5 s for 100), and how well the shared constants come back
// from sessions drawn with known ones (docs/benchmarks.md).
//
// Each session is drawn under Hunt-Crossley (synth/law_session.h) with k =
// (8/3) E* sqrt(R) from its material's E* and its own sphere radius R and
// pendulum mass, typed in with a [specimen], reduced, and written as a
// results file; a share of them is drawn with chi shifted by a factor. Then
// the campaign reads the files, fits each material's constants and writes
// its file and HTML report, timed. Printed for the Hunt-Crossley fit (E*,
// chi) and restitution's speed law (chi, beta = 1): the campaign's time; per
// material, each constant against its truth in sigmas; the pulls' RMS of
// the clean sessions (1 when their errors are honest); which shifted
// sessions were found and which clean ones were named.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "bench/bench_support.h"
#include "campaign/campaign.h"
#include "fit/effective_modulus.h"
#include "io/manifest.h"
#include "model/power_law_contact.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "report/campaign_report.h"
#include "synth/law_session.h"

namespace impactlab {
namespace {

constexpr double kGravity = 385.644;

struct Material {
  std::string name;
  double effective_modulus, chi;  // psi, s/in
};

std::string Manifest(const std::string& title, const Material& m, double radius, double weight,
                     double chi, std::uint64_t seed) {
  const Pendulum pendulum{22.0, kGravity};
  const HuntCrossley law{weight / kGravity, HertzStiffnessOfSpheres(m.effective_modulus, radius),
                         1.5, chi};
  LawSessionOptions draw;
  draw.xmax_sigma = 2e-4;
  draw.seed = seed;
  std::string text = fmt::format(
      "format = 1\ntitle = \"{}\"\n\n[apparatus]\npendulum_length = 22.0\nweight = {}\n"
      "gravity = {}\n\n[products]\njoint_fits = false\nintervals = false\nleave_one_out = false\n"
      "[products.contact_laws]\nkelvin_voigt = false\nhunt_crossley_n = false\n"
      "hertz_damper = false\n\n[specimen]\nmaterial = \"{}\"\nend_shape = \"sphere\"\n"
      "sphere_radius = {}\n",
      title, weight, kGravity, m.name, radius);
  text += LawSessionRunsToml(DrawLawSession(pendulum, HuntCrossleyContactLaw(law), draw));
  return text;
}

}  // namespace
}  // namespace impactlab

int main(int argc, char** argv) {
  using namespace impactlab;
  namespace fs = std::filesystem;
  int sessions = 100, every = 10;
  double shift = 1.25;
  std::uint64_t seed = 1;
  fs::path dir = fs::temp_directory_path() / "bench_campaign";
  CLI::App app{"impactlab campaign over many results files: time and shared constants' pulls"};
  app.add_option("--sessions", sessions, "sessions drawn")->capture_default_str();
  app.add_option("--shift-every", every, "every N-th session is drawn with chi shifted")
      ->capture_default_str();
  app.add_option("--shift", shift, "the factor chi is shifted by")->capture_default_str();
  app.add_option("--seed", seed, "seed")->capture_default_str();
  app.add_option("--dir", dir, "where the sessions and results files go")->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const std::vector<Material> materials = {{"steel", 1.6e7, 1.5}, {"brass", 7.0e6, 3.0}};
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> radius(0.5, 4.0), weight(1.5, 3.0);
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::vector<fs::path> files;
  std::set<std::string> shifted;
  const auto reduce_start = std::chrono::steady_clock::now();
  for (int i = 0; i < sessions; ++i) {
    // Materials alternate, and the shifted sessions (every N-th) fall on each.
    const Material& m =
        materials[static_cast<std::size_t>(i + (every > 0 ? i / every : 0)) % materials.size()];
    const std::string name = fmt::format("s{:03d}", i);
    const bool off = every > 0 && i % every == every - 1;
    if (off) shifted.insert(name);
    fs::create_directories(dir / name);
    std::ofstream(dir / name / "session.toml")
        << Manifest(name, m, radius(random), weight(random), off ? shift * m.chi : m.chi,
                    seed * 1000 + static_cast<std::uint64_t>(i));
    WriteResults(ReduceSession(ReadManifest(dir / name).session, {}), dir / (name + ".h5"));
    files.push_back(dir / (name + ".h5"));
  }
  const double reduce_seconds = Seconds(reduce_start);

  const auto start = std::chrono::steady_clock::now();
  const Campaign campaign = MakeCampaign(files, {});
  WriteCampaign(campaign, dir / "campaign.h5");
  const std::string html = RenderCampaignHtml(campaign);
  std::ofstream(dir / "campaign.html") << html;
  const double campaign_seconds = Seconds(start);

  fmt::print("{} sessions ({} shifted by x{} in chi), reduced in {:.1f} s\n", sessions,
             shifted.size(), shift, reduce_seconds);
  fmt::print("campaign: read, fitted, written, HTML report: {:.2f} s (target < 5 s)\n",
             campaign_seconds);
  // Hunt-Crossley's (E*, chi), and restitution's speed law (chi, beta = 1:
  // the truth's e(u) is Hunt-Crossley's E(chi u)), each on its own.
  for (const std::string fit : {"hunt-crossley", "restitution"}) {
    std::vector<double> clean_pulls, truth_pulls;
    std::set<std::string> found, false_alarms;
    for (const MaterialFit& f : campaign.fits) {
      if (f.fit != fit || !f.ok) continue;
      const auto m = std::find_if(materials.begin(), materials.end(),
                                  [&](const Material& x) { return x.name == f.material; });
      const std::vector<double> truth = fit == "hunt-crossley"
                                            ? std::vector<double>{m->effective_modulus, m->chi}
                                            : std::vector<double>{m->chi, 1.0};
      for (std::size_t c = 0; c < f.constants.size(); ++c) {
        const double pull = (f.values[c] - truth[c]) / f.sigma_scaled[c];
        truth_pulls.push_back(pull);
        fmt::print(
            "{} {} {}: {:.5g} +- {:.2g} (truth {:.5g}: {:+.2f} sigma); Birge {:.3f}, {} of {} "
            "sessions agree\n",
            f.material, fit, f.constants[c], f.values[c], f.sigma_scaled[c], truth[c], pull,
            f.birge_ratio, f.sessions.size() - f.pulling_away.size(), f.sessions.size());
      }
      for (std::size_t k = 0; k < f.pull.size(); ++k) {
        if (!shifted.contains(f.pull_session[k])) clean_pulls.push_back(f.pull[k]);
      }
      for (const std::string& s : f.pulling_away) {
        (shifted.contains(s) ? found : false_alarms).insert(s);
      }
    }
    fmt::print(
        "{}: clean sessions' pulls: RMS {:.3f} over {} (within 1: {:.0f} %, within 2: {:.0f} %)\n",
        fit, Rms(clean_pulls), clean_pulls.size(), 100 * ShareWithin(clean_pulls, 1.0),
        100 * ShareWithin(clean_pulls, 2.0));
    fmt::print("{}: shared constants against the truth: RMS {:.3f} sigma over {}\n", fit,
               Rms(truth_pulls), truth_pulls.size());
    fmt::print("{}: shifted sessions found: {} of {}; clean sessions named: {}\n", fit,
               found.size(), shifted.size(), false_alarms.size());
  }
  return 0;
}
