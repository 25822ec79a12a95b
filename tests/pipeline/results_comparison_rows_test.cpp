// A results file written before the model comparison kept its fits whole
// still reads. The fixture tests/pipeline/data/comparison-rows/results.h5 was
// written by that writer (each model, restitution model or contact law, a row
// of the same names) from the session beside it; what it kept reads as a
// reduce of that session makes it today, and the report shows it the same.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "report/tables.h"
#include "tests/pipeline/every_field.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

const std::filesystem::path kFixture =
    std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "tests" / "pipeline" / "data" / "comparison-rows";

void CheckSameParameters(const std::vector<NamedEstimate>& a, const std::vector<NamedEstimate>& b) {
  REQUIRE(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    INFO(a[i].name);
    CHECK(a[i].name == b[i].name);
    CHECK(a[i].units == b[i].units);
    CHECK(a[i].estimate.value == b[i].estimate.value);
    CHECK(a[i].estimate.sigma == b[i].estimate.sigma);
  }
}

const Table& Named(const std::vector<Table>& tables, const std::string& name) {
  for (const Table& t : tables) {
    if (t.name == name) return t;
  }
  FAIL("no table " << name);
  return tables.front();
}

std::vector<std::vector<std::string>> Texts(const Table& t) {
  std::vector<std::vector<std::string>> out;
  for (const std::vector<Cell>& row : t.rows) {
    out.emplace_back();
    for (const Cell& c : row) out.back().push_back(c.text);
  }
  return out;
}

TEST_CASE(
    "results_comparison_rows: a comparison written as rows reads as today's reduce makes it") {
  const SessionResult old = ReadResults(kFixture / "results.h5");
  ReduceOptions options;
  options.jobs = 2;
  const SessionResult today = ReduceSession(ReadManifest(kFixture).session, options);
  REQUIRE(old.model_comparison);
  REQUIRE(today.model_comparison);
  const ModelComparison &a = *old.model_comparison, &b = *today.model_comparison;
  CHECK(a.run_ids == b.run_ids);
  CHECK(a.best_by_bic == b.best_by_bic);
  CHECK(a.best_by_leave_one_out == b.best_by_leave_one_out);
  CHECK(a.evidence == b.evidence);

  REQUIRE(a.restitution_models.size() == 3);
  REQUIRE(b.restitution_models.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    const JointModelFit &p = a.restitution_models[i].fit, &q = b.restitution_models[i].fit;
    INFO(q.name);
    CHECK(p.name == q.name);
    CHECK(p.ok == q.ok);
    CHECK(a.restitution_models[i].verdict == b.restitution_models[i].verdict);
    CheckSameParameters(p.parameters, q.parameters);
    CHECK((p.maxima == q.maxima && p.parameter_count == q.parameter_count && p.dof == q.dof));
    CHECK(p.chi2 == q.chi2);
    CHECK(p.aic == q.aic);
    CHECK(p.bic == q.bic);
    CHECK(p.log_restitution_spread == q.log_restitution_spread);
    CHECK(p.leave_one_out.rms_normalized == q.leave_one_out.rms_normalized);
    CHECK(p.leave_one_out.rms_length == q.leave_one_out.rms_length);
    // Not written then: complete where its RMS was; the count and u_ref unknown.
    CHECK(p.leave_one_out.ok == q.leave_one_out.ok);
    CHECK(p.leave_one_out.maxima == 0);
    CHECK(p.reference_speed == 0.0);
    CHECK(p.covariance.names == q.covariance.names);
    REQUIRE(p.covariance.matrix.size() == q.covariance.matrix.size());
    for (std::size_t k = 0; k < p.covariance.matrix.size(); ++k) {
      CHECK(p.covariance.matrix[k] == Approx(q.covariance.matrix[k]).epsilon(1e-12));
    }
  }
  // The laws' rows: their figures, and the scatter check as the fit makes it.
  REQUIRE(a.contact_laws.size() == 2);
  REQUIRE(b.contact_laws.size() == 2);
  int fitted = 0;
  for (std::size_t i = 0; i < 2; ++i) {
    const ContactLawFit &p = a.contact_laws[i].fit, &q = b.contact_laws[i].fit;
    INFO(q.law);
    CHECK(p.law == q.law);
    CHECK(p.ok == q.ok);
    CHECK(p.reason == q.reason);
    CHECK(a.contact_laws[i].verdict == b.contact_laws[i].verdict);
    CHECK(a.contact_laws[i].log_restitution_spread == b.contact_laws[i].log_restitution_spread);
    CHECK(a.contact_laws[i].Ran() == b.contact_laws[i].Ran());
    if (!q.ok) continue;
    CheckSameParameters(p.parameters, q.parameters);
    CHECK((p.maxima == q.maxima && p.parameter_count == q.parameter_count && p.dof == q.dof));
    CHECK(p.chi2 == q.chi2);
    CHECK(p.bic == q.bic);
    CHECK(p.loo_ok == q.loo_ok);
    CHECK(p.loo_rms_normalized == q.loo_rms_normalized);
    CHECK(p.scatter.excess == q.scatter.excess);
    CHECK(p.scatter.birge_ratio == Approx(q.scatter.birge_ratio).epsilon(1e-12));
    CHECK(p.identifiability.empty());  // not written then
    ++fitted;
  }
  CHECK(fitted >= 1);

  // The report's comparison tables are the same, the laws' scaled errors included.
  const std::vector<Table> from_file = BuildTables(old), reduced = BuildTables(today);
  for (const char* name : {"model_comparison", "model_comparison_parameters"}) {
    INFO(name);
    CHECK(Texts(Named(from_file, name)) == Texts(Named(reduced, name)));
  }

  // Written again in today's layout, it reads the same.
  testing::TempDir dir;
  WriteResults(old, dir.path() / "again.h5");
  const SessionResult again = ReadResults(dir.path() / "again.h5");
  REQUIRE(again.model_comparison);
  CHECK(testing::EveryField(*again.model_comparison) == testing::EveryField(a));
  REQUIRE(again.model_comparison->restitution_models.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(testing::EveryField(again.model_comparison->restitution_models[i]) ==
          testing::EveryField(a.restitution_models[i]));
  }
  REQUIRE(again.model_comparison->contact_laws.size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    CHECK(testing::EveryField(again.model_comparison->contact_laws[i]) ==
          testing::EveryField(a.contact_laws[i]));
  }
}

}  // namespace
}  // namespace impactlab
