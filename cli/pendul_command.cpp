// `impactlab pendul fit|response|predict`: PENDUL's three options.
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/commands.h"
#include "cli/validators.h"
#include "fit/pendul.h"
#include "io/units.h"
#include "model/rebound_history.h"

namespace impactlab::cli {
namespace {

struct PendulumArgs {
  double length = 0;
  std::optional<double> mass, weight, gravity;
  std::string units = "in-lbf-s";
  std::string convention = "exact";
  std::string separation = "kinematic";
  int rebounds = 4;
  double step = 0;  // s; 0: no sampled history
};

void AddPendulumOptions(CLI::App* cmd, PendulumArgs& a) {
  cmd->add_option("--length", a.length, "Pendulum length L")->required()->check(kPositive);
  auto* mass = cmd->add_option("--mass", a.mass, "Mass M of one pendulum")->check(kPositive);
  auto* weight =
      cmd->add_option("--weight", a.weight, "Weight W of one pendulum (M = W/g)")->check(kPositive);
  mass->excludes(weight);
  cmd->add_option("--gravity", a.gravity, "g (default: 385.644 in/s^2 or 9.80665 m/s^2)")
      ->check(kPositive);
  cmd->add_option("--units", a.units, "in-lbf-s or SI (for the default g)")
      ->check(CLI::IsMember({"in-lbf-s", "SI"}))
      ->capture_default_str();
  cmd->add_option("--convention", a.convention, "exact or thesis (PENDUL's small angle)")
      ->check(CLI::IsMember({"exact", "thesis"}))
      ->capture_default_str();
  cmd->add_option("--separation", a.separation, "kinematic or force")
      ->check(CLI::IsMember({"kinematic", "force"}))
      ->capture_default_str();
  cmd->add_option("--rebounds", a.rebounds, "Rebounds to compute")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--step", a.step, "Print the displacement history sampled every STEP s (CSV)")
      ->check(kNonNegative);
}

struct Resolved {
  Pendulum pendulum;
  double mass;
  Separation separation;
};

Resolved Resolve(const PendulumArgs& a) {
  const double g = a.gravity.value_or(StandardGravity(*ParseUnitSystem(a.units)));
  if (!a.mass && !a.weight) throw std::invalid_argument("give --mass or --weight");
  const double mass = a.mass ? *a.mass : *a.weight / g;
  const PendulumConvention convention =
      a.convention == "thesis" ? PendulumConvention::kThesis : PendulumConvention::kExact;
  return {Pendulum{a.length, g, convention}, mass, ParseSeparation(a.separation)};
}

void PrintResponse(const PendulResponse& r, const Resolved& setup, double step) {
  fmt::print("K = {:.8g}   C = {:.8g}   zeta = {:.8g}\n", r.parameters.stiffness,
             r.parameters.damping, r.damping_ratio);
  fmt::print("tau_c = {:.8g} s   tau_r = {:.8g} s   e = {:.8g}\n", r.contact.contact_time,
             r.rebound_time, r.contact.restitution);
  fmt::print("\nrebound,time_s,xmax\n");
  for (std::size_t n = 0; n < r.sequence.xmax.size(); ++n) {
    fmt::print("{},{:.10g},{:.10g}\n", n, r.sequence.peak_time[n], r.sequence.xmax[n]);
  }
  if (step > 0.0) {
    const KelvinVoigtContactLaw law(r.parameters, setup.separation);
    const SampledHistory h = SampleHistory(r.sequence, setup.pendulum, law, step);
    fmt::print("\ntime_s,displacement\n");
    for (std::size_t i = 0; i < h.time.size(); ++i) {
      fmt::print("{:.10g},{:.10g}\n", h.time[i], h.displacement[i]);
    }
  }
}

struct MeasuredArgs {
  std::vector<double> xmax;
  std::vector<int> pair = {0, 1};
  double contact_time = 0;
};

void AddMeasuredOptions(CLI::App* cmd, MeasuredArgs& m) {
  cmd->add_option("--xmax", m.xmax, "Measured maxima of rebound 0, 1, 2, ... (comma-separated)")
      ->required()
      ->delimiter(',');
  cmd->add_option("--pair", m.pair, "The two rebounds a,b (a < b) the fit uses")
      ->delimiter(',')
      ->expected(2);
  cmd->add_option("--contact-time", m.contact_time, "Measured contact time tau_c, s")
      ->required()
      ->check(kPositive);
}

PendulFit FitMeasured(const Resolved& setup, const MeasuredArgs& m, int rebounds) {
  ReboundMeasurements measured;
  measured.xmax = m.xmax;
  measured.contact_time = m.contact_time;
  TwoPointOptions options;
  options.rebounds = {m.pair.at(0), m.pair.at(1)};
  options.separation = setup.separation;
  return PendulFromMeasurements(setup.pendulum, setup.mass, measured, options, rebounds);
}

}  // namespace

void AddPendulCommand(CLI::App& app, Action& action) {
  CLI::App* pendul = app.add_subcommand("pendul", "PENDUL's three options (thesis Appendix E)");
  pendul->require_subcommand(1);

  {
    auto p = std::make_shared<PendulumArgs>();
    auto m = std::make_shared<MeasuredArgs>();
    CLI::App* cmd = pendul->add_subcommand(
        "fit", "Option 1: K, C, zeta, tau_r from measured maxima and tau_c, and the response");
    AddPendulumOptions(cmd, *p);
    AddMeasuredOptions(cmd, *m);
    cmd->callback([&action, p, m] {
      action = [p, m] {
        const Resolved setup = Resolve(*p);
        PrintResponse(FitMeasured(setup, *m, p->rebounds).response, setup, p->step);
        return kExitOk;
      };
    });
  }
  {
    auto p = std::make_shared<PendulumArgs>();
    auto kc = std::make_shared<std::array<double, 3>>();  // K, C, X0
    CLI::App* cmd = pendul->add_subcommand(
        "response", "Option 2: the response, tau_c and tau_r from given K and C");
    AddPendulumOptions(cmd, *p);
    cmd->add_option("--stiffness", (*kc)[0], "K")->required()->check(kPositive);
    cmd->add_option("--damping", (*kc)[1], "C")->required()->check(kNonNegative);
    cmd->add_option("--x0", (*kc)[2], "Release displacement X0")->required()->check(kPositive);
    cmd->callback([&action, p, kc] {
      action = [p, kc] {
        const Resolved setup = Resolve(*p);
        const KelvinVoigt parameters{setup.mass, (*kc)[0], (*kc)[1]};
        PrintResponse(
            PendulResponseFor(setup.pendulum, parameters, setup.separation, (*kc)[2], p->rebounds),
            setup, p->step);
        return kExitOk;
      };
    });
  }
  {
    auto p = std::make_shared<PendulumArgs>();
    auto m = std::make_shared<MeasuredArgs>();
    auto releases = std::make_shared<std::vector<double>>();
    CLI::App* cmd = pendul->add_subcommand(
        "predict", "Option 3: parameters from measured maxima predict new release displacements");
    AddPendulumOptions(cmd, *p);
    AddMeasuredOptions(cmd, *m);
    cmd->add_option("--new-x0", *releases, "New release displacements (comma-separated)")
        ->required()
        ->delimiter(',');
    cmd->callback([&action, p, m, releases] {
      action = [p, m, releases] {
        const Resolved setup = Resolve(*p);
        const PendulFit fitted = FitMeasured(setup, *m, p->rebounds);
        for (const PendulResponse& r :
             PendulPredict(setup.pendulum, fitted, *releases, p->rebounds)) {
          fmt::print("# release X0 = {:.8g}\n", r.sequence.xmax.front());
          PrintResponse(r, setup, p->step);
          fmt::print("\n");
        }
        return kExitOk;
      };
    });
  }
}

}  // namespace impactlab::cli
