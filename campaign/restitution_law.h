// Restitution's speed law, one session's impacts at a time
// (docs/campaigns.md, "Restitution's speed law").
//
// The law is Hunt-Crossley's restitution with its argument a power of the
// impact speed:
//   e(u) = E(eps(u)),  eps(u) = eps_ref (u/u_ref)^beta,
// E(eps) the restitution of a Hunt-Crossley contact at eps = chi v
// (model/power_law_contact.h). beta = 1 is Hunt-Crossley itself, exactly,
// at every speed (eps_ref = chi u_ref); beta = 0 is a restitution that does
// not depend on speed (Kelvin-Voigt); where damping is small (1 - E ~ 2 eps/3)
// it is 1 - e proportional to u^beta, which holds quasi-static viscoelastic
// spheres with beta = 1/5 and a Hertz contact with a constant damper with
// beta = -1/5. A power law 1 - e = alpha u^beta alone does not hold
// Hunt-Crossley across the speeds of a campaign: from e = 0.98 to 0.71 its
// best fit misses ln e by up to 0.03, where a generated campaign's impact
// reads ln e to 0.0006-0.007.
//
// Each impact n of a run states ln e_n = ln v(X_{n+1}) - ln v(X_n) at the
// speed v(X_n), both from the maxima through the exact pendulum. The law is
// fitted to them by generalised least squares: a maximum's error enters the
// impact before it and the one after, so consecutive impacts of a run are
// correlated, and the speed an impact is put at is itself measured (the
// residual's covariance carries both, to first order: effective variance).
#pragma once

#include <string>
#include <vector>

#include "campaign/campaign.h"

namespace impactlab {

struct RestitutionLawOptions {
  int max_iterations = 50;
  double min_relative_eigenvalue = 1e-12;  // below: the impacts do not fix the law
};

// Throws nothing: a fit that cannot be made is !ok with why.
SessionRestitutionLaw FitRestitutionLaw(const std::vector<ImpactRestitution>& impacts,
                                        const RestitutionLawOptions& options = {});

// The law's ln e at speed u, with its slopes in (ln eps_ref, beta).
struct LogRestitutionAtSpeed {
  double value = 0.0;
  double d_log_eps = 0.0;   // d ln e / d ln eps_ref
  double d_exponent = 0.0;  // d ln e / d beta
};
LogRestitutionAtSpeed RestitutionLawAt(double log_eps_ref, double exponent, double log_speed_ratio);

}  // namespace impactlab
