#include "pipeline/results_file.h"

#include <algorithm>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "imagefile/image_file.h"
#include "io/errors.h"
#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/manifest.h"
#include "io/result_fields_hdf5.h"
#include "pipeline/log_results.h"
#include "pipeline/setting_key_internal.h"

namespace impactlab {
namespace {

// The file being written: the typed view, what layout 2 needs beyond it, and
// the session's unit labels.
struct Out {
  Hdf5File& f;
  const Hdf5Extras& x;
  UnitLabels u;
  const SettingValues& session_settings;  // /settings: the others are written as changes
  bool thumbnails = true;                 // the overlays' HDF5 images (products.thumbnails)
};

// The file being read and its layout (1 or 2), where the two differ.
struct In {
  const Hdf5File& f;
  long long layout;
  const SettingValues& session_settings;  // /settings, read first
  // The session's (the root's), which its fits used.
  Separation separation = Separation::kKinematic;
  double mass = 0.0;
};

// A result's stage settings (pipeline/stage_options.h): the attributes of its
// `settings` group, one per key, each the value as session.toml or the
// command line writes it ("gaussian", "0.15", "true").

// The session's settings, every one an attribute of /settings.
void WriteSessionSettings(Hdf5File& f, const SettingValues& settings) {
  if (settings.empty()) return;
  f.CreateGroup("/settings");
  for (const auto& [key, value] : settings) f.SetAttribute("/settings", key, SettingText(value));
}

// A result's settings: `@stages`, the stages that made it, and an attribute
// for each of their settings that differs from the session's. (Every setting
// of every result as an attribute cost about 47 ms of the sample photo
// session's 1.07 s reduce; the results are the same.)
void WriteSettings(Out& out, const std::string& group, const SettingValues& settings) {
  if (settings.empty()) return;
  Hdf5File& f = out.f;
  f.CreateGroup(group);
  std::set<std::string> stages;
  for (const auto& [key, value] : settings) {
    stages.insert(pipeline_internal::StageOf(key));
    const auto session = out.session_settings.find(key);
    if (session == out.session_settings.end() ||
        SettingText(session->second) != SettingText(value)) {
      f.SetAttribute(group, key, SettingText(value));
    }
  }
  f.SetAttribute(group, "stages", fmt::format("{}", fmt::join(stages, " ")));
}

SettingValues ReadSessionSettingsGroup(const Hdf5File& f) {
  SettingValues settings;
  if (!f.Exists("/settings")) return settings;  // layout 1
  for (const std::string& key : f.AttributeNames("/settings")) {
    settings[key] = ParseSettingText(f.ReadStringAttribute("/settings", key));
  }
  return settings;
}

// The first files of layout 2 wrote every setting and no `@stages`.
SettingValues ReadSettings(const In& in, const std::string& group) {
  const Hdf5File& f = in.f;
  SettingValues settings;
  if (!f.Exists(group)) return settings;  // layout 1, or a result made with none
  if (f.HasAttribute(group, "stages")) {
    std::istringstream stages(f.ReadStringAttribute(group, "stages"));
    for (std::string stage; stages >> stage;) {
      for (const auto& [key, value] : in.session_settings) {
        if (pipeline_internal::StageOf(key) == stage) settings[key] = value;
      }
    }
  }
  for (const std::string& key : f.AttributeNames(group)) {
    if (key != "stages") settings[key] = ParseSettingText(f.ReadStringAttribute(group, key));
  }
  return settings;
}

// Paths in one place, so writer and reader cannot drift apart.
std::string RunPath(const std::string& id) { return JoinPath({"runs", id}); }
std::string KelvinVoigtPath(const std::string& id) { return RunPath(id) + "/fit/kelvin_voigt"; }

void WriteEstimate(Hdf5File& f, const std::string& name, const Estimate& e,
                   std::string_view units) {
  f.WriteScalar(name, e.value, units);
  f.WriteScalar(name + "_std_error", e.sigma, units);
}

Estimate ReadEstimate(const Hdf5File& f, const std::string& name) {
  return {f.ReadScalar(name), f.ReadScalarIfPresent(name + "_std_error").value_or(0.0)};
}

std::vector<double> ReadVectorIfPresent(const Hdf5File& f, const std::string& name) {
  return f.Exists(name) ? f.ReadVector(name) : std::vector<double>{};
}

// The reason of a "failed: <reason>" status.
std::string ReasonOf(const std::string& status) {
  return status.rfind("failed: ", 0) == 0 ? status.substr(8) : status;
}

// The arrays of group `g` that hold `count` values (a dimension scale must be
// as long as the dimension it labels); none when `count` is 0.
std::vector<std::string> SameLength(
    const std::string& g, std::size_t count,
    const std::vector<std::pair<std::string, std::size_t>>& arrays) {
  std::vector<std::string> out;
  for (const auto& [name, size] : arrays) {
    if (count > 0 && size == count) out.push_back(g + "/" + name);
  }
  return out;
}

// The rebounds' numbers (session numbering), as `group`/rebound, the
// dimension scale of each of `arrays` (one value per rebound).
void WriteReboundScale(Out& out, const std::string& group, const std::vector<long long>& rebound,
                       const std::vector<std::string>& arrays) {
  if (rebound.empty()) return;
  const std::string scale = group + "/rebound";
  out.f.WriteIntegers(scale, rebound);
  out.f.SetAttribute(scale, "units", "1");
  for (const std::string& a : arrays) out.x.AttachScale(a, scale);
}

// A 1-D array and the axis it is sampled on (time, frequency), the axis
// attached as its dimension scale.
void WriteCurve(Out& out, const std::string& axis, const std::vector<double>& axis_values,
                std::string_view axis_units, const std::string& values_name,
                const std::vector<double>& values, std::string_view units) {
  out.f.WriteVector(axis, axis_values, axis_units);
  out.f.WriteVector(values_name, values, units);
  out.x.AttachScale(values_name, axis);
}

// The numbers `first`, `first` + 1, ... of `count` rebounds.
std::vector<long long> Consecutive(int first, std::size_t count) {
  std::vector<long long> rebound(count);
  for (std::size_t i = 0; i < count; ++i) rebound[i] = first + static_cast<long long>(i);
  return rebound;
}

// A bar's rows, with their rebounds' numbers as the scale (a bar may lack a
// rebound its trace does not show).
void WriteBar(Out& out, const std::string& g, const BarRebounds& bar) {
  WriteFields(out.f, out.x, g, bar, out.u);
  const std::size_t n = bar.xmax.size();
  std::vector<long long> rebound(n);
  for (std::size_t i = 0; i < n; ++i) rebound[i] = bar.Number(i);
  WriteReboundScale(out, g, rebound,
                    SameLength(g, n,
                               {{"xmax", n},
                                {"xmax_std_error", bar.xmax_sigma.size()},
                                {"t_peak", bar.t_peak.size()},
                                {"t_peak_std_error", bar.t_peak_sigma.size()},
                                {"duration", bar.duration.size()},
                                {"duration_std_error", bar.duration_sigma.size()}}));
}

// The rows' rebounds from the scale (none without rows: rows 0, 1, ...).
BarRebounds ReadBar(const Hdf5File& f, const std::string& g) {
  BarRebounds bar;
  ReadFields(f, g, bar);
  if (f.Exists(g + "/rebound")) {
    for (const long long n : f.ReadIntegers(g + "/rebound")) {
      bar.rebound.push_back(static_cast<int>(n));
    }
    if (bar.rebound.size() != bar.xmax.size() ||
        !std::is_sorted(bar.rebound.begin(), bar.rebound.end())) {
      throw InputError({f.path(), g + "/rebound", std::nullopt},
                       fmt::format("{} rebound numbers for {} maxima, or not ascending",
                                   bar.rebound.size(), bar.xmax.size()));
    }
  }
  return bar;
}

// The overlay's pixels, red-green-blue, as its JPEG decodes at a quarter of its width
// (none if it does not): the preview of an overlay read from an earlier
// results file (a reused run's), which keeps only the JPEG. libjpeg scales
// while it decodes (what cv::imdecode's IMREAD_REDUCED_COLOR_4 gave).
RgbImage DecodeOverlay(const std::vector<unsigned char>& jpeg) {
  if (jpeg.empty()) return {};
  cv::Mat bgr;
  if (std::string ignored; !imagefile::DecodeJpegBgr(jpeg, 4, &bgr, &ignored)) return {};
  RgbImage image{bgr.rows, bgr.cols, {}};
  image.pixels.resize(static_cast<std::size_t>(bgr.rows) * bgr.cols * 3);
  cv::Mat rgb(bgr.rows, bgr.cols, CV_8UC3, image.pixels.data());
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return image;
}

// A digitized photo: the overlay image and the digitizer's figures of merit.
void WriteOverlay(Out& out, const std::string& h, const PhotoOverlay& o) {
  Hdf5File& f = out.f;
  WriteFields(f, out.x, h, o, out.u);
  // The pixels as an HDF5 image, which HDFView shows (it cannot decode a
  // JPEG); the JPEG itself for the report's HTML, a tenth of the size.
  if (!out.thumbnails) {
    // Not asked for: the JPEG alone.
  } else if (!o.preview.pixels.empty()) {
    out.x.WriteImage(h + "/overlay", o.preview);
  } else if (const RgbImage image = DecodeOverlay(o.jpeg); !image.pixels.empty()) {
    out.x.WriteImage(h + "/overlay", image);
  }
  f.WriteBytes(h + "/overlay_jpeg", o.jpeg);
  for (const std::string& a :
       SameLength(h, o.trace_names.size(),
                  {{"trace_coverage", o.trace_coverage.size()},
                   {"trace_spread", o.trace_spread_px2.size()},
                   {"trace_spread_std_error", o.trace_spread_sigma_px2.size()}})) {
    out.x.AttachScale(a, h + "/trace_names");
  }
  // The file keeps seconds, the overlay milliseconds.
  f.WriteScalar(h + "/processing_time", 1e-3 * o.processing_ms, "s");
}

PhotoOverlay ReadOverlay(const Hdf5File& f, const std::string& h) {
  PhotoOverlay o;
  ReadFields(f, h, o);
  o.jpeg = f.ReadBytes(h + "/overlay_jpeg");
  o.processing_ms = 1e3 * f.ReadScalar(h + "/processing_time");
  return o;
}

void WriteCalibration(Out& out, const std::string& g, const CellCalibration& c) {
  Hdf5File& f = out.f;
  f.CreateGroup(g);
  WriteFields(f, out.x, g, c, out.u);
  f.SetAttribute(g, "model", "V(X) = sum c_k T_k(2X/X0 - 1), Chebyshev, order by BIC");
  WriteSettings(out, g + "/settings", c.settings);
  if (c.overlay) WriteOverlay(out, g + "/digitized", *c.overlay);
}

CellCalibration ReadCalibration(const In& in, const std::string& g, const std::string& cell) {
  const Hdf5File& f = in.f;
  CellCalibration c;
  ReadFields(f, g, c);
  if (!cell.empty()) c.cell = cell;
  c.settings = ReadSettings(in, g + "/settings");
  c.order = static_cast<int>(c.chebyshev.size()) - 1;
  if (f.Exists(g + "/digitized")) c.overlay = ReadOverlay(f, g + "/digitized");
  return c;
}

// A fit's parameters' names and unit kinds, so that they read back in order.
void WriteParameterNames(Out& out, const std::string& g,
                         const std::vector<NamedEstimate>& parameters) {
  std::vector<std::string> names, kinds;
  for (const NamedEstimate& p : parameters) {
    names.push_back(p.name);
    kinds.push_back(p.units);
  }
  out.f.WriteStrings(g + "/parameter_names", names);
  out.f.WriteStrings(g + "/parameter_unit_kinds", kinds);
}

// A fit's parameters: one dataset each (+ _std_error), and their names.
void WriteNamedEstimates(Out& out, const std::string& g,
                         const std::vector<NamedEstimate>& parameters) {
  for (const NamedEstimate& p : parameters) {
    WriteEstimate(out.f, g + "/" + p.name, p.estimate, UnitOfKind(p.units, out.u));
  }
  WriteParameterNames(out, g, parameters);
}

// Each parameter's standard error times `scale`, the fit's Birge scale
// (ScatterCheck::Scale), beside it: the errors to quote.
void WriteScaledErrors(Out& out, const std::string& g, const std::vector<NamedEstimate>& parameters,
                       double scale) {
  for (const NamedEstimate& p : parameters) {
    out.f.WriteScalar(g + "/" + p.name + "_std_error_scaled", p.estimate.sigma * scale,
                      UnitOfKind(p.units, out.u));
  }
}

std::vector<NamedEstimate> ReadNamedEstimates(const Hdf5File& f, const std::string& g) {
  const auto names = f.ReadStrings(g + "/parameter_names");
  const auto kinds = f.ReadStrings(g + "/parameter_unit_kinds");
  std::vector<NamedEstimate> parameters;
  for (std::size_t i = 0; i < names.size(); ++i) {
    parameters.push_back({names[i], kinds.at(i), ReadEstimate(f, g + "/" + names[i])});
  }
  return parameters;
}

// A least-squares fit's covariance is over its free parameters (fit/…:
// zeta and v0; log K1, log K2, log C and ln v0 of each run). A correlation is
// the same for a parameter and its logarithm, so the file names each row of
// `correlation` as the estimate it is: rebound0_speed, stiffness_1,
// stiffness_2, damping, rebound0_speed_<run id> (names already so are kept).
const std::pair<const char*, const char*> kEstimateNames[] = {{"v0", "rebound0_speed"},
                                                              {"log K1", "stiffness_1"},
                                                              {"log K2", "stiffness_2"},
                                                              {"log C", "damping"}};
const std::string kPerRunSpeed = "ln v0 ", kPerRunSpeedEstimate = "rebound0_speed_";

std::vector<std::string> EstimateNamesOf(const std::vector<std::string>& parameters) {
  std::vector<std::string> names;
  for (const std::string& p : parameters) {
    std::string name =
        p.starts_with(kPerRunSpeed) ? kPerRunSpeedEstimate + p.substr(kPerRunSpeed.size()) : p;
    for (const auto& [parameter, estimate] : kEstimateNames) {
      if (p == parameter) name = estimate;
    }
    names.push_back(name);
  }
  return names;
}

// The fit's own names of a file's estimate names (files that kept only the
// correlation).
std::vector<std::string> ParameterNamesOf(const std::vector<std::string>& estimates) {
  std::vector<std::string> names;
  for (const std::string& e : estimates) {
    std::string name = e.starts_with(kPerRunSpeedEstimate)
                           ? kPerRunSpeed + e.substr(kPerRunSpeedEstimate.size())
                           : e;
    for (const auto& [parameter, estimate] : kEstimateNames) {
      if (e == estimate) name = parameter;
    }
    names.push_back(name);
  }
  return names;
}

// A least-squares fit's estimates, its listed Estimate fields that hold one,
// in the list's order: what `parameter_names` names.
template <typename Fit>
std::vector<NamedEstimate> EstimatesOf(const Fit& fit) {
  std::vector<NamedEstimate> out;
  Fit::VisitFields(fit, [&](const char* name, auto&& listed, Quantity quantity, const char*) {
    const auto& field = FieldOf(listed);
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (std::is_same_v<Field, Estimate>) {
      out.push_back({name, UnitKindOf(quantity), field});
    } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
      if (field) out.push_back({name, UnitKindOf(quantity), *field});
    }
  });
  return out;
}

// A least-squares fit (fit/kelvin_voigt_least_squares.h,
// fit/poynting_thomson_least_squares.h): its status, and for a fit that ran
// its listed fields, an ok fit's caveat, and what the layout adds: the
// parameters' names and Birge-scaled errors, the correlation's rows named as
// estimates, `rebound_scale` (the run's rebound numbers, when the fit
// predicts one maximum per rebound; empty: none) on the predicted maxima.
template <typename Fit>
void WriteLeastSquares(Out& out, const std::string& g, const Fit& fit,
                       const std::string& rebound_scale) {
  Hdf5File& f = out.f;
  f.CreateGroup(g);
  f.SetAttribute(g, "method", "least-squares");
  f.SetAttribute(g, "status", fit.ok ? std::string("ok") : "failed: " + fit.reason);
  if (!fit.status.Ran()) return;
  if (fit.ok && !fit.reason.empty()) f.SetAttribute(g, "note", fit.reason);
  WriteFields(f, out.x, g, fit, out.u);
  const std::vector<NamedEstimate> estimates = EstimatesOf(fit);
  WriteParameterNames(out, g, estimates);
  WriteScaledErrors(out, g, estimates, fit.scatter.Scale());
  if (!rebound_scale.empty()) out.x.AttachScale(g + "/predicted_xmax", rebound_scale);
  if (!fit.covariance.correlation.empty()) {
    out.x.SetStringsAttribute(g + "/correlation", "parameter_names",
                              EstimateNamesOf(fit.covariance.names));
  }
}

// A least-squares fit as WriteLeastSquares wrote it, or as layout 1 and the
// first files of layout 2 did; what the file does not keep follows from what
// it does (the separation and M are the session's, K1, K2, C the estimates').
template <typename Fit>
Fit ReadLeastSquares(const In& in, const std::string& g) {
  const Hdf5File& f = in.f;
  Fit fit;
  fit.separation = in.separation;
  const std::string status = f.ReadStringAttribute(g, "status");
  fit.ok = status == "ok";
  if (!fit.ok) fit.reason = ReasonOf(status);
  if (in.layout == 1) {
    // Every fit ran; its "solver_message" is the termination, or a failed fit's reason.
    fit.status.message = f.ReadStringAttribute(g, "solver_message");
  } else if (!f.Exists(g + "/parameter_names")) {
    return fit;  // its inputs were refused
  }
  ReadFields(f, g, fit);
  // Written before a failed fit's termination was kept: its reason stands in.
  if (!fit.status.Ran()) fit.status.message = fit.reason;
  if (fit.ok && f.HasAttribute(g, "note")) fit.reason = f.ReadStringAttribute(g, "note");
  if (in.layout == 1) {
    fit.covariance.names = f.ReadStrings(g + "/covariance_names");
  } else if (f.Exists(g + "/correlation")) {
    fit.covariance.names =
        ParameterNamesOf(ReadStringsAttribute(f.path(), g + "/correlation", "parameter_names"));
  }
  if constexpr (std::is_same_v<Fit, PoyntingThomsonLeastSquaresFit>) {
    fit.model = {in.mass, fit.stiffness1.value, fit.stiffness2.value, fit.damping.value};
  }
  return fit;
}

// A contact law's layout beside its list (fit/contact_law_fit.h): its
// estimates with their stated and Birge-scaled standard errors, each
// interval's ends and method (`interval_methods` too when none was made, where
// `intervals` were asked), the leave-one-out RMS where it ran.
void WriteContactLawLayout(Out& out, const std::string& g, const ContactLawFit& fit,
                           bool intervals) {
  Hdf5File& f = out.f;
  WriteNamedEstimates(out, g, fit.parameters);
  WriteScaledErrors(out, g, fit.parameters, fit.scatter.Scale());
  std::vector<std::string> methods;
  for (std::size_t i = 0; i < fit.intervals.size() && i < fit.parameters.size(); ++i) {
    const ParameterInterval& in = fit.intervals[i];
    const std::string units = UnitOfKind(fit.parameters[i].units, out.u);
    f.WriteScalar(g + "/" + in.name + "_interval_lower", in.lower, units);
    f.WriteScalar(g + "/" + in.name + "_interval_upper", in.upper, units);
    methods.push_back(std::string(in.profile ? "profile" : "linear") +
                      (in.at_bound ? ", at a bound" : ""));
  }
  if (intervals || !methods.empty()) f.WriteStrings(g + "/interval_methods", methods);
  if (fit.loo_ok || fit.loo_maxima > 0) {  // left out: fewer than three runs, or not asked
    f.WriteScalar(g + "/leave_one_out_rms_normalized", fit.loo_rms_normalized, "1");
    f.WriteScalar(g + "/leave_one_out_rms", fit.loo_rms_length, out.u.length);
  }
}

// What WriteContactLawLayout wrote, into a law its list was read into.
void ReadContactLawLayout(const Hdf5File& f, const std::string& g, ContactLawFit& fit) {
  fit.parameters = ReadNamedEstimates(f, g);
  // Each interval's ends and method, beside the rises its list read.
  const std::vector<std::string> methods = f.Exists(g + "/interval_methods")
                                               ? f.ReadStrings(g + "/interval_methods")
                                               : std::vector<std::string>{};
  fit.intervals.resize(std::min(methods.size(), fit.parameters.size()));
  for (std::size_t i = 0; i < fit.intervals.size(); ++i) {
    ParameterInterval& in = fit.intervals[i];
    in.name = fit.parameters[i].name;
    in.lower = f.ReadScalar(g + "/" + in.name + "_interval_lower");
    in.upper = f.ReadScalar(g + "/" + in.name + "_interval_upper");
    in.profile = methods[i].rfind("profile", 0) == 0;
    in.at_bound = methods[i].find("at a bound") != std::string::npos;
  }
  const std::optional<double> loo = f.ReadScalarIfPresent(g + "/leave_one_out_rms_normalized");
  fit.loo_rms_normalized = loo.value_or(0.0);
  fit.loo_rms_length = f.ReadScalarIfPresent(g + "/leave_one_out_rms").value_or(0.0);
  // Files written before leave_one_out_ok was kept: ok where the RMS is.
  if (!f.HasAttribute(g, "leave_one_out_ok")) fit.loo_ok = fit.ok && loo.has_value();
}

// The comparison's models, each a group: its status, and for one that was
// fitted its list (the verdict and the fit's own fields) and its layout; one
// that was not has its verdict only. A restitution model's layout is its
// parameters and the Birge ratio (from chi2 and dof), a contact law's as in
// /session/contact_laws (fitted without intervals).
void WriteModelComparison(Out& out, const ModelComparison& c) {
  Hdf5File& f = out.f;
  const std::string g = "/session/model_comparison";
  WriteFields(f, out.x, g, c, out.u);
  const auto start = [&](const auto& m, bool ok, const std::string& reason) {
    const std::string h = g + "/" + m.Name();
    f.CreateGroup(h);
    f.SetAttribute(h, "status", ok ? std::string("ok") : "failed: " + reason);
    if (!m.Ran()) f.SetAttribute(h, "verdict", m.verdict);
    return h;
  };
  for (const ComparedRestitutionModel& m : c.restitution_models) {
    const std::string h = start(m, m.fit.ok, m.fit.reason);
    if (!m.Ran()) continue;
    WriteFields(f, out.x, h, m, out.u);
    WriteNamedEstimates(out, h, m.fit.parameters);
  }
  for (const ComparedContactLaw& m : c.contact_laws) {
    const std::string h = start(m, m.fit.ok, m.fit.reason);
    if (!m.Ran()) continue;
    WriteFields(f, out.x, h, m, out.u);
    WriteContactLawLayout(out, h, m.fit, false);
  }
}

// A restitution model's covariance from its correlation (which its list
// read, with its rows' names) and the parameters' standard errors.
void ReadModelCovariance(const Hdf5File& f, const std::string& h, JointModelFit& m) {
  ParameterCovariance& c = m.covariance;
  const std::size_t n = c.names.size();
  if (c.correlation.size() != n * n) {
    throw InputError({f.path(), h + "/correlation", std::nullopt},
                     fmt::format("not {} x {}", n, n));
  }
  std::vector<double> sigma;
  for (const std::string& name : c.names) {
    const auto it = std::find_if(m.parameters.begin(), m.parameters.end(),
                                 [&](const NamedEstimate& p) { return p.name == name; });
    if (it == m.parameters.end()) {
      throw InputError({f.path(), h + "/correlation", std::nullopt},
                       fmt::format("names '{}', not a parameter of the model", name));
    }
    sigma.push_back(it->estimate.sigma);
  }
  c.matrix.clear();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      c.matrix.push_back(c.correlation[i * n + j] * sigma[i] * sigma[j]);
    }
  }
}

bool IsContactLawName(const std::string& name) {
  for (ContactLawKind kind :
       {ContactLawKind::kKelvinVoigt, ContactLawKind::kHertz, ContactLawKind::kHuntCrossley,
        ContactLawKind::kHuntCrossleyExponent, ContactLawKind::kHertzDamper}) {
    if (name == ContactLawName(kind)) return true;
  }
  return false;
}

// The comparison as WriteModelComparison wrote it, or as files before it kept
// the fits did (a row of the same names per model: their lists read what
// there is; a restitution model's leave-one-out was ok where its RMS is).
ModelComparison ReadModelComparison(const Hdf5File& f) {
  const std::string g = "/session/model_comparison";
  ModelComparison c;
  ReadFields(f, g, c);
  for (const std::string& model : f.Children(g)) {
    const std::string h = g + "/" + model;
    if (!f.IsGroup(h)) continue;
    const std::string status = f.ReadStringAttribute(h, "status");
    const bool ok = status == "ok";
    const std::string reason = ok ? "" : ReasonOf(status);
    if (IsContactLawName(model)) {
      ComparedContactLaw m;
      m.fit.law = model;
      m.fit.ok = ok;
      m.fit.reason = reason;
      ReadFields(f, h, m);
      if (f.Exists(h + "/parameter_names")) ReadContactLawLayout(f, h, m.fit);
      // Written before the comparison kept the law's scatter check: as the
      // fit makes it, from its chi2 and dof.
      if (m.Ran() && !f.HasAttribute(h, "excess_scatter")) {
        m.fit.scatter = CheckScatter(m.fit.chi2, m.fit.dof);
      }
      c.contact_laws.push_back(std::move(m));
      continue;
    }
    ComparedRestitutionModel m;
    m.fit.name = model;
    m.fit.ok = ok;
    m.fit.reason = reason;
    ReadFields(f, h, m);
    if (f.Exists(h + "/parameter_names")) m.fit.parameters = ReadNamedEstimates(f, h);
    if (f.Exists(h + "/correlation")) ReadModelCovariance(f, h, m.fit);
    // Written before the model kept its scatter check: from chi2 and dof.
    if (!f.Exists(h + "/chi2_p_value")) m.fit.scatter = CheckScatter(m.fit.chi2, m.fit.dof);
    if (!f.HasAttribute(h, "leave_one_out_ok")) {
      m.fit.leave_one_out.ok = f.Exists(h + "/leave_one_out_rms_normalized");
    }
    c.restitution_models.push_back(std::move(m));
  }
  return c;
}

// A contact law fitted across the runs (fit/contact_law_fit.h): its status,
// and for one that ran its list and its layout.
void WriteContactLaw(Out& out, const ContactLawFit& fit) {
  Hdf5File& f = out.f;
  const std::string g = "/session/contact_laws/" + fit.law;
  f.CreateGroup(g);
  f.SetAttribute(g, "status", fit.ok ? std::string("ok") : "failed: " + fit.reason);
  if (fit.parameters.empty() && fit.maxima == 0) return;  // it did not run
  WriteFields(f, out.x, g, fit, out.u);
  WriteContactLawLayout(out, g, fit, true);
}

ContactLawFit ReadContactLaw(const Hdf5File& f, const std::string& law) {
  const std::string g = "/session/contact_laws/" + law;
  ContactLawFit fit;
  fit.law = law;
  const std::string status = f.ReadStringAttribute(g, "status");
  fit.ok = status == "ok";
  if (!fit.ok) fit.reason = ReasonOf(status);
  if (!f.Exists(g + "/chi2")) return fit;
  ReadFields(f, g, fit);
  ReadContactLawLayout(f, g, fit);
  return fit;
}

void WriteLogChannel(Out& out, const std::string& k, const ChannelAnalysis& c) {
  Hdf5File& f = out.f;
  f.CreateGroup(k);
  WriteFields(f, out.x, k, c, out.u);
  if (const SegmentSpectrum* s = KeptSpectrum(c)) {
    WriteCurve(out, k + "/spectrum/frequency", s->spectrum.frequency_hz, "Hz", k + "/spectrum/psd",
               s->spectrum.psd, "(" + c.units + ")^2/Hz");
    f.SetAttribute(k + "/spectrum", "segment", s->segment);
  }
  if (!c.series.time_s.empty()) {
    WriteCurve(out, k + "/series/time", c.series.time_s, "s", k + "/series/value", c.series.value,
               c.units);
  }
}

// The kind a channel's units are of (the analysis's UnitsOf, inverted).
LogChannelKind ChannelKindOf(const std::string& units) {
  return units == "rad"     ? LogChannelKind::kAngle
         : units == "m/s^2" ? LogChannelKind::kAcceleration
                            : LogChannelKind::kOther;
}

ChannelAnalysis ReadLogChannel(const Hdf5File& f, const std::string& k,
                               const std::string& channel) {
  ChannelAnalysis c;
  c.name = channel;
  ReadFields(f, k, c);
  c.kind = ChannelKindOf(c.units);
  // Layout 1 wrote an empty spectrum where none was computed.
  if (std::vector<double> frequency = ReadVectorIfPresent(f, k + "/spectrum/frequency");
      !frequency.empty()) {
    SegmentSpectrum s;
    if (f.HasAttribute(k + "/spectrum", "segment")) {
      s.segment = f.ReadStringAttribute(k + "/spectrum", "segment");
    } else {
      // Written before the segment was kept: the post-impact one, unless the
      // analysis noted that no impact was found.
      const bool no_impact = std::any_of(c.notes.begin(), c.notes.end(), [](const std::string& n) {
        return n.starts_with("no impact found");
      });
      s.segment = no_impact ? "whole" : "post_impact";
    }
    s.spectrum.frequency_hz = std::move(frequency);
    s.spectrum.psd = ReadVectorIfPresent(f, k + "/spectrum/psd");
    c.spectra.push_back(std::move(s));
  }
  c.series.time_s = ReadVectorIfPresent(f, k + "/series/time");
  c.series.value = ReadVectorIfPresent(f, k + "/series/value");
  return c;
}

void WriteLog(Out& out, const LogResult& log) {
  Hdf5File& f = out.f;
  const std::string g = JoinPath({"logs", log.id});
  f.CreateGroup(g);
  f.SetAttribute(g, "status", log.Status());
  WriteSettings(out, g + "/settings", log.settings);
  for (const LogSourceResult& s : log.sources) {
    const std::string h = g + "/" + s.source;
    WriteFields(f, out.x, h, s, out.u);
    for (const ChannelAnalysis& c : s.channels) WriteLogChannel(out, h + "/" + c.name, c);
  }
  if (!log.comparison) return;
  WriteFields(f, out.x, g + "/comparison", *log.comparison, out.u);
  for (const ChannelComparison& c : log.comparison->channels) {
    UnitLabels units = out.u;
    units.channel = c.units;
    WriteFields(f, out.x, g + "/comparison/" + c.channel, c, units);
  }
}

// A channel's units as its sources' analyses have them.
std::string ChannelUnitsOf(const LogResult& log, const std::string& channel) {
  for (const LogSourceResult& s : log.sources) {
    for (const ChannelAnalysis& c : s.channels) {
      if (c.name == channel) return c.units;
    }
  }
  return "";
}

// The comparison of a log's sources at `h`; `log` holds its sources.
LogComparison ReadLogComparison(const Hdf5File& f, const std::string& h, const LogResult& log) {
  LogComparison comparison;
  ReadFields(f, h, comparison);
  for (const std::string& channel : f.Children(h)) {
    const std::string k = h + "/" + channel;
    if (!f.IsGroup(k)) continue;
    ChannelComparison c;
    c.channel = channel;
    ReadFields(f, k, c);
    // Written before the comparison kept its units: the channel's.
    if (c.units.empty()) c.units = ChannelUnitsOf(log, channel);
    comparison.channels.push_back(std::move(c));
  }
  // Written before the comparison kept its instants, the sources held the
  // instants compared, each method beginning with the channel compared.
  if (!comparison.experiment_impact_s && !comparison.simulation_impact_s &&
      log.sources.size() == 2) {
    comparison.experiment_impact_s = log.sources[0].impact_time_s;
    comparison.simulation_impact_s = log.sources[1].impact_time_s;
    const std::string& e = log.sources[0].impact_method;
    const std::string& s = log.sources[1].impact_method;
    const std::string channel = e.substr(0, e.find(','));
    if (channel == s.substr(0, s.find(','))) comparison.impact_channel = channel;
  }
  return comparison;
}

LogResult ReadLog(const In& in, const std::string& id) {
  const Hdf5File& f = in.f;
  const std::string g = JoinPath({"logs", id});
  LogResult log;
  log.id = id;
  const std::string status = f.ReadStringAttribute(g, "status");
  log.ok = status == "ok";
  if (!log.ok) log.reason = ReasonOf(status);
  log.settings = ReadSettings(in, g + "/settings");
  for (const std::string& source : f.Children(g)) {
    const std::string h = g + "/" + source;
    if (source == "comparison" || source == "settings" || !f.IsGroup(h)) continue;
    LogSourceResult s;
    s.source = source;
    ReadFields(f, h, s);
    for (const std::string& channel : f.Children(h)) {
      const std::string k = h + "/" + channel;
      if (f.IsGroup(k)) s.channels.push_back(ReadLogChannel(f, k, channel));
    }
    log.sources.push_back(std::move(s));
  }
  const std::string h = g + "/comparison";
  if (f.Exists(h)) log.comparison = ReadLogComparison(f, h, log);
  return log;
}

void WriteKelvinVoigt(Out& out, const RunResult& run) {
  Hdf5File& f = out.f;
  const RunFits& fits = run.fits;
  const KelvinVoigtTwoPointFit& fit = *fits.kelvin_voigt;
  const std::string g = KelvinVoigtPath(run.id);
  f.CreateGroup(g);
  f.SetAttribute(g, "method", "two-point");
  f.SetAttribute(g, "separation", SeparationName(fit.separation));
  f.SetAttribute(g, "rebounds_used",
                 std::vector<long long>{fit.rebounds_used[0], fit.rebounds_used[1]});
  f.SetAttribute(g, "status", fit.ok ? std::string("ok") : "failed: " + fit.reason);
  if (!fit.ok) return;
  WriteFields(f, out.x, g, fit, out.u);
  WriteFields(f, out.x, g, fits, out.u);  // its contact time's source after the contact time
  if (!fits.model_response.time_s.empty()) {
    WriteCurve(out, g + "/response/time", fits.model_response.time_s, "s",
               g + "/response/displacement", fits.model_response.value, out.u.length);
  }
  if (!fits.model_residual.time_s.empty()) {
    WriteCurve(out, g + "/residual/time", fits.model_residual.time_s, "s",
               g + "/residual/displacement", fits.model_residual.value, out.u.length);
  }
  const std::size_t n = fit.predicted_xmax.size();
  for (const std::string& a : SameLength(g, run.measured.xmax.size(),
                                         {{"predicted_xmax", n},
                                          {"predicted_xmax_std_error", n},
                                          {"deviation", fits.deviation.size()},
                                          {"deviation_pct_peak", fits.deviation_pct_peak.size()},
                                          {"deviation_pct_x0", fits.deviation_pct_x0.size()}})) {
    out.x.AttachScale(a, RunPath(run.id) + "/rebounds/rebound");
  }
}

// When the maxima fall: measured on the traces, or (typed-in maxima) as the
// fitted model has them, which the "source" attribute says; the rebounds'
// scale and each bar's own (the maxima are the measurement's fields).
void WriteRebounds(Out& out, const RunResult& run) {
  Hdf5File& f = out.f;
  const RunMeasurement& m = run.measured;
  const std::string g = RunPath(run.id) + "/rebounds";
  const std::vector<double>& t_peak = run.PeakTimes();
  if (!t_peak.empty()) {
    f.WriteVector(g + "/t_peak", t_peak, "s");
    f.SetAttribute(g + "/t_peak", "source", std::string(run.PeakTimesSource()));
  }
  WriteReboundScale(out, g, Consecutive(0, m.xmax.size()),
                    SameLength(g, m.xmax.size(),
                               {{"xmax", m.xmax.size()},
                                {"xmax_std_error", m.xmax_sigma.size()},
                                {"t_peak", t_peak.size()},
                                {"t_peak_std_error", m.t_peak_sigma.size()},
                                {"duration", m.rebound_duration.size()},
                                {"duration_std_error", m.rebound_duration_sigma.size()}}));
  if (m.right) WriteBar(out, g + "/right", *m.right);
  if (m.left) WriteBar(out, g + "/left", *m.left);
}

void CheckRunId(const Hdf5File& f, const std::string& id) {
  if (id.find('/') != std::string::npos || id.empty() || id == "." || id == "..") {
    throw InputError({f.path(), "runs", std::nullopt},
                     fmt::format("run id \"{}\" cannot name an HDF5 group", id));
  }
}

void WriteRun(Out& out, const RunResult& run) {
  Hdf5File& f = out.f;
  CheckRunId(f, run.id);
  const std::string g = RunPath(run.id);
  f.CreateGroup(g);
  f.SetAttribute(g, "status", run.Status());
  const RunMeasurement& m = run.measured;
  WriteFields(f, out.x, g, m, out.u);
  WriteFields(f, out.x, g, run, out.u);
  // A run the manifest rejected took no time.
  if (run.initial_displacement > 0.0)
    WriteFields(f, out.x, g + "/stage_seconds", run.seconds, out.u);
  WriteSettings(out, g + "/settings", run.settings);
  if (!run.specimen.empty()) WriteFields(f, out.x, g + "/specimen", run.specimen, out.u);
  if (!m.xmax.empty()) WriteRebounds(out, run);
  if (!m.measured_displacement.time_s.empty()) {
    WriteCurve(out, g + "/displacement/time", m.measured_displacement.time_s, "s",
               g + "/displacement/average", m.measured_displacement.value, out.u.length);
  }
  for (std::size_t i = 0; i < m.overlays.size(); ++i) {
    WriteOverlay(out, fmt::format("{}/digitized/{}", g, i), m.overlays[i]);
  }
  for (const CellCalibration& c : m.calibrations) {
    WriteCalibration(out, g + "/calibration/" + c.cell, c);
  }
  if (run.fits.kelvin_voigt) WriteKelvinVoigt(out, run);
  if (const auto& fit = run.fits.kelvin_voigt_least_squares) {
    const bool per_rebound = !m.xmax.empty() && fit->predicted_xmax.size() == m.xmax.size();
    WriteLeastSquares(out, g + "/fit/kelvin_voigt_least_squares", *fit,
                      per_rebound ? g + "/rebounds/rebound" : "");
  }
  if (run.fits.poynting_thomson) {
    WriteLeastSquares(out, g + "/fit/poynting_thomson", *run.fits.poynting_thomson, "");
  }
}

void WriteSessionKelvinVoigt(Out& out, const SessionKelvinVoigt& s) {
  Hdf5File& f = out.f;
  const std::string g = "/session/kelvin_voigt";
  WriteFields(f, out.x, g, s, out.u);
  f.SetAttribute(g, "stiffness", s.average_stiffness ? "average" : "per-run");
  const std::size_t n = s.run_ids.size();
  for (const std::string& a :
       SameLength(g, n,
                  {{"sqrt_restitution", s.sqrt_restitution.size()},
                   {"stiffness", s.stiffness.size()},
                   {"stiffness_deviation", s.spread.deviation.size()},
                   {"stiffness_pct_variation", s.spread.pct_variation.size()},
                   {"damping", s.damping.size()},
                   {"damping_std_error", s.damping_sigma.size()}})) {
    out.x.AttachScale(a, g + "/run_ids");
  }
  if (s.damping_line) {
    const DampingLine& line = *s.damping_line;
    const std::string l = g + "/damping_line";
    WriteFields(f, out.x, l, line, out.u);
    f.SetAttribute(l, "equation", "C = a (1 - b sqrt(xi))  (thesis eq. 40)");
  }
}

void WritePrediction(Out& out, const RunPrediction& p) {
  Hdf5File& f = out.f;
  const std::string g = JoinPath({"predictions", p.target_run + "_from_" + p.source_run});
  WriteFields(f, out.x, g, p, out.u);
  const std::size_t n = p.predicted.size();
  WriteReboundScale(out, g, Consecutive(p.start_rebound, n),
                    SameLength(g, n,
                               {{"predicted_xmax", n},
                                {"calculated_xmax", p.calculated.size()},
                                {"deviation", p.deviation.size()},
                                {"deviation_pct_peak", p.pct_peak.size()},
                                {"deviation_pct_start", p.pct_start.size()}}));
}

// The pendulum's settings apply to runs and calibrations (a session of logs
// only has no pendulum).
bool HasPendulum(const SessionResult& r) { return !r.runs.empty() || !r.calibrations.empty(); }

void WriteAll(Hdf5File& f, const SessionResult& r) {
  const Hdf5Extras extras(f);
  const ProductRecord* thumbnails = r.FindProduct("thumbnails");
  Out out{f, extras, LabelsFor(r.units), r.settings, thumbnails == nullptr || thumbnails->made};
  f.SetAttribute("/", "layout", static_cast<long long>(kResultsLayout));
  f.SetAttribute("/", "units", std::string(UnitSystemName(r.units)));
  WriteFields(f, extras, "/", r, out.u);
  WriteSessionSettings(f, r.settings);
  if (HasPendulum(r)) {
    f.SetAttribute("/", "convention", ConventionName(r.convention));
    f.SetAttribute("/", "separation", SeparationName(r.separation));
    WriteFields(f, extras, "/apparatus", r.apparatus, out.u);
  }
  if (!r.specimen.empty()) WriteFields(f, extras, "/specimen", r.specimen, out.u);
  if (!r.products.empty()) {
    f.CreateGroup("/session/products");
    for (const ProductRecord& p : r.products)
      f.SetAttribute("/session/products", p.name, p.Status());
  }
  if (!r.runs.empty()) f.CreateGroup("/runs");
  for (const RunResult& run : r.runs) WriteRun(out, run);
  for (const CellCalibration& c : r.calibrations) {
    WriteCalibration(out, JoinPath({"calibrations", c.calibration_id}), c);
  }
  if (r.kelvin_voigt) WriteSessionKelvinVoigt(out, *r.kelvin_voigt);
  for (const PoyntingThomsonLeastSquaresFit& fit : r.joint_fits) {
    WriteLeastSquares(out, "/session/joint_fits/poynting_thomson", fit, "");
  }
  if (r.model_comparison) WriteModelComparison(out, *r.model_comparison);
  for (const ContactLawFit& fit : r.contact_laws) WriteContactLaw(out, fit);
  for (const LogResult& log : r.logs) WriteLog(out, log);
  for (const RunPrediction& p : r.predictions) WritePrediction(out, p);
}

// Layout 1 and the first files of layout 2 hold, with [reduction]
// average_stiffness, the session's K and C in place of the run's own, and say
// so in a "stiffness_source" attribute.
void ReadKelvinVoigt(const In& in, RunResult& run) {
  const Hdf5File& f = in.f;
  RunFits& fits = run.fits;
  const std::string k = KelvinVoigtPath(run.id);
  KelvinVoigtTwoPointFit fit;
  fit.separation = ParseSeparation(f.ReadStringAttribute(k, "separation"));
  const auto used = f.ReadIntegerArrayAttribute(k, "rebounds_used");
  fit.rebounds_used = {static_cast<int>(used.at(0)), static_cast<int>(used.at(1))};
  const std::string status = f.ReadStringAttribute(k, "status");
  fit.ok = status == "ok";
  if (!fit.ok) {
    // Layout 1 repeated the reason in a "diagnostic" attribute.
    fit.reason = ReasonOf(status);
  } else if (f.HasAttribute(k, "diagnostic")) {
    // An ok fit's caveat, before it was its "note".
    fit.note = f.ReadStringAttribute(k, "diagnostic");
  }
  if (fit.ok) {
    ReadFields(f, k, fit);
    ReadFields(f, k, fits);
  }
  if (f.Exists(k + "/response/time")) {
    fits.model_response = {f.ReadVector(k + "/response/time"),
                           f.ReadVector(k + "/response/displacement")};
  }
  if (f.Exists(k + "/residual/time")) {
    fits.model_residual = {f.ReadVector(k + "/residual/time"),
                           f.ReadVector(k + "/residual/displacement")};
  }
  fits.kelvin_voigt = std::move(fit);
}

// When the maxima fall (the fitted model's times for typed-in runs), and each bar's.
void ReadRebounds(const Hdf5File& f, const std::string& g, RunResult& run) {
  RunMeasurement& m = run.measured;
  if (f.Exists(g + "/rebounds/t_peak")) {
    const bool from_model = f.ReadStringAttribute(g + "/rebounds/t_peak", "source") == "model";
    (from_model ? run.fits.model_peak_times : m.t_peak) = f.ReadVector(g + "/rebounds/t_peak");
  }
  if (f.Exists(g + "/rebounds/right")) m.right = ReadBar(f, g + "/rebounds/right");
  if (f.Exists(g + "/rebounds/left")) m.left = ReadBar(f, g + "/rebounds/left");
}

// The run's status, measured values and specimen (a campaign's), and with
// `everything` its settings, bars, curves, photos, calibrations and fits.
RunResult ReadRun(const In& in, const std::string& id, ResultsReading reading) {
  const bool everything = reading == ResultsReading::kEverything;
  const Hdf5File& f = in.f;
  const std::string g = RunPath(id);
  RunResult run;
  run.id = id;
  if (everything) run.settings = ReadSettings(in, g + "/settings");
  const std::string status = f.ReadStringAttribute(g, "status");
  run.ok = status == "ok";
  if (!run.ok) run.reason = ReasonOf(status);
  RunMeasurement& m = run.measured;
  ReadFields(f, g, m);
  ReadFields(f, g, run);  // after the status and the maxima, which say what it holds
  if (f.Exists(g + "/specimen")) ReadFields(f, g + "/specimen", run.specimen);
  // Before, a session's one contact time was written here as the run's, with
  // the source "session"; the fit's "contact_time_used" holds it now.
  const bool session_contact_time = m.contact_time_source == "session";
  if (session_contact_time) {
    m.contact_time.reset();
    m.contact_time_sigma = 0.0;
    m.contact_time_source.clear();
    if (run.ok) run.fits.contact_time_source = "session";
  }
  if (reading == ResultsReading::kEstimates) return run;
  if (everything && f.Exists(g + "/stage_seconds")) {
    ReadFields(f, g + "/stage_seconds", run.seconds);
  }
  ReadRebounds(f, g, run);
  if (f.Exists(g + "/displacement/time")) {
    m.measured_displacement = {f.ReadVector(g + "/displacement/time"),
                               f.ReadVector(g + "/displacement/average")};
  }
  if (f.Exists(g + "/digitized")) {
    for (const std::string& i : f.Children(g + "/digitized")) {
      m.overlays.push_back(ReadOverlay(f, g + "/digitized/" + i));
    }
  }
  if (f.Exists(g + "/calibration")) {
    for (const std::string& cell : f.Children(g + "/calibration")) {
      m.calibrations.push_back(ReadCalibration(in, g + "/calibration/" + cell, cell));
    }
  }
  if (reading == ResultsReading::kRunMeasurements) return run;
  if (f.Exists(g + "/fit/kelvin_voigt_least_squares")) {
    run.fits.kelvin_voigt_least_squares =
        ReadLeastSquares<KelvinVoigtLeastSquaresFit>(in, g + "/fit/kelvin_voigt_least_squares");
  }
  if (f.Exists(g + "/fit/poynting_thomson")) {
    run.fits.poynting_thomson =
        ReadLeastSquares<PoyntingThomsonLeastSquaresFit>(in, g + "/fit/poynting_thomson");
  }
  if (f.Exists(KelvinVoigtPath(id))) ReadKelvinVoigt(in, run);
  return run;
}

SessionKelvinVoigt ReadSessionKelvinVoigt(const Hdf5File& f) {
  const std::string g = "/session/kelvin_voigt";
  SessionKelvinVoigt s;
  ReadFields(f, g, s);
  s.damping_sigma.resize(s.damping.size(), 0.0);  // files without them
  if (f.Exists(g + "/damping_line")) ReadFields(f, g + "/damping_line", s.damping_line.emplace());
  return s;
}

RunPrediction ReadPrediction(const Hdf5File& f, const std::string& name) {
  RunPrediction p;
  ReadFields(f, JoinPath({"predictions", name}), p);
  return p;
}

// The root's attributes and the apparatus (absent in layout 2 without runs
// or calibrations: the defaults stay).
void ReadSessionSettings(const Hdf5File& f, SessionResult& r) {
  ReadFields(f, "/", r);
  const auto units = ParseUnitSystem(f.ReadStringAttribute("/", "units"));
  if (!units) throw InputError({f.path(), "/units", std::nullopt}, "unknown unit system");
  r.units = *units;
  r.settings = ReadSessionSettingsGroup(f);
  if (f.HasAttribute("/", "convention")) {
    r.convention = ParseConvention(f.ReadStringAttribute("/", "convention"));
    r.separation = ParseSeparation(f.ReadStringAttribute("/", "separation"));
  }
  if (f.Exists("/apparatus")) ReadFields(f, "/apparatus", r.apparatus);
  if (f.Exists("/specimen")) ReadFields(f, "/specimen", r.specimen);
  if (f.Exists("/session/products")) {
    for (const std::string& name : f.AttributeNames("/session/products")) {
      const std::string status = f.ReadStringAttribute("/session/products", name);
      const std::string skipped = "skipped: ";
      r.products.push_back({name, status == "made",
                            status.starts_with(skipped) ? status.substr(skipped.size()) : ""});
    }
  }
}

std::vector<std::string> ChildrenIfPresent(const Hdf5File& f, const std::string& group) {
  return f.Exists(group) ? f.Children(group) : std::vector<std::string>{};
}

}  // namespace

void WriteResults(const SessionResult& result, const std::filesystem::path& path) {
  WriteHdf5Atomically(path, [&](Hdf5File& file) { WriteAll(file, result); });
}

namespace {

long long CheckedLayout(const Hdf5File& f) {
  const long long layout =
      f.HasAttribute("/", "layout") ? f.ReadIntegerAttribute("/", "layout") : 0;
  if (layout != 1 && layout != kResultsLayout) {
    throw InputError(
        {f.path(), "/layout", std::nullopt},
        fmt::format("not an impactlab results file of layout 1 or {}", kResultsLayout));
  }
  return layout;
}

// The session's settings and the runs `wanted` names, read as `reading` says.
SessionResult ReadSessionAndRuns(const Hdf5File& f, long long layout, ResultsReading reading,
                                 const std::function<bool(const std::string&)>& wanted) {
  SessionResult r;
  ReadSessionSettings(f, r);
  const In in{f, layout, r.settings, r.separation, r.apparatus.mass};
  for (const std::string& id : ChildrenIfPresent(f, "/runs")) {
    if (wanted(id)) r.runs.push_back(ReadRun(in, id, reading));
  }
  return r;
}

}  // namespace

SessionResult ReadRunMeasurements(const std::filesystem::path& path,
                                  const std::function<bool(const std::string&)>& wanted) {
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  return ReadSessionAndRuns(f, CheckedLayout(f), ResultsReading::kRunMeasurements, wanted);
}

SessionResult ReadResults(const std::filesystem::path& path, ResultsReading reading) {
  const bool everything = reading == ResultsReading::kEverything;
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  const long long layout = CheckedLayout(f);
  SessionResult r = ReadSessionAndRuns(f, layout, reading, [](const std::string&) { return true; });
  const In in{f, layout, r.settings, r.separation, r.apparatus.mass};
  if (f.Exists("/session/model_comparison")) r.model_comparison = ReadModelComparison(f);
  for (const std::string& law : ChildrenIfPresent(f, "/session/contact_laws")) {
    r.contact_laws.push_back(ReadContactLaw(f, law));
  }
  if (!everything) return r;
  for (const std::string& id : ChildrenIfPresent(f, "/calibrations")) {
    r.calibrations.push_back(ReadCalibration(in, JoinPath({"calibrations", id}), ""));
  }
  if (f.Exists("/session/kelvin_voigt")) r.kelvin_voigt = ReadSessionKelvinVoigt(f);
  for (const std::string& id : ChildrenIfPresent(f, "/logs")) r.logs.push_back(ReadLog(in, id));
  if (f.Exists("/session/joint_fits/poynting_thomson")) {
    r.joint_fits.push_back(ReadLeastSquares<PoyntingThomsonLeastSquaresFit>(
        in, "/session/joint_fits/poynting_thomson"));
  }
  for (const std::string& name : ChildrenIfPresent(f, "/predictions")) {
    r.predictions.push_back(ReadPrediction(f, name));
  }
  return r;
}

}  // namespace impactlab
