#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/validators.h"
#include "model/kelvin_voigt.h"
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
void PrintContact(const ContactResponse& c, const Extras& extras, bool json) {
  if (json) {
    nlohmann::json out = {{"contact_time", c.contact_time},
                          {"restitution", c.restitution},
                          {"log_restitution", c.log_restitution},
                          {"peak_compression", c.peak_compression},
                          {"peak_time", c.peak_time},
                          {"separation", SeparationName(c.separation)}};
    for (const Extra& e : extras) out[e.key] = e.value;
    fmt::print("{}\n", out.dump(2));
    return;
  }
  fmt::print("separation        {}\n", SeparationName(c.separation));
  for (const Extra& e : extras) fmt::print("{:<17} {:.10g}\n", e.label, e.value);
  fmt::print("contact time      {:.10g} s\n", c.contact_time);
  fmt::print("restitution       {:.10g}  (ln e = {:.10g})\n", c.restitution, c.log_restitution);
  fmt::print("peak compression  {:.10g}  at {:.10g} s\n", c.peak_compression, c.peak_time);
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

}  // namespace

void AddModelCommand(CLI::App& app, Action& action) {
  CLI::App* model = app.add_subcommand("model", "Evaluate a contact model for one impact");
  model->require_subcommand(1);
  AddKelvinVoigt(model, action);
  AddPoyntingThomson(model, action);
}

}  // namespace impactlab::cli
