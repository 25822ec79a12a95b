#include "pipeline/least_squares_runs.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "fit/joint_fits.h"
#include "fit/kelvin_voigt_least_squares.h"
#include "fit/poynting_thomson_least_squares.h"

namespace impactlab {
namespace {

void CopyQuality(const FitStatus& status, const Identifiability& identifiability, double chi2,
                 int dof, const ParameterCovariance& covariance, LeastSquaresSummary& out) {
  out.converged = status.converged;
  out.termination = status.message;
  out.seconds = status.seconds;
  out.identifiable = identifiability.identifiable;
  out.rank = identifiability.rank;
  out.identifiability = identifiability.message;
  out.chi2 = chi2;
  out.dof = dof;
  out.covariance_names = covariance.names;
  out.correlation = covariance.correlation;
}

LeastSquaresSummary Summarise(const KelvinVoigtLeastSquaresFit& fit) {
  LeastSquaresSummary out;
  out.model = "kelvin_voigt_least_squares";
  CopyQuality(fit.status, fit.identifiability, fit.chi2, fit.dof, fit.covariance, out);
  out.ok = fit.ok;
  if (!fit.ok) out.reason = fit.reason;
  out.parameters = {{"zeta", "1", fit.damping_ratio},
                    {"restitution", "1", fit.restitution},
                    {"log_restitution", "1", fit.log_restitution},
                    {"rebound0_xmax", "length", fit.rebound0_xmax},
                    {"rebound0_speed", "speed", fit.rebound0_speed}};
  if (fit.stiffness) out.parameters.push_back({"stiffness", "stiffness", *fit.stiffness});
  if (fit.damping) out.parameters.push_back({"damping", "damping", *fit.damping});
  for (const Estimate& x : fit.predicted_xmax) out.predicted_xmax.push_back(x.value);
  for (const MaximumResidual& r : fit.residuals) out.normalized_residuals.push_back(r.normalized);
  return out;
}

LeastSquaresSummary Summarise(const PoyntingThomsonLeastSquaresFit& fit) {
  LeastSquaresSummary out;
  out.model = "poynting_thomson";
  CopyQuality(fit.status, fit.identifiability, fit.chi2, fit.dof, fit.covariance, out);
  out.ok = fit.ok;
  if (!fit.ok) out.reason = fit.reason;
  out.parameters = {
      {"stiffness_1", "stiffness", fit.stiffness1}, {"stiffness_2", "stiffness", fit.stiffness2},
      {"damping", "damping", fit.damping},          {"log_restitution", "1", fit.log_restitution},
      {"restitution", "1", fit.restitution},        {"contact_time", "s", fit.contact_time},
      {"peak_per_speed", "s", fit.peak_per_speed}};
  for (const PoyntingThomsonRunFit& r : fit.runs) {
    for (const MaximumResidual& m : r.maxima) out.normalized_residuals.push_back(m.normalized);
  }
  return out;
}

LeastSquaresSummary Failed(const std::string& model, const std::string& why) {
  LeastSquaresSummary out;
  out.model = model;
  out.reason = why;
  return out;
}

// The run's observations as the fits take them. Every observation of a fit
// must carry an uncertainty, or none: a contact time without one is left out
// when the maxima have theirs (it would weigh arbitrarily against them).
PoyntingThomsonRun AsPoyntingThomsonRun(const Pendulum& pendulum, const std::string& id,
                                        const ReboundMeasurements& fitted) {
  PoyntingThomsonRun out{id, pendulum, {}, std::nullopt};
  out.measured.xmax = fitted.xmax;
  out.measured.xmax_sigma = fitted.xmax_sigma;
  const bool weighted = !fitted.xmax_sigma.empty() && fitted.xmax_sigma.front() > 0.0;
  if (fitted.contact_time && (fitted.contact_time_sigma > 0.0) == weighted) {
    out.measured.contact_time = fitted.contact_time;
    out.measured.contact_time_sigma = fitted.contact_time_sigma;
  }
  if (!weighted) out.measured.xmax_sigma.clear();
  return out;
}

// Where Poynting-Thomson starts when no contact time enters its fit (the
// maxima alone fix no time scale): the run's Kelvin-Voigt K and C, with K2 = 10 K.
std::optional<PoyntingThomson> StartFromKelvinVoigt(const RunFits& fits, double mass) {
  if (!fits.kelvin_voigt || !fits.kelvin_voigt->stiffness) return std::nullopt;
  const double k = fits.kelvin_voigt->stiffness->value;
  return PoyntingThomson{mass, k, 10.0 * k, std::max(fits.kelvin_voigt->damping->value, 1e-9 * k)};
}

}  // namespace

std::vector<LeastSquaresSummary> FitRunLeastSquares(const Pendulum& pendulum, double mass,
                                                    Separation separation, const FitOptions& fit,
                                                    const std::string& run_id,
                                                    const RunFits& fits) {
  std::vector<LeastSquaresSummary> out;
  ReboundMeasurements measured = fits.fitted;
  if (!measured.xmax_sigma.empty() && measured.xmax_sigma.front() <= 0.0)
    measured.xmax_sigma.clear();
  try {
    KelvinVoigtLeastSquaresOptions options = fit.kelvin_voigt;
    options.separation = separation;
    out.push_back(Summarise(FitKelvinVoigtLeastSquares(pendulum, mass, measured, options)));
  } catch (const std::exception& e) {
    out.push_back(Failed("kelvin_voigt_least_squares", e.what()));
  }
  try {
    PoyntingThomsonLeastSquaresOptions options = fit.poynting_thomson;
    options.mass = mass;
    options.separation = separation;
    options.initial = StartFromKelvinVoigt(fits, mass);
    out.push_back(Summarise(FitPoyntingThomsonLeastSquares(
        {AsPoyntingThomsonRun(pendulum, run_id, fits.fitted)}, options)));
  } catch (const std::exception& e) {
    out.push_back(Failed("poynting_thomson", e.what()));
  }
  return out;
}

std::vector<LeastSquaresSummary> FitSessionJointly(const Pendulum& pendulum, double mass,
                                                   Separation separation, const FitOptions& fit,
                                                   const std::vector<RunResult>& runs) {
  std::vector<PoyntingThomsonRun> joint;
  for (const RunResult& run : runs) {
    if (run.ok && run.measured.xmax.size() >= 2) {
      joint.push_back(AsPoyntingThomsonRun(pendulum, run.id, run.fits.fitted));
    }
  }
  if (joint.size() < 2) return {};
  try {
    PoyntingThomsonLeastSquaresOptions options = fit.poynting_thomson;
    options.mass = mass;
    options.separation = separation;
    for (const RunResult& run : runs) {
      if (!options.initial && run.ok) options.initial = StartFromKelvinVoigt(run.fits, mass);
    }
    return {Summarise(FitPoyntingThomsonLeastSquares(joint, options))};
  } catch (const std::exception& e) {
    return {Failed("poynting_thomson", e.what())};
  }
}

std::optional<ModelComparison> CompareModels(const Pendulum& pendulum, const FitOptions& fit,
                                             const std::vector<RunResult>& runs, std::string* why) {
  std::vector<JointRun> joint;
  for (const RunResult& run : runs) {
    const RunMeasurement& m = run.measured;
    const bool weighted =
        std::all_of(m.xmax_sigma.begin(), m.xmax_sigma.end(), [](double s) { return s > 0.0; });
    if (run.ok && m.xmax.size() >= 2 && !m.xmax_sigma.empty() && weighted) {
      joint.push_back(
          {run.id, pendulum, {m.xmax, m.xmax_sigma, std::nullopt, 0.0}, run.initial_displacement});
    }
  }
  if (joint.size() < 3) {
    *why = fmt::format(
        "model comparison skipped: it needs three runs whose maxima all carry an uncertainty, "
        "found {}",
        joint.size());
    return std::nullopt;
  }
  try {
    const SessionModelComparison c = CompareRestitutionModels(joint, fit.restitution_models);
    ModelComparison out;
    out.run_ids = c.run_names;
    out.best_by_leave_one_out = c.best_by_leave_one_out;
    out.best_by_bic = c.best_by_bic;
    for (const JointModelFit& m : c.models) {
      ModelComparisonRow row;
      row.model = m.name;
      row.ok = m.ok;
      row.reason = m.reason;
      row.parameters = m.parameters;
      row.maxima = m.maxima;
      row.parameter_count = m.parameter_count;
      row.dof = m.dof;
      row.chi2 = m.chi2;
      row.aic = m.aic;
      row.bic = m.bic;
      row.log_restitution_spread = m.log_restitution_spread;
      row.loo_rms_normalized = m.leave_one_out.rms_normalized;
      row.loo_rms_length = m.leave_one_out.rms_length;
      out.models.push_back(std::move(row));
    }
    return out;
  } catch (const std::exception& e) {
    *why = fmt::format("model comparison skipped: {}", e.what());
    return std::nullopt;
  }
}

}  // namespace impactlab
