// The least-squares fits of `reduce` (fit/kelvin_voigt_least_squares.h,
// fit/poynting_thomson_least_squares.h): per run, and Poynting-Thomson jointly
// over the session's runs, kept as fit/ returns them.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "fit/fit_options.h"
#include "pipeline/session_result.h"

namespace impactlab {

// Into `fits`: Kelvin-Voigt over all maxima the run's fits are fitted to, and
// Poynting-Thomson from them (with the contact time when it has an
// uncertainty), started from the run's two-point Kelvin-Voigt fit. A fit
// whose inputs its stage refuses holds that reason (fit/ returns it as a fit
// that did not run).
void FitRunLeastSquares(const Pendulum& pendulum, double mass, Separation separation,
                        const FitOptions& fit, const std::string& run_id, RunFits& fits);

// Poynting-Thomson with one parameter set for every successful run (none
// when fewer than two runs have two maxima).
std::vector<PoyntingThomsonLeastSquaresFit> FitSessionJointly(const Pendulum& pendulum, double mass,
                                                              Separation separation,
                                                              const FitOptions& fit,
                                                              const std::vector<RunResult>& runs);

// What the contact-law fits need of the session beyond the runs' results.
struct LawInputs {
  Pendulum pendulum;
  double mass = 0.0;
  Separation separation = Separation::kKinematic;
  // Per run id: the session rebound its measured contact time's impact follows
  // (-1: the release's impact). Runs absent: their contact time is not used.
  std::map<std::string, int> contact_rebounds;
  int jobs = 1;  // threads the contact-law fits may use
};

// The restitution models, and the contact laws' predictions of the maxima
// (Hunt-Crossley, elastic Hertz; a linear law's is "common"), compared over
// the runs whose maxima all carry an uncertainty (at least three runs), with
// each model's verdict against the best and the evidence in sentences;
// nullopt otherwise, with `why`. `leave_one_out`: refit without each run too.
std::optional<ModelComparison> CompareModels(const LawInputs& inputs, const FitOptions& fit,
                                             const std::vector<RunResult>& runs, bool leave_one_out,
                                             std::string* why);

// The contact laws asked for in `asked` (every one when all are), fitted
// across those runs, maxima and own contact times together; a law the runs
// cannot inform (fit/contact_law_fit.h ContactLawUninformed) is not fitted.
// One record per law (pipeline/products.h) goes to `records`. Empty (with
// `why`) when fewer than two runs qualify.
std::vector<ContactLawFit> FitContactLaws(const LawInputs& inputs, const FitOptions& fit,
                                          const std::vector<RunResult>& runs,
                                          const ProductOptions& asked,
                                          std::vector<ProductRecord>* records, std::string* why);

// Every session-level fit product (joint fits, model comparison, the contact
// laws, their intervals, leave-one-out) that `asked` names and the runs can
// inform, into `result`, with a record of each in `result.products`.
void MakeSessionFits(const LawInputs& inputs, const FitOptions& fit, const ProductOptions& asked,
                     SessionResult& result);

}  // namespace impactlab
