// One results file's estimates as the campaign tabulates them.
#include <algorithm>
#include <cmath>
#include <optional>
#include <variant>

#include <fmt/format.h>

#include "campaign/campaign_internal.h"
#include "campaign/restitution_law.h"
#include "fit/effective_modulus.h"
#include "io/result_fields_hdf5.h"
#include "model/pendulum.h"
#include "pipeline/material_constants.h"

namespace impactlab {
namespace {

std::string UnitLabel(const std::string& kind, UnitSystem system) {
  const UnitLabels labels = LabelsFor(system);
  if (kind == "pressure") return labels.pressure;
  if (kind == "hertz_stiffness") return labels.hertz_stiffness;
  return UnitOfKind(kind, labels);
}

Specimen ConvertSpecimen(Specimen specimen, UnitSystem from, UnitSystem to) {
  Specimen::VisitFields(specimen, [&](const char*, auto&& listed, Quantity quantity, const char*) {
    auto& field = FieldOf(listed);
    if constexpr (std::is_same_v<std::remove_cvref_t<decltype(field)>, std::optional<double>>) {
      if (field) *field *= UnitFactor(UnitKindOf(quantity), from, to);
    }
  });
  return specimen;
}

std::string Geometry(const Specimen& s, UnitSystem units) {
  const std::string length = LabelsFor(units).length;
  if (s.end_shape == "sphere") {
    return s.sphere_radius ? fmt::format("sphere R = {:.4g} {}", *s.sphere_radius, length)
                           : "sphere, radius not given";
  }
  if (s.end_shape == "plane") {
    return s.edge_radius ? fmt::format("plane, edge radius {:.4g} {}", *s.edge_radius, length)
                         : "plane";
  }
  if (s.end_shape == "given_stiffness") return "given stiffness";
  return "not given";
}

double ExponentSetting(const SessionResult& r) {
  const auto it = r.settings.find("fit.contact_laws.exponent");
  if (it == r.settings.end()) return 1.5;
  if (const double* n = std::get_if<double>(&it->second)) return *n;
  if (const long long* n = std::get_if<long long>(&it->second)) return static_cast<double>(*n);
  return 1.5;
}

const NamedEstimate* Find(const std::vector<NamedEstimate>& parameters, const std::string& name) {
  const auto it = std::find_if(parameters.begin(), parameters.end(),
                               [&](const NamedEstimate& p) { return p.name == name; });
  return it == parameters.end() ? nullptr : &*it;
}

// The covariance of the named logarithms ("log k", "log chi"), from the fit's
// own or, where it has none, from the stated errors alone.
std::vector<double> LogCovariance(const ContactLawFit& law, const std::vector<std::string>& names,
                                  const std::vector<double>& relative_sigma) {
  const std::size_t n = names.size();
  std::vector<double> out(n * n, 0.0);
  const ParameterCovariance& c = law.covariance;
  std::vector<std::optional<std::size_t>> at;
  for (const std::string& name : names) {
    const auto it = std::find(c.names.begin(), c.names.end(), name);
    at.push_back(it == c.names.end() || c.matrix.size() != c.names.size() * c.names.size()
                     ? std::nullopt
                     : std::optional<std::size_t>(it - c.names.begin()));
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      if (at[i] && at[j]) {
        out[i * n + j] = c.At(*at[i], *at[j]);
      } else if (i == j) {
        out[i * n + j] = relative_sigma[i] * relative_sigma[i];
      }
    }
  }
  return out;
}

}  // namespace

CampaignSession TabulateSession(const SessionResult& source, const std::string& name,
                                const std::string& file, UnitSystem to) {
  SessionResult r = source;
  const UnitSystem from = r.units;
  const auto factor = [&](const std::string& kind) { return UnitFactor(kind, from, to); };
  CampaignSession s;
  s.name = name;
  s.file = file;
  s.title = r.title;
  s.original_units = std::string(UnitSystemName(from));
  s.specimen = ConvertSpecimen(r.specimen, from, to);
  s.material = s.specimen.material.empty() ? kMaterialNotGiven : s.specimen.material;
  s.geometry = Geometry(s.specimen, to);

  // E* as this campaign's specimen makes it (a file from before E* was
  // written, or a specimen edited since, gets it all the same).
  for (ContactLawFit& law : r.contact_laws) {
    law.effective_modulus.reset();
    law.handbook_effective_modulus.reset();
    law.effective_modulus_unidentifiable.clear();
  }
  AddMaterialConstants(r.specimen, r.runs, ExponentSetting(r), r.contact_laws);

  const auto add = [&](const std::string& source_name, const std::string& parameter,
                       const Estimate& e, const std::string& kind) {
    if (!std::isfinite(e.value) || !std::isfinite(e.sigma)) return;
    const double f = factor(kind);
    s.estimates.push_back({source_name, parameter, e.value * f, e.sigma * f, UnitLabel(kind, to)});
  };
  for (const ContactLawFit& law : r.contact_laws) {
    if (!law.ok) continue;
    for (const NamedEstimate& p : law.parameters) add(law.law, p.name, p.estimate, p.units);
    if (law.effective_modulus)
      add(law.law, "effective_modulus", *law.effective_modulus, "pressure");
    if (law.handbook_effective_modulus) {
      add(law.law, "handbook_effective_modulus", {*law.handbook_effective_modulus, 0.0},
          "pressure");
    }
    const NamedEstimate* k = Find(law.parameters, "hertz_stiffness");
    if (k == nullptr || Find(law.parameters, "exponent") != nullptr) continue;
    const double modulus_per_k = law.effective_modulus && k->estimate.value != 0.0
                                     ? law.effective_modulus->value / k->estimate.value *
                                           factor("pressure") / factor("hertz_stiffness")
                                     : 0.0;
    if (law.law == "hunt-crossley") {
      const NamedEstimate* chi = Find(law.parameters, "damping_factor");
      if (chi == nullptr) continue;
      s.laws.push_back({law.law, r.apparatus.mass * factor("mass"),
                        k->estimate.value * factor("hertz_stiffness"),
                        chi->estimate.value * factor("inverse_speed"), modulus_per_k,
                        LogCovariance(law, {"log k", "log chi"},
                                      {k->estimate.sigma / k->estimate.value,
                                       chi->estimate.sigma / chi->estimate.value})});
    } else if (law.law == "hertz") {
      s.laws.push_back({law.law, r.apparatus.mass * factor("mass"),
                        k->estimate.value * factor("hertz_stiffness"), 0.0, modulus_per_k,
                        LogCovariance(law, {"log k"}, {k->estimate.sigma / k->estimate.value})});
    }
  }
  if (r.model_comparison) {
    const auto add_model = [&](const std::string& model, bool ok,
                               const std::vector<NamedEstimate>& parameters) {
      if (!ok) return;
      for (const NamedEstimate& p : parameters) {
        add("restitution " + model, p.name, p.estimate, p.units);
      }
    };
    for (const ComparedRestitutionModel& m : r.model_comparison->restitution_models) {
      add_model(m.fit.name, m.fit.ok, m.fit.parameters);
    }
    for (const ComparedContactLaw& m : r.model_comparison->contact_laws) {
      add_model(m.fit.law, m.fit.ok, m.fit.parameters);
    }
  }

  const Pendulum pendulum{r.apparatus.pendulum_length, r.apparatus.gravity, r.convention};
  // A maximum's relative error as its speed's: times d ln v / d ln X (1 to
  // first order; less where the pendulum swings far).
  const auto speed_relative_sigma = [&](double x, double sigma) {
    const double h = 1e-4;
    const double slope = std::log(SpeedFromAmplitude(pendulum, x * (1 + h)) /
                                  SpeedFromAmplitude(pendulum, x * (1 - h))) /
                         std::log((1 + h) / (1 - h));
    return slope * sigma / x;
  };
  for (const RunResult& run : r.runs) {
    if (!run.ok || run.measured.xmax.empty() || pendulum.length <= 0.0) continue;
    const std::vector<double>& x = run.measured.xmax;
    const std::vector<double>& sx = run.measured.xmax_sigma;
    for (std::size_t n = 0; n + 1 < x.size(); ++n) {
      if (!(x[n] > 0.0) || !(x[n + 1] > 0.0)) continue;
      const double v = SpeedFromAmplitude(pendulum, x[n]);
      const double e = SpeedFromAmplitude(pendulum, x[n + 1]) / v;
      // To first order v is proportional to X, so e's relative error is the
      // maxima's combined.
      const double a = n < sx.size() ? sx[n] / x[n] : 0.0;
      const double b = n + 1 < sx.size() ? sx[n + 1] / x[n + 1] : 0.0;
      ImpactRestitution impact{run.id, static_cast<int>(n), v * factor("speed"), e,
                               e * std::hypot(a, b)};
      if (n + 1 < sx.size()) {
        impact.speed_relative_sigma = speed_relative_sigma(x[n], sx[n]);
        impact.rebound_speed_relative_sigma = speed_relative_sigma(x[n + 1], sx[n + 1]);
      }
      s.restitution.push_back(std::move(impact));
    }
    if (run.measured.contact_time && x.front() > 0.0) {
      s.contact_times.push_back({run.id, SpeedFromAmplitude(pendulum, x.front()) * factor("speed"),
                                 *run.measured.contact_time, run.measured.contact_time_sigma});
    }
  }
  // The session's restitution speed law, in the campaign's units.
  s.restitution_law = FitRestitutionLaw(s.restitution);
  if (const SessionRestitutionLaw& law = s.restitution_law; law.ok) {
    s.reference_speed = law.reference_speed;
    // Already in the campaign's units: chi = eps_ref/u_ref, Hunt-Crossley's
    // where beta = 1.
    const double chi = std::exp(law.log_eps) / law.reference_speed;
    s.estimates.push_back({"restitution speed law", "damping_factor", chi,
                           chi * std::sqrt(law.covariance[0]), UnitLabel("inverse_speed", to)});
    s.estimates.push_back({"restitution speed law", "speed_exponent", law.exponent,
                           std::sqrt(law.covariance[3]), "1"});
  }
  return s;
}

}  // namespace impactlab
