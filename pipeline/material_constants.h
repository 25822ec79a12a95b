// The material constants a session's contact-law fits hold, where its
// specimen (the manifest's [specimen], each run's own merged in) makes them
// identifiable: E* from Hertz's k through the ends' sphere radius
// (fit/effective_modulus.h, docs/physics.md).
#pragma once

#include <vector>

#include "fit/contact_law_fit.h"
#include "io/specimen.h"
#include "pipeline/session_result.h"

namespace impactlab {

// Sets each law's effective_modulus (and the handbook's E*), or why not,
// into `laws`. A law's k is a material constant only with Hertz's exponent
// 3/2 (`exponent`, the fits' n where not fitted; a fitted n makes k's units
// n's) and when every run has the same ends. Nothing is said when no
// specimen is given.
void AddMaterialConstants(const Specimen& session_specimen, const std::vector<RunResult>& runs,
                          double exponent, std::vector<ContactLawFit>& laws);

}  // namespace impactlab
