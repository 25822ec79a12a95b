// The session-level products (pipeline/products.h): made when asked for and
// when the session's data can inform them, each recorded with why not.
#include <fstream>
#include <iterator>
#include <string>
#include <variant>

#include <catch2/catch.hpp>

#include "io/hdf5_file.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "tests/support/sample_data.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

using testing::kSampleData;

const ContactLawFit* Law(const SessionResult& r, const std::string& name) {
  for (const ContactLawFit& fit : r.contact_laws) {
    if (fit.law == name) return &fit;
  }
  return nullptr;
}

std::string StatusOf(const SessionResult& r, const std::string& product) {
  const ProductRecord* p = r.FindProduct(product);
  return p == nullptr ? "(none)" : p->Status();
}

TEST_CASE(
    "products: the defaults reproduce the thesis session's fits, and skip what it cannot fix") {
  const SessionResult r = ReduceSession(ReadManifest(kSampleData / "thesis-1969").session, {});
  // Values as the reduce gave them before products were chosen (commit 5feb5ca).
  const ContactLawFit* hc = Law(r, "hunt-crossley");
  const ContactLawFit* kv = Law(r, "kelvin-voigt");
  REQUIRE(hc != nullptr);
  REQUIRE(kv != nullptr);
  CHECK(hc->parameters.at(0).estimate.value == Approx(0.22885522879628764).epsilon(1e-12));
  CHECK(hc->loo_rms_normalized == Approx(175.95748805540356).epsilon(1e-12));
  REQUIRE(hc->intervals.size() == 1);
  CHECK(hc->intervals[0].upper == Approx(0.25168016308582652).epsilon(1e-12));
  CHECK(kv->parameters.at(0).estimate.value == Approx(0.10071696711663014).epsilon(1e-12));
  REQUIRE(r.model_comparison);
  CHECK(r.model_comparison->best_by_leave_one_out == "common");
  CHECK_FALSE(r.joint_fits.empty());
  for (const char* made : {"model_comparison", "joint_fits", "contact_laws.kelvin_voigt",
                           "contact_laws.hunt_crossley", "intervals", "leave_one_out"}) {
    INFO(made);
    CHECK(StatusOf(r, made) == "made");
  }
  // No run has its own contact time: Hertz has nothing to fit, n and the
  // damper's k are not fixed. They are not fitted, and the record says why.
  CHECK(r.contact_laws.size() == 2);
  for (const char* skipped :
       {"contact_laws.hertz", "contact_laws.hunt_crossley_n", "contact_laws.hertz_damper"}) {
    INFO(skipped);
    CHECK_THAT(StatusOf(r, skipped), Catch::StartsWith("skipped: the data cannot inform it: ") &&
                                         Catch::Contains("contact time"));
  }
  CHECK(StatusOf(r, "thumbnails") ==
        "skipped: the data cannot inform it: the session has no digitized photo");
}

TEST_CASE("products: a two-run session does not run leave-one-out, and says why") {
  Session session = ReadManifest(kSampleData / "thesis-1969").session;
  session.runs.resize(2);
  const SessionResult r = ReduceSession(session, {});
  CHECK_THAT(StatusOf(r, "leave_one_out"),
             Catch::Equals("skipped: the data cannot inform it: leave-one-out needs three runs "
                           "whose maxima all carry an uncertainty, found 2"));
  CHECK_THAT(
      StatusOf(r, "model_comparison"),
      Catch::StartsWith("skipped: the data cannot inform it: ") && Catch::Contains("three runs"));
  CHECK_FALSE(r.model_comparison);
  const ContactLawFit* hc = Law(r, "hunt-crossley");
  REQUIRE(hc != nullptr);
  CHECK(hc->ok);
  CHECK_FALSE(hc->loo_ok);
  CHECK(hc->loo_maxima == 0);
  // The file keeps the record, and no leave-one-out figure it did not compute.
  testing::TempDir dir;
  WriteResults(r, dir.path() / "two.h5");
  const SessionResult read = ReadResults(dir.path() / "two.h5");
  CHECK(StatusOf(read, "leave_one_out") == StatusOf(r, "leave_one_out"));
  CHECK(StatusOf(read, "contact_laws.kelvin_voigt") == "made");
  REQUIRE(Law(read, "hunt-crossley") != nullptr);
  CHECK_FALSE(Law(read, "hunt-crossley")->loo_ok);
}

TEST_CASE("products: what is not asked for is not made, and the rest is unchanged") {
  const Session session = ReadManifest(kSampleData / "thesis-1969").session;
  const SessionResult all = ReduceSession(session, {});
  ReduceOptions options;
  options.overrides = CommandLineSettings({{"products.leave_one_out", "false"},
                                           {"products.intervals", "false"},
                                           {"products.contact_laws.kelvin_voigt", "false"},
                                           {"products.joint_fits", "false"}});
  const SessionResult some = ReduceSession(session, options);
  for (const char* product :
       {"leave_one_out", "intervals", "contact_laws.kelvin_voigt", "joint_fits"}) {
    INFO(product);
    CHECK(StatusOf(some, product) == "skipped: not asked");
  }
  CHECK(some.joint_fits.empty());
  CHECK(Law(some, "kelvin-voigt") == nullptr);
  const ContactLawFit* hc = Law(some, "hunt-crossley");
  REQUIRE(hc != nullptr);
  CHECK(hc->intervals.empty());
  CHECK_FALSE(hc->loo_ok);
  CHECK(hc->chi2 == Law(all, "hunt-crossley")->chi2);
  CHECK(hc->parameters.at(0).estimate.value ==
        Law(all, "hunt-crossley")->parameters.at(0).estimate.value);
  REQUIRE(some.model_comparison);
  CHECK(some.model_comparison->best_by_leave_one_out.empty());
  CHECK(some.model_comparison->best_by_bic == all.model_comparison->best_by_bic);
  // The products asked for are settings of the session, recorded in /settings.
  CHECK(std::get<bool>(some.settings.at("products.leave_one_out")) == false);
}

TEST_CASE("products: the manifest's [products] table asks, and a bad key is refused") {
  testing::TempDir dir;
  std::string text;
  {
    std::ifstream in(kSampleData / "thesis-1969" / "session.toml");
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  std::ofstream(dir.path() / "session.toml") << text << "\n[products]\nmodel_comparison = false\n";
  const SessionResult r = ReduceSession(ReadManifest(dir.path()).session, {});
  CHECK(StatusOf(r, "model_comparison") == "skipped: not asked");
  CHECK_FALSE(r.model_comparison);
  std::ofstream(dir.path() / "session.toml") << text << "\n[products]\nmodel_comparisons = false\n";
  CHECK_THROWS_WITH(ReduceSession(ReadManifest(dir.path()).session, {}),
                    Catch::Contains("no such setting") && Catch::Contains("model_comparison"));
}

TEST_CASE("products: thumbnails not asked for are neither drawn nor written; asked later, added") {
  Session session = ReadManifest(kSampleData / "thesis-photos").session;
  session.runs.resize(1);
  ReduceOptions options;
  options.overrides = CommandLineSettings({{"products.thumbnails", "false"}});
  const SessionResult without = ReduceSession(session, options);
  REQUIRE(without.runs.at(0).ok);
  REQUIRE(without.runs[0].measured.overlays.size() == 1);
  CHECK(without.runs[0].measured.overlays[0].preview.pixels.empty());
  CHECK_FALSE(without.runs[0].measured.overlays[0].jpeg.empty());
  CHECK(StatusOf(without, "thumbnails") == "skipped: not asked");
  testing::TempDir dir;
  const auto file = dir.path() / "photos.h5";
  const std::string group = "/runs/" + without.runs[0].id + "/digitized/0";
  WriteResults(without, file);
  {
    const Hdf5File f = Hdf5File::OpenReadOnly(file);
    CHECK(f.Exists(group + "/overlay_jpeg"));
    CHECK_FALSE(f.Exists(group + "/overlay"));
  }
  // Asked for with the earlier file: the run is reused, the thumbnail made from its JPEG.
  const SessionResult previous = ReadResults(file);
  ReduceOptions again;
  again.previous = &previous;
  const SessionResult with = ReduceSession(session, again);
  CHECK(with.runs.at(0).reused);
  CHECK(StatusOf(with, "thumbnails") == "made");
  WriteResults(with, file);
  const Hdf5File f = Hdf5File::OpenReadOnly(file);
  CHECK(f.Exists(group + "/overlay"));
}

}  // namespace
}  // namespace impactlab
