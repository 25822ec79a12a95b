#include "pipeline/material_constants.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "fit/effective_modulus.h"
#include "io/session.h"

namespace impactlab {
namespace {

const NamedEstimate* FindParameter(const ContactLawFit& law, const std::string& name) {
  const auto it = std::find_if(law.parameters.begin(), law.parameters.end(),
                               [&](const NamedEstimate& p) { return p.name == name; });
  return it == law.parameters.end() ? nullptr : &*it;
}

// The specimen every run shares; why not, when their ends differ.
Specimen SharedSpecimen(const Specimen& session, const std::vector<RunResult>& runs,
                        std::string* why) {
  const Specimen shared = session;
  for (const RunResult& run : runs) {
    const Specimen own = SpecimenOf(session, run.specimen);
    if (own.end_shape != shared.end_shape || own.sphere_radius != shared.sphere_radius) {
      *why = fmt::format(
          "run \"{}\" has ends of its own ([run.specimen]), so one k across the "
          "runs is no single geometry's",
          run.id);
      return shared;
    }
  }
  return shared;
}

}  // namespace

void AddMaterialConstants(const Specimen& session_specimen, const std::vector<RunResult>& runs,
                          double exponent, std::vector<ContactLawFit>& laws) {
  const bool any_run_specimen = std::any_of(
      runs.begin(), runs.end(), [](const RunResult& run) { return !run.specimen.empty(); });
  if (session_specimen.empty() && !any_run_specimen) return;
  std::string differ;
  const Specimen specimen = SharedSpecimen(session_specimen, runs, &differ);
  const std::string geometry = differ.empty() ? EffectiveModulusUnidentifiable(specimen) : differ;
  for (ContactLawFit& law : laws) {
    const NamedEstimate* k = FindParameter(law, "hertz_stiffness");
    if (k == nullptr || !law.ok) continue;  // a linear law's K is no Hertz k
    law.handbook_effective_modulus = HandbookEffectiveModulus(specimen);
    if (FindParameter(law, "exponent") != nullptr) {
      law.effective_modulus_unidentifiable =
          "n is fitted: k's units are n's, and Hertz's k = (8/3) E* sqrt(R) holds for n = 3/2";
    } else if (exponent != 1.5) {
      law.effective_modulus_unidentifiable =
          fmt::format("n = {}: Hertz's k = (8/3) E* sqrt(R) holds for n = 3/2", exponent);
    } else if (!geometry.empty()) {
      law.effective_modulus_unidentifiable = geometry;
    } else if (!std::isfinite(k->estimate.sigma)) {
      law.effective_modulus_unidentifiable = "the data do not determine k";
    } else {
      law.effective_modulus = EffectiveModulusOfSpheres(k->estimate, *specimen.sphere_radius);
    }
  }
}

}  // namespace impactlab
