// Results files of layout 1 still read: `reduce` reuses the measurements of an
// earlier results file, which may be of layout 1. The fixture
// tests/pipeline/data/layout1/results.h5 was written by the layout-1 writer
// from the session beside it.
#include <cmath>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/hdf5_file.h"
#include "pipeline/results_file.h"
#include "tests/pipeline/every_field.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

const std::filesystem::path kLayout1 = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "tests" /
                                       "pipeline" / "data" / "layout1" / "results.h5";

// Equal, or both NaN (a value the file stores as it was computed).
bool Same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
bool Same(const Estimate& a, const Estimate& b) {
  return Same(a.value, b.value) && Same(a.sigma, b.sigma);
}
bool Same(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!Same(a[i], b[i])) return false;
  }
  return true;
}
bool Same(const std::optional<Estimate>& a, const std::optional<Estimate>& b) {
  return a.has_value() == b.has_value() && (!a || Same(*a, *b));
}
bool Same(const std::vector<NamedEstimate>& a, const std::vector<NamedEstimate>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].name != b[i].name || a[i].units != b[i].units || !Same(a[i].estimate, b[i].estimate))
      return false;
  }
  return true;
}

// Every field the file keeps of a least-squares fit (its list, its status,
// the correlation's rows).
template <typename Fit>
void CheckSame(const std::optional<Fit>& a, const std::optional<Fit>& b) {
  REQUIRE(a.has_value() == b.has_value());
  if (!a) return;
  CHECK(a->ok == b->ok);
  CHECK(a->reason == b->reason);
  CHECK(a->covariance.names == b->covariance.names);
  CHECK(testing::EveryField(*a) == testing::EveryField(*b));
}

void CheckSame(const RunResult& a, const RunResult& b) {
  INFO("run " << a.id);
  CHECK(a.id == b.id);
  CHECK(a.fingerprint == b.fingerprint);
  CHECK(a.ok == b.ok);
  CHECK(a.reason == b.reason);
  CHECK(a.measured.source == b.measured.source);
  CHECK(Same(a.initial_displacement, b.initial_displacement));
  CHECK(a.first_rebound == b.first_rebound);
  CHECK(Same(a.measured.xmax, b.measured.xmax));
  CHECK(Same(a.measured.xmax_sigma, b.measured.xmax_sigma));
  CHECK(Same(a.measured.t_peak, b.measured.t_peak));
  CHECK(Same(a.measured.t_peak_sigma, b.measured.t_peak_sigma));
  CHECK(std::string(a.PeakTimesSource()) == b.PeakTimesSource());
  CHECK(a.measured.contact_time == b.measured.contact_time);
  CHECK(Same(a.measured.contact_time_sigma, b.measured.contact_time_sigma));
  CHECK(a.measured.contact_time_source == b.measured.contact_time_source);
  CHECK(Same(a.fits.model_response.time_s, b.fits.model_response.time_s));
  CHECK(Same(a.fits.model_response.value, b.fits.model_response.value));
  CHECK(a.fits.contact_time_source == b.fits.contact_time_source);
  CHECK(Same(a.fits.deviation, b.fits.deviation));
  CHECK(Same(a.fits.deviation_pct_peak, b.fits.deviation_pct_peak));
  CHECK(Same(a.fits.deviation_pct_x0, b.fits.deviation_pct_x0));
  REQUIRE(a.fits.kelvin_voigt.has_value() == b.fits.kelvin_voigt.has_value());
  if (a.fits.kelvin_voigt) {
    const KelvinVoigtTwoPointFit &p = *a.fits.kelvin_voigt, &q = *b.fits.kelvin_voigt;
    CHECK(p.ok == q.ok);
    CHECK(p.reason == q.reason);
    CHECK(p.separation == q.separation);
    CHECK(p.rebounds_used == q.rebounds_used);
    CHECK(Same(p.damping_ratio, q.damping_ratio));
    CHECK(Same(p.restitution, q.restitution));
    CHECK(Same(p.log_restitution, q.log_restitution));
    CHECK(Same(p.stiffness, q.stiffness));
    CHECK(Same(p.damping, q.damping));
    CHECK(p.contact_time == q.contact_time);
    REQUIRE(p.predicted_xmax.size() == q.predicted_xmax.size());
    for (std::size_t i = 0; i < p.predicted_xmax.size(); ++i) {
      CHECK(Same(p.predicted_xmax[i], q.predicted_xmax[i]));
    }
  }
  CheckSame(a.fits.kelvin_voigt_least_squares, b.fits.kelvin_voigt_least_squares);
  CheckSame(a.fits.poynting_thomson, b.fits.poynting_thomson);
}

void CheckSame(const ModelComparison& a, const ModelComparison& b) {
  CHECK(a.run_ids == b.run_ids);
  CHECK(a.best_by_leave_one_out == b.best_by_leave_one_out);
  CHECK(a.best_by_bic == b.best_by_bic);
  // Every field the file keeps of each model: its list, its status, its parameters.
  const auto same_models = [](const auto& x, const auto& y) {
    REQUIRE(x.size() == y.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      INFO("model " << x[i].Name());
      CHECK(x[i].Name() == y[i].Name());
      CHECK(x[i].fit.ok == y[i].fit.ok);
      CHECK(x[i].fit.reason == y[i].fit.reason);
      CHECK(Same(x[i].fit.parameters, y[i].fit.parameters));
      CHECK(testing::EveryField(x[i]) == testing::EveryField(y[i]));
    }
  };
  same_models(a.restitution_models, b.restitution_models);
  same_models(a.contact_laws, b.contact_laws);
}

// Everything ReadResults reads of a typed-in session.
void CheckSame(const SessionResult& a, const SessionResult& b) {
  CHECK(a.title == b.title);
  CHECK(a.units == b.units);
  CHECK(a.producer == b.producer);
  CHECK(a.created == b.created);
  CHECK(a.session_folder == b.session_folder);
  CHECK(Same(
      std::vector<double>{a.apparatus.pendulum_length, a.apparatus.mass, a.apparatus.gravity},
      std::vector<double>{b.apparatus.pendulum_length, b.apparatus.mass, b.apparatus.gravity}));
  CHECK(a.convention == b.convention);
  CHECK(a.separation == b.separation);
  CHECK(a.session_contact_time == b.session_contact_time);
  CHECK(a.warnings == b.warnings);
  REQUIRE(a.runs.size() == b.runs.size());
  for (std::size_t i = 0; i < a.runs.size(); ++i) CheckSame(a.runs[i], b.runs[i]);
  REQUIRE(a.kelvin_voigt.has_value() == b.kelvin_voigt.has_value());
  if (a.kelvin_voigt) {
    const SessionKelvinVoigt &p = *a.kelvin_voigt, &q = *b.kelvin_voigt;
    CHECK(p.run_ids == q.run_ids);
    CHECK(Same(p.sqrt_restitution, q.sqrt_restitution));
    CHECK(Same(p.stiffness, q.stiffness));
    CHECK(Same(p.damping, q.damping));
    CHECK(Same(p.spread.average, q.spread.average));
    CHECK(Same(p.spread.deviation, q.spread.deviation));
    CHECK(Same(p.spread.pct_variation, q.spread.pct_variation));
    REQUIRE(p.average_stiffness.has_value() == q.average_stiffness.has_value());
    if (p.average_stiffness) CHECK(Same(*p.average_stiffness, *q.average_stiffness));
    CHECK(Same(p.damping_sigma, q.damping_sigma));
    REQUIRE(p.damping_line.has_value() == q.damping_line.has_value());
    if (p.damping_line) {
      CHECK(Same(p.damping_line->a, q.damping_line->a));
      CHECK(Same(p.damping_line->b, q.damping_line->b));
      CHECK(Same(p.damping_line->correlation_ab, q.damping_line->correlation_ab));
      CHECK(Same(p.damping_line->rms_residual, q.damping_line->rms_residual));
      CHECK(p.damping_line->points == q.damping_line->points);
    }
  }
  REQUIRE(a.joint_fits.size() == b.joint_fits.size());
  for (std::size_t i = 0; i < a.joint_fits.size(); ++i) {
    CheckSame(std::optional(a.joint_fits[i]), std::optional(b.joint_fits[i]));
  }
  REQUIRE(a.model_comparison.has_value() == b.model_comparison.has_value());
  if (a.model_comparison) CheckSame(*a.model_comparison, *b.model_comparison);
  REQUIRE(a.predictions.size() == b.predictions.size());
  for (std::size_t i = 0; i < a.predictions.size(); ++i) {
    const RunPrediction &p = a.predictions[i], &q = b.predictions[i];
    CHECK(p.source_run == q.source_run);
    CHECK(p.target_run == q.target_run);
    CHECK(p.start_rebound == q.start_rebound);
    CHECK(Same(p.start_xmax, q.start_xmax));
    CHECK(Same(p.predicted, q.predicted));
    CHECK(Same(p.calculated, q.calculated));
    CHECK(Same(p.deviation, q.deviation));
    CHECK(Same(p.pct_peak, q.pct_peak));
    CHECK(Same(p.pct_start, q.pct_start));
  }
}

TEST_CASE("results_layout1: a layout-1 file reads with its values where they were written") {
  REQUIRE(Hdf5File::OpenReadOnly(kLayout1).ReadIntegerAttribute("/", "layout") == 1);
  const SessionResult r = ReadResults(kLayout1);
  CHECK(r.title == "Layout-1 fixture (three thesis runs and a failing pair)");
  CHECK(r.apparatus.pendulum_length == 22.0);
  REQUIRE(r.runs.size() == 4);
  CHECK(r.runs[0].id == "0.234");  // manifest order
  const RunResult& run = r.runs[2];
  CHECK(run.id == "0.405");
  CHECK(run.ok);
  CHECK(run.measured.source == "typed-in");
  CHECK(run.measured.xmax == std::vector<double>{0.293, 0.195, 0.117, 0.060, 0.053});
  CHECK(std::string(run.PeakTimesSource()) == "model");
  // The session's one contact time is the fit's, not the run's.
  CHECK_FALSE(run.measured.contact_time.has_value());
  CHECK(run.fits.contact_time_source == "session");
  CHECK(run.fits.kelvin_voigt->contact_time.has_value());
  REQUIRE(run.fits.kelvin_voigt.has_value());
  CHECK(run.fits.kelvin_voigt->stiffness->value == Approx(460000).epsilon(0.05));
  CHECK(run.fits.model_response.time_s.size() == run.fits.model_response.value.size());
  REQUIRE(run.fits.kelvin_voigt_least_squares);
  const KelvinVoigtLeastSquaresFit& kv = *run.fits.kelvin_voigt_least_squares;
  CHECK(kv.ok);
  CHECK_THAT(kv.status.message, Catch::StartsWith("Function tolerance reached"));
  CHECK(kv.covariance.names == std::vector<std::string>{"zeta", "v0"});
  CHECK(kv.covariance.correlation.size() == 4);
  REQUIRE(run.fits.poynting_thomson);
  const PoyntingThomsonLeastSquaresFit& pt = *run.fits.poynting_thomson;
  CHECK(!pt.ok);
  CHECK_THAT(pt.reason, Catch::StartsWith("not identifiable"));
  CHECK(pt.status.Ran());
  CHECK(pt.covariance.correlation.size() == 16);
  CHECK(pt.model.stiffness1 == pt.stiffness1.value);

  const RunResult& rising = r.runs[3];
  CHECK(!rising.ok);
  CHECK_THAT(rising.reason, Catch::Contains("the pair shows no dissipation"));
  REQUIRE(rising.fits.kelvin_voigt.has_value());
  CHECK(!rising.fits.kelvin_voigt->ok);
  CHECK_THAT(rising.fits.kelvin_voigt->reason, Catch::StartsWith("rebound 1 (0.18) exceeds"));

  REQUIRE(r.joint_fits.size() == 1);
  CHECK(r.joint_fits[0].covariance.correlation.size() == 36);
  REQUIRE(r.model_comparison.has_value());
  REQUIRE(r.model_comparison->restitution_models.size() == 3);
  CHECK(r.model_comparison->contact_laws.empty());
  // Written before the restitution models kept their leave-one-out's
  // completeness: complete where its RMS was written.
  for (const ComparedRestitutionModel& m : r.model_comparison->restitution_models) {
    INFO(m.Name());
    CHECK(m.fit.leave_one_out.ok == (m.fit.leave_one_out.rms_normalized > 0.0));
    CHECK(m.fit.maxima > 0);
    CHECK(m.verdict.empty());  // layout 1 had no verdicts
  }
  REQUIRE(r.predictions.size() == 1);
  CHECK(r.predictions[0].target_run == "0.405");
}

TEST_CASE("results_layout1: a layout-1 file written again in today's layout reads the same") {
  testing::TempDir dir;
  const SessionResult layout1 = ReadResults(kLayout1);
  WriteResults(layout1, dir.path() / "again.h5");
  CHECK(Hdf5File::OpenReadOnly(dir.path() / "again.h5").ReadIntegerAttribute("/", "layout") ==
        kResultsLayout);
  CheckSame(ReadResults(dir.path() / "again.h5"), layout1);
}

}  // namespace
}  // namespace impactlab
