#include <string>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "model/kelvin_voigt.h"

namespace impactlab::cli {
namespace {

void PrintContact(const ContactResponse& c, double damping_ratio, bool json) {
  if (json) {
    const nlohmann::json out = {{"contact_time", c.contact_time},
                                {"restitution", c.restitution},
                                {"log_restitution", c.log_restitution},
                                {"peak_compression", c.peak_compression},
                                {"peak_time", c.peak_time},
                                {"damping_ratio", damping_ratio},
                                {"separation", SeparationName(c.separation)}};
    fmt::print("{}\n", out.dump(2));
    return;
  }
  fmt::print("separation        {}\n", SeparationName(c.separation));
  fmt::print("damping ratio     {:.10g}\n", damping_ratio);
  fmt::print("contact time      {:.10g} s\n", c.contact_time);
  fmt::print("restitution       {:.10g}  (ln e = {:.10g})\n", c.restitution, c.log_restitution);
  fmt::print("peak compression  {:.10g}  at {:.10g} s\n", c.peak_compression, c.peak_time);
}

}  // namespace

void AddModelCommand(CLI::App& app, Action& action) {
  CLI::App* model = app.add_subcommand("model", "Evaluate a contact model for one impact");
  model->require_subcommand(1);

  struct KvArgs {
    double mass = 0, stiffness = 0, damping = 0, speed = 0;
    std::string separation = "kinematic";
    bool json = false;
  };
  auto kv = std::make_shared<KvArgs>();
  CLI::App* cmd = model->add_subcommand(
      "kv", "Kelvin-Voigt (spring K parallel to dashpot C); any consistent units");
  cmd->add_option("--mass", kv->mass, "M")->required()->check(CLI::PositiveNumber);
  cmd->add_option("--stiffness", kv->stiffness, "K")->required()->check(CLI::PositiveNumber);
  cmd->add_option("--damping", kv->damping, "C")->required()->check(CLI::NonNegativeNumber);
  cmd->add_option("--speed", kv->speed, "Impact speed v0")->required()->check(CLI::PositiveNumber);
  cmd->add_option("--separation", kv->separation, "kinematic (x = 0) or force (K x + C x' = 0)")
      ->check(CLI::IsMember({"kinematic", "force"}))
      ->capture_default_str();
  cmd->add_flag("--json", kv->json, "Print JSON");
  cmd->callback([&action, kv] {
    action = [kv] {
      const KelvinVoigt m{kv->mass, kv->stiffness, kv->damping};
      const ContactResponse c = KelvinVoigtContact(m, kv->speed, ParseSeparation(kv->separation));
      PrintContact(c, RatesOf(m).damping_ratio, kv->json);
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
