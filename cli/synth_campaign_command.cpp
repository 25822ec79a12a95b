#include <filesystem>

#include <fmt/core.h>

#include "cli/commands.h"
#include "synth/campaign.h"

namespace impactlab::cli {

void AddSynthCampaignCommand(CLI::App& app, Action& action) {
  struct Args {
    std::filesystem::path out;
    DrawnCampaignOptions options;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "synth-campaign",
      "Simulate a campaign: sessions of several materials and end shapes from shared constants, "
      "with truth");
  cmd->add_option("-o,--out,--output", args->out,
                  "Folder to create (must not exist or be empty): a session folder per session "
                  "and campaign.truth.json")
      ->required();
  cmd->add_option("--sessions", args->options.sessions, "Number of sessions")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--runs", args->options.runs, "Runs (X0s) per session")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Random seed: the same seed, the same campaign")
      ->capture_default_str();
  cmd->add_option("--disagreeing", args->options.disagreeing_fraction,
                  "Fraction of the sessions made to disagree with their material")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--disagreement-factor", args->options.disagreement_factor,
                  "What a disagreeing session's chi or E* is multiplied by")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->callback([&action, args] {
    action = [args] {
      const DrawnCampaign campaign = DrawCampaign(args->options);
      WriteCampaign(args->out, campaign);
      std::size_t disagreeing = 0;
      for (const DrawnCampaignSession& s : campaign.sessions) disagreeing += s.disagreement ? 1 : 0;
      fmt::print(stderr, "{} session(s), {} made to disagree, in {}; truth in {}\n",
                 campaign.sessions.size(), disagreeing, args->out.string(),
                 (args->out / "campaign.truth.json").string());
      return kExitOk;
    };
  });
}

}  // namespace impactlab::cli
