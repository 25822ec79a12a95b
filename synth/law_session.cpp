#include "synth/law_session.h"

#include <fmt/format.h>

#include <random>

#include "model/rebound_history.h"

namespace impactlab {

std::vector<LawSessionRun> DrawLawSession(const Pendulum& pendulum, const ContactLaw& law,
                                          const LawSessionOptions& options) {
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<LawSessionRun> runs;
  for (double x0 : options.initial_displacements) {
    const ReboundSequence seq =
        SimulateRebounds(pendulum, law, x0, options.first_rebound + options.maxima - 1);
    LawSessionRun run;
    run.initial_displacement = x0;
    for (int i = 0; i < options.maxima; ++i) {
      const double x = seq.xmax[static_cast<std::size_t>(options.first_rebound + i)];
      run.true_xmax.push_back(x);
      run.xmax.push_back(x + options.error_scale * options.xmax_sigma * normal(rng));
      run.xmax_sigma.push_back(options.xmax_sigma);
    }
    // Impact N (from 1) follows thesis rebound N - 1, session rebound N - 1 - first_rebound.
    run.contact_rebound = options.contact_impact - 1 - options.first_rebound;
    if (options.contact_time_sigma > 0.0) {
      const double speed = seq.impact_speed[static_cast<std::size_t>(options.contact_impact - 1)];
      run.true_contact_time = law.Respond(speed).contact_time;
      run.contact_time =
          run.true_contact_time + options.error_scale * options.contact_time_sigma * normal(rng);
      run.contact_time_sigma = options.contact_time_sigma;
    }
    runs.push_back(std::move(run));
  }
  return runs;
}

std::string LawSessionRunsToml(const std::vector<LawSessionRun>& runs) {
  std::string text;
  for (const LawSessionRun& r : runs) {
    std::string maxima;
    for (double x : r.xmax) maxima += fmt::format("{}{:.9g}", maxima.empty() ? "" : ", ", x);
    text += fmt::format(
        "\n[[run]]\nid = \"{0}\"\ninitial_displacement = {0}\nrebounds = [{1}]\n"
        "rebound_uncertainty = {2}\ncontact_time = {3:.9g}\ncontact_time_uncertainty = {4}\n",
        r.initial_displacement, maxima, r.xmax_sigma.front(), r.contact_time, r.contact_time_sigma);
  }
  return text;
}

}  // namespace impactlab
