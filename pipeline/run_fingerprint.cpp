#include "pipeline/run_fingerprint.h"

#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <memory>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/session_file.h"
#include "model/contact.h"
#include "pipeline/stage_options.h"

namespace impactlab {
namespace {

// Streams every value with a separator, so that adjacent fields cannot alias.
class Hasher {
 public:
  Hasher() : state_(XXH3_createState(), XXH3_freeState) { XXH3_128bits_reset(state_.get()); }

  Hasher& Add(const std::string& text) {
    XXH3_128bits_update(state_.get(), text.data(), text.size());
    XXH3_128bits_update(state_.get(), "\x1f", 1);
    return *this;
  }
  Hasher& Add(double value) { return Add(fmt::format("{:a}", value)); }  // exact bits
  Hasher& Add(int value) { return Add(std::to_string(value)); }
  Hasher& Add(std::size_t value) { return Add(std::to_string(value)); }
  Hasher& Add(long long value) { return Add(std::to_string(value)); }
  Hasher& Add(bool value) { return Add(std::string(value ? "true" : "false")); }

  // A file of the session, read as every session file is (io/session_file.h):
  // from inside `folder` only, never a pipe that would block the hash.
  Hasher& AddFile(const std::filesystem::path& folder, const std::filesystem::path& path) {
    const SessionFile file(folder, path);
    std::array<char, 1 << 16> buffer{};
    while (true) {
      const ssize_t n = ::read(file.descriptor(), buffer.data(), buffer.size());
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw InputError({path, "", std::nullopt}, "cannot read the file");
      if (n == 0) break;
      XXH3_128bits_update(state_.get(), buffer.data(), static_cast<std::size_t>(n));
    }
    return Add(path.filename().string());
  }

  std::string Hex() const {
    const XXH128_hash_t h = XXH3_128bits_digest(state_.get());
    return fmt::format("{:016x}{:016x}", h.high64, h.low64);
  }

 private:
  std::unique_ptr<XXH3_state_t, XXH_errorcode (*)(XXH3_state_t*)> state_;
};

void AddTrace(Hasher& h, const std::filesystem::path& folder, const TraceSettings& s) {
  h.Add(s.time_per_div).Add(s.volts_per_div).Add(s.zero_div).Add(s.band_div[0]).Add(s.band_div[1]);
  h.Add(s.t0_div).Add(s.impact ? std::to_string(*s.impact) : "-");
  if (s.csv) h.AddFile(folder, *s.csv);
  // A manual hint changes what is measured: a hinted photo is measured afresh.
  h.Add(s.points_px.size());
  for (const auto& [x, y] : s.points_px) h.Add(x).Add(y);
}

void AddCorners(Hasher& h, const std::optional<GraticuleCorners>& corners) {
  h.Add(corners.has_value());
  if (corners) {
    for (const auto& [x, y] : *corners) h.Add(x).Add(y);
  }
}

// An options struct's settings (options/settings.h), key and value, and its
// size, so that a field added but not listed as a setting still changes it.
template <typename Options>
void AddSettings(Hasher& h, const std::string& stage, const Options& options) {
  h.Add(stage).Add(sizeof(Options));
  ForEachSetting(options, [&](const std::string& key, const auto& field, const char*) {
    h.Add(key);
    std::visit([&](const auto& value) { h.Add(value); }, ToSettingValue(field));
  });
}

}  // namespace

std::string RunFingerprint(const Run& run, const Session& session, const ReduceOptions& options) {
  Hasher h;
  h.Add(options.producer).Add(std::string(UnitSystemName(session.units)));
  // The settings as reduce resolves them: an override, else the manifest's.
  const PendulumConvention convention =
      options.convention.value_or(ParseConvention(session.reduction.convention));
  const Separation separation =
      options.separation.value_or(ParseSeparation(session.reduction.separation));
  h.Add(std::string(ConventionName(convention))).Add(std::string(SeparationName(separation)));
  // Not the products asked for (--only, [products]): a measurement is the
  // same whatever is made of it, so asking for more later re-measures nothing.
  if (session.apparatus) {
    h.Add(session.apparatus->pendulum_length).Add(session.apparatus->mass);
    h.Add(session.apparatus->gravity);
  }
  h.Add(session.divisions[0]).Add(session.divisions[1]);
  h.Add(run.id).Add(run.initial_displacement).Add(run.first_rebound);
  for (double x : run.rebounds) h.Add(x);
  h.Add(run.contact_time.value_or(-1.0)).Add(run.rebound_uncertainty.value_or(-1.0));
  h.Add(run.contact_time_uncertainty.value_or(-1.0));
  if (run.photo) h.AddFile(session.folder, *run.photo);
  AddCorners(h, run.graticule_corners_px);
  for (const auto& [name, trace] : run.traces) {
    h.Add(name);
    AddTrace(h, session.folder, trace);
  }
  // The settings the measurement uses, as the run resolves them: a setting
  // changed for one run, or for photos only, re-measures just those runs.
  const StageOptions session_options =
      SessionStageOptions(options.stages, session, options.overrides);
  if (!run.HasTypedRebounds()) {
    const StageOptions run_options =
        EntryStageOptions(session_options, run.settings, options.overrides);
    const bool from_photo = std::any_of(run.traces.begin(), run.traces.end(),
                                        [](const auto& t) { return !t.second.csv; });
    if (run.photo && from_photo) AddSettings(h, "digitize", run_options.digitize);
    AddSettings(h, "rebound_extraction", run_options.rebound_extraction);
  }
  for (const auto& [cell, id] : run.calibration) {
    h.Add(cell).Add(id);
    const auto c = std::find_if(session.calibrations.begin(), session.calibrations.end(),
                                [&](const Calibration& k) { return k.id == id; });
    if (c == session.calibrations.end()) continue;
    h.Add(c->cell).Add(c->initial_displacement);
    if (c->photo) h.AddFile(session.folder, *c->photo);
    AddCorners(h, c->graticule_corners_px);
    AddTrace(h, session.folder, c->trace);
    const StageOptions calibration_options =
        EntryStageOptions(session_options, c->settings, options.overrides);
    if (c->photo && !c->trace.csv) AddSettings(h, "digitize", calibration_options.digitize);
    AddSettings(h, "photocell", calibration_options.photocell);
    AddSettings(h, "limits", calibration_options.rebound_extraction.limits);
  }
  return h.Hex();
}

namespace {

// The first value of `values` that is not finite, as "name[i] is nan".
std::string NotFinite(const std::string& name, const std::vector<double>& values) {
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) return fmt::format("{}[{}] is {}", name, i, values[i]);
  }
  return {};
}

std::string NotFinite(const std::string& name, double value) {
  return std::isfinite(value) ? std::string() : fmt::format("{} is {}", name, value);
}

std::string SizesDiffer(const std::string& a, std::size_t size_a, const std::string& b,
                        std::size_t size_b) {
  return size_a == size_b ? std::string()
                          : fmt::format("{} has {} values but {} has {}", a, size_a, b, size_b);
}

std::string BarProblem(const std::string& name, const BarRebounds& bar) {
  const std::pair<const char*, const std::vector<double>*> fields[] = {
      {"xmax", &bar.xmax},
      {"xmax_std_error", &bar.xmax_sigma},
      {"t_peak", &bar.t_peak},
      {"t_peak_std_error", &bar.t_peak_sigma},
      {"duration", &bar.duration}};
  for (const auto& [field, values] : fields) {
    const std::string full = name + "/" + field;
    if (std::string p = NotFinite(full, *values); !p.empty()) return p;
    if (std::string p = SizesDiffer(name + "/xmax", bar.xmax.size(), full, values->size());
        !p.empty())
      return p;
  }
  if (!bar.rebound.empty()) {
    return SizesDiffer(name + "/xmax", bar.xmax.size(), name + "/rebound", bar.rebound.size());
  }
  return {};
}

}  // namespace

std::string ReuseProblem(const RunMeasurement& r) {
  if (r.xmax.empty()) return "it has no xmax";
  const std::vector<std::pair<std::string, const std::vector<double>*>> vectors = {
      {"xmax", &r.xmax},
      {"xmax_std_error", &r.xmax_sigma},
      {"t_peak", &r.t_peak},
      {"t_peak_std_error", &r.t_peak_sigma},
      {"duration", &r.rebound_duration},
      {"displacement/time", &r.measured_displacement.time_s},
      {"displacement/average", &r.measured_displacement.value}};
  for (const auto& [name, values] : vectors) {
    if (std::string p = NotFinite(name, *values); !p.empty()) return p;
  }
  const std::string sizes[] = {
      SizesDiffer("xmax", r.xmax.size(), "xmax_std_error", r.xmax_sigma.size()),
      r.t_peak.empty() ? std::string()
                       : SizesDiffer("xmax", r.xmax.size(), "t_peak", r.t_peak.size()),
      r.t_peak_sigma.empty()
          ? std::string()
          : SizesDiffer("t_peak", r.t_peak.size(), "t_peak_std_error", r.t_peak_sigma.size()),
      r.rebound_duration.empty()
          ? std::string()
          : SizesDiffer("xmax", r.xmax.size(), "duration", r.rebound_duration.size()),
      SizesDiffer("displacement/time", r.measured_displacement.time_s.size(),
                  "displacement/average", r.measured_displacement.value.size())};
  for (const std::string& p : sizes) {
    if (!p.empty()) return p;
  }
  for (std::size_t i = 0; i < r.xmax.size(); ++i) {
    if (!(r.xmax[i] > 0.0)) return fmt::format("xmax[{}] is {}, not positive", i, r.xmax[i]);
    if (r.xmax_sigma[i] < 0.0) return fmt::format("xmax_std_error[{}] is negative", i);
  }
  for (std::size_t i = 1; i < r.measured_displacement.time_s.size(); ++i) {
    if (!(r.measured_displacement.time_s[i] > r.measured_displacement.time_s[i - 1])) {
      return fmt::format("displacement/time does not increase at [{}]", i);
    }
  }
  if (r.contact_time) {
    if (std::string p = NotFinite("contact_time", *r.contact_time); !p.empty()) return p;
    if (std::string p = NotFinite("contact_time_std_error", r.contact_time_sigma); !p.empty())
      return p;
  }
  if (r.right) {
    if (std::string p = BarProblem("rebounds/right", *r.right); !p.empty()) return p;
  }
  if (r.left) {
    if (std::string p = BarProblem("rebounds/left", *r.left); !p.empty()) return p;
  }
  for (std::size_t k = 0; k < r.overlays.size(); ++k) {
    const PhotoOverlay& o = r.overlays[k];
    const std::string g = fmt::format("digitized[{}]/", k);
    if (std::string p = NotFinite(g + "graticule_residual", o.graticule_residual_px); !p.empty())
      return p;
    if (std::string p = NotFinite(g + "trace_coverage", o.trace_coverage); !p.empty()) return p;
    if (std::string p = SizesDiffer(g + "trace_names", o.trace_names.size(), g + "trace_coverage",
                                    o.trace_coverage.size());
        !p.empty())
      return p;
  }
  for (const CellCalibration& c : r.calibrations) {
    const std::string g = "calibration/" + c.cell;
    const std::pair<const char*, double> scalars[] = {
        {"release_x", c.release_x},
        {"residual_rms_volts", c.residual_rms_volts},
        {"residual_rms_length", c.residual_rms_length},
        {"volts_min", c.volts_min},
        {"volts_max", c.volts_max}};
    for (const auto& [name, value] : scalars) {
      if (std::string p = NotFinite(g + "/" + name, value); !p.empty()) return p;
    }
    const std::pair<const char*, const std::vector<double>*> vectors[] = {
        {"chebyshev", &c.chebyshev}, {"points_x", &c.points_x}, {"points_volts", &c.points_volts},
        {"left_out_from", &c.left_out_from_s}, {"left_out_to", &c.left_out_to_s}};
    for (const auto& [name, values] : vectors) {
      if (std::string p = NotFinite(g + "/" + name, *values); !p.empty()) return p;
    }
    if (std::string p = SizesDiffer(g + "/points_x", c.points_x.size(), g + "/points_volts",
                                    c.points_volts.size());
        !p.empty())
      return p;
  }
  return {};
}

}  // namespace impactlab
