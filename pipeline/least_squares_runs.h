// The least-squares fits of `reduce` (fit/kelvin_voigt_least_squares.h,
// fit/poynting_thomson_least_squares.h): per run, and Poynting-Thomson jointly
// over the session's runs, summarised for the results file.
#pragma once

#include <vector>

#include "fit/fit_options.h"
#include "pipeline/session_result.h"

namespace impactlab {

// Kelvin-Voigt over all maxima the run's fits are fitted to, and
// Poynting-Thomson from them (with the contact time when it has an
// uncertainty), started from the run's two-point Kelvin-Voigt fit. A fit that
// cannot run is summarised with its reason, never thrown.
std::vector<LeastSquaresSummary> FitRunLeastSquares(const Pendulum& pendulum, double mass,
                                                    Separation separation, const FitOptions& fit,
                                                    const std::string& run_id, const RunFits& fits);

// Poynting-Thomson with one parameter set for every successful run.
std::vector<LeastSquaresSummary> FitSessionJointly(const Pendulum& pendulum, double mass,
                                                   Separation separation, const FitOptions& fit,
                                                   const std::vector<RunResult>& runs);

// The restitution models compared over the runs whose maxima all carry an
// uncertainty (at least three runs); nullopt otherwise, with `why`.
std::optional<ModelComparison> CompareModels(const Pendulum& pendulum, const FitOptions& fit,
                                             const std::vector<RunResult>& runs, std::string* why);

}  // namespace impactlab
