#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/validators.h"
#include "model/kelvin_voigt.h"
#include "model/power_law_contact.h"
#include "model/poynting_thomson.h"

namespace impactlab::cli {
namespace {

// A model-specific number printed beside the common response keys.
struct Extra {
  std::string key;    // JSON key
  std::string label;  // text label
  double value = 0.0;
};
using Extras = std::vector<Extra>;

// The keys every contact model prints (contact_time, restitution,
// log_restitution, peak_compression, peak_time, separation), then `extras`.
void PrintContact(const ContactResponse& c, const Extras& extras, bool json,
                  const ContactHistory* history = nullptr) {
  if (json) {
    nlohmann::json out = {{"contact_time", c.contact_time},
                          {"restitution", c.restitution},
                          {"log_restitution", c.log_restitution},
                          {"peak_compression", c.peak_compression},
                          {"peak_time", c.peak_time},
                          {"separation", SeparationName(c.separation)}};
    for (const Extra& e : extras) out[e.key] = e.value;
    if (history) {
      out["history"] = {{"time", history->time},
                        {"compression", history->compression},
                        {"velocity", history->velocity},
                        {"force", history->force}};
    }
    fmt::print("{}\n", out.dump(2));
    return;
  }
  fmt::print("separation        {}\n", SeparationName(c.separation));
  for (const Extra& e : extras) fmt::print("{:<17} {:.10g}\n", e.label, e.value);
  fmt::print("contact time      {:.10g} s\n", c.contact_time);
  fmt::print("restitution       {:.10g}  (ln e = {:.10g})\n", c.restitution, c.log_restitution);
  fmt::print("peak compression  {:.10g}  at {:.10g} s\n", c.peak_compression, c.peak_time);
  if (!history) return;
  fmt::print("\n{:>16} {:>16} {:>16} {:>16}\n", "t", "x", "x'", "F");
  for (std::size_t i = 0; i < history->time.size(); ++i) {
    fmt::print("{:16.9g} {:16.9g} {:16.9g} {:16.9g}\n", history->time[i], history->compression[i],
               history->velocity[i], history->force[i]);
  }
}

// Options shared by the model subcommands.
struct CommonArgs {
  double mass = 0, speed = 0;
  std::string separation = "kinematic";
  bool json = false;
};

void AddCommonOptions(CLI::App* cmd, CommonArgs& args, const char* force_rule) {
  cmd->add_option("--mass", args.mass, "M")->required()->check(kPositive);
  cmd->add_option("--speed", args.speed, "Impact speed v0")->required()->check(kPositive);
  cmd->add_option("--separation", args.separation,
                  std::string("kinematic (x = 0) or force (") + force_rule + " = 0)")
      ->check(CLI::IsMember({"kinematic", "force"}))
      ->capture_default_str();
  cmd->add_flag("--json", args.json, "Print JSON");
}

void AddKelvinVoigt(CLI::App* model, Action& action) {
  struct Args : CommonArgs {
    double stiffness = 0, damping = 0;
  };
  auto kv = std::make_shared<Args>();
  CLI::App* cmd = model->add_subcommand(
      "kv", "Kelvin-Voigt (spring K parallel to dashpot C); any consistent units");
  AddCommonOptions(cmd, *kv, "K x + C x'");
  cmd->add_option("--stiffness", kv->stiffness, "K")->required()->check(kPositive);
  cmd->add_option("--damping", kv->damping, "C")->required()->check(kNonNegative);
  cmd->callback([&action, kv] {
    action = [kv] {
      const KelvinVoigt m{kv->mass, kv->stiffness, kv->damping};
      const ContactResponse c = KelvinVoigtContact(m, kv->speed, ParseSeparation(kv->separation));
      PrintContact(c, {{"damping_ratio", "damping ratio", RatesOf(m).damping_ratio}}, kv->json);
      return kExitOk;
    };
  });
}

void AddPoyntingThomson(CLI::App* model, Action& action) {
  struct Args : CommonArgs {
    double k1 = 0, k2 = 0, damping = 0;
  };
  auto pt = std::make_shared<Args>();
  CLI::App* cmd = model->add_subcommand(
      "pt",
      "Poynting-Thomson (spring K1 parallel to spring K2 in series with dashpot C); any "
      "consistent units");
  AddCommonOptions(cmd, *pt, "K1 x1 + K2 (x1 - x2)");
  cmd->add_option("--k1", pt->k1, "K1, the spring from the mass to ground")
      ->required()
      ->check(kPositive);
  cmd->add_option("--k2", pt->k2, "K2, the spring in series with the dashpot")
      ->required()
      ->check(kPositive);
  cmd->add_option("--damping", pt->damping, "C, the dashpot")->required()->check(kPositive);
  cmd->callback([&action, pt] {
    action = [pt] {
      const PoyntingThomson m{pt->mass, pt->k1, pt->k2, pt->damping};
      const ContactResponse c =
          PoyntingThomsonContact(m, pt->speed, ParseSeparation(pt->separation));
      PrintContact(c, {}, pt->json);
      return kExitOk;
    };
  });
}

// Options of the power-law (Hertz-family) subcommands.
struct PowerLawArgs : CommonArgs {
  double stiffness = 0, exponent = 1.5;
  int history = 0;  // samples of the force history; 0 = none
};

void AddPowerLawOptions(CLI::App* cmd, PowerLawArgs& args) {
  cmd->add_option("--mass", args.mass, "M")->required()->check(kPositive);
  cmd->add_option("--speed", args.speed, "Impact speed v0")->required()->check(kPositive);
  cmd->add_option("--stiffness", args.stiffness, "k in F = k x^n")->required()->check(kPositive);
  cmd->add_option("--exponent", args.exponent, "n in F = k x^n")
      ->check(CLI::Range(1e-3, 10.0))
      ->capture_default_str();
  cmd->add_option("--history", args.history,
                  "Also print the force history at this many equally spaced times")
      ->check(CLI::Range(2, 100000));
  cmd->add_flag("--json", args.json, "Print JSON");
}

void AddHertz(CLI::App* model, Action& action) {
  auto args = std::make_shared<PowerLawArgs>();
  CLI::App* cmd = model->add_subcommand(
      "hertz", "Hertz, F = k x^n: elastic (e = 1), contact time by the Beta function");
  AddPowerLawOptions(cmd, *args);
  cmd->callback([&action, args] {
    action = [args] {
      const Hertz m{args->mass, args->stiffness, args->exponent};
      const ContactResponse c = HertzContact(m, args->speed);
      ContactHistory h;
      if (args->history > 0) {
        h = HuntCrossleyHistory({m.mass, m.stiffness, m.exponent, 0.0}, args->speed, args->history);
      }
      PrintContact(c, {}, args->json, args->history > 0 ? &h : nullptr);
      return kExitOk;
    };
  });
}

void AddHuntCrossley(CLI::App* model, Action& action) {
  struct Args : PowerLawArgs {
    double damping_factor = -1, restitution = -1;
    std::string convention = "exact";
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = model->add_subcommand(
      "hc", "Hunt-Crossley, F = k x^n (1 + chi x'); chi given, or set from a target e");
  cmd->alias("hunt-crossley");
  AddPowerLawOptions(cmd, *args);
  auto* chi = cmd->add_option("--damping-factor", args->damping_factor, "chi (time/length)")
                  ->check(kNonNegative);
  auto* e =
      cmd->add_option("--restitution", args->restitution,
                      "Target e at --speed: chi from --convention instead of --damping-factor")
          ->check(CLI::Range(1e-12, 1.0));
  chi->excludes(e);
  cmd->add_option("--convention", args->convention,
                  "How chi follows from --restitution: exact (the energy relation), "
                  "hunt-crossley, lankarani-nikravesh or flores")
      ->check(CLI::IsMember({"exact", "hunt-crossley", "lankarani-nikravesh", "flores"}))
      ->capture_default_str();
  cmd->callback([&action, args, chi, e] {
    if (chi->count() == 0 && e->count() == 0) {
      throw CLI::RequiredError("--damping-factor or --restitution");
    }
    action = [args] {
      const double damping_factor =
          args->restitution >= 0.0
              ? DampingFactorFor(args->restitution, args->speed,
                                 ParseDampingFactorConvention(args->convention))
              : args->damping_factor;
      const HuntCrossley m{args->mass, args->stiffness, args->exponent, damping_factor};
      const ContactResponse c = HuntCrossleyContact(m, args->speed);
      ContactHistory h;
      if (args->history > 0) h = HuntCrossleyHistory(m, args->speed, args->history);
      Extras extras{{"damping_factor", "chi", damping_factor},
                    {"epsilon", "eps = chi v0", damping_factor * args->speed}};
      if (args->restitution >= 0.0) {
        extras.push_back({"target_restitution", "target e", args->restitution});
      }
      PrintContact(c, extras, args->json, args->history > 0 ? &h : nullptr);
      return kExitOk;
    };
  });
}

void AddHertzDamper(CLI::App* model, Action& action) {
  struct Args : PowerLawArgs {
    double damping = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = model->add_subcommand(
      "hertz-damper", "Hertz spring with a linear damper, F = k x^n + c x' (integrated)");
  AddPowerLawOptions(cmd, *args);
  cmd->add_option("--damping", args->damping, "c")->required()->check(kNonNegative);
  cmd->add_option("--separation", args->separation, "kinematic (x = 0) or force (F = 0)")
      ->check(CLI::IsMember({"kinematic", "force"}))
      ->capture_default_str();
  cmd->callback([&action, args] {
    action = [args] {
      const HertzDamper m{args->mass, args->stiffness, args->exponent, args->damping};
      const Separation separation = ParseSeparation(args->separation);
      const ContactResponse c = HertzDamperContact(m, args->speed, separation);
      ContactHistory h;
      if (args->history > 0) h = HertzDamperHistory(m, args->speed, separation, args->history);
      PrintContact(c, {}, args->json, args->history > 0 ? &h : nullptr);
      return kExitOk;
    };
  });
}

}  // namespace

void AddModelCommand(CLI::App& app, Action& action) {
  CLI::App* model = app.add_subcommand("model", "Evaluate a contact model for one impact");
  model->require_subcommand(1);
  AddKelvinVoigt(model, action);
  AddPoyntingThomson(model, action);
  AddHertz(model, action);
  AddHuntCrossley(model, action);
  AddHertzDamper(model, action);
}

}  // namespace impactlab::cli
