// The settings of reduce's least-squares fits ([fit] in session.toml).
#pragma once

#include <string>

#include "fit/contact_law_fit.h"
#include "fit/joint_fits.h"
#include "fit/kelvin_voigt_least_squares.h"
#include "fit/poynting_thomson_least_squares.h"

namespace impactlab {

struct FitOptions {
  KelvinVoigtLeastSquaresOptions kelvin_voigt;          // per run, over all its maxima
  PoyntingThomsonLeastSquaresOptions poynting_thomson;  // per run and jointly over the runs
  JointFitOptions restitution_models;                   // the models compared across runs
  ContactLawFitOptions contact_laws;                    // the contact laws across runs

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("kelvin_voigt", self.kelvin_voigt, "");
    visit("poynting_thomson", self.poynting_thomson, "");
    visit("restitution_models", self.restitution_models, "");
    visit("contact_laws", self.contact_laws, "");
  }

  bool Check(std::string* why) const {
    const auto in = [&](const char* part, bool ok) {
      if (!ok) *why = std::string(part) + "." + *why;
      return ok;
    };
    return in("kelvin_voigt", kelvin_voigt.Check(why)) &&
           in("poynting_thomson", poynting_thomson.Check(why)) &&
           in("restitution_models", restitution_models.Check(why)) &&
           in("contact_laws", contact_laws.Check(why));
  }
};

}  // namespace impactlab
