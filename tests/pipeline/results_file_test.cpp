// The results file: layout names with units, a faithful round trip, atomic writes.
#include <fstream>
#include <functional>

#include <catch2/catch.hpp>

#include "io/hdf5_file.h"
#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

SessionResult ReducedThesis() {
  const auto folder = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data" / "thesis-1969";
  return ReduceSession(ReadManifest(folder).session, {});
}

void VisitDatasets(const Hdf5File& f, const std::string& group,
                   const std::function<void(const std::string&)>& visit) {
  for (const std::string& child : f.Children(group)) {
    const std::string path = (group == "/" ? "" : group) + "/" + child;
    if (f.IsGroup(path)) {
      VisitDatasets(f, path, visit);
    } else {
      visit(path);
    }
  }
}

TEST_CASE("results_file: the minimum layout is present and every numeric dataset has units") {
  testing::TempDir dir;
  const auto path = dir.path() / "results.h5";
  WriteResults(ReducedThesis(), path);
  const Hdf5File f = Hdf5File::OpenReadOnly(path);
  CHECK(f.ReadIntegerAttribute("/", "layout") == kResultsLayout);
  CHECK_THAT(f.ReadStringAttribute("/", "producer"), Catch::StartsWith("impactlab"));
  CHECK(f.ReadStringAttribute("/", "units") == "in-lbf-s");
  CHECK(f.ReadStringAttribute("/runs/0.234", "status") == "ok");
  for (const char* name :
       {"/runs/0.234/rebounds/xmax", "/runs/0.234/rebounds/t_peak",
        // The session gives the one contact time; the runs have none of their own.
        "/runs/0.234/fit/kelvin_voigt/contact_time_used", "/runs/0.234/fit/kelvin_voigt/zeta",
        "/runs/0.234/fit/kelvin_voigt/stiffness", "/runs/0.234/fit/kelvin_voigt/damping",
        "/runs/0.234/fit/kelvin_voigt/restitution",
        "/runs/0.234/fit/kelvin_voigt/predicted_xmax"}) {
    INFO(name);
    CHECK(f.Exists(name));
  }
  CHECK(f.ReadStringAttribute("/runs/0.234/fit/kelvin_voigt", "method") == "two-point");
  CHECK(f.ReadStringAttribute("/runs/0.234/fit/kelvin_voigt", "separation") == "kinematic");
  CHECK(f.ReadIntegerArrayAttribute("/runs/0.323/fit/kelvin_voigt", "rebounds_used") ==
        std::vector<long long>{1, 2});
  int numeric = 0;
  VisitDatasets(f, "/", [&](const std::string& path) {
    if (!f.IsNumericDataset(path)) return;
    ++numeric;
    INFO(path);
    CHECK(f.HasAttribute(path, "units"));
  });
  CHECK(numeric > 100);
}

TEST_CASE("results_file: reading back gives what was written") {
  testing::TempDir dir;
  const auto path = dir.path() / "results.h5";
  const SessionResult written = ReducedThesis();
  WriteResults(written, path);
  const SessionResult read = ReadResults(path);
  CHECK(read.title == written.title);
  REQUIRE(read.runs.size() == written.runs.size());
  for (std::size_t i = 0; i < read.runs.size(); ++i) {
    CHECK(read.runs[i].id == written.runs[i].id);  // manifest order kept
    CHECK(read.runs[i].measured.xmax == written.runs[i].measured.xmax);
    CHECK(read.runs[i].fits.kelvin_voigt->stiffness->value ==
          written.runs[i].fits.kelvin_voigt->stiffness->value);
    CHECK(read.runs[i].fits.kelvin_voigt->predicted_xmax.size() ==
          written.runs[i].fits.kelvin_voigt->predicted_xmax.size());
  }
  CHECK(read.kelvin_voigt->damping_line->b.value == written.kelvin_voigt->damping_line->b.value);
  REQUIRE(read.predictions.size() == 1);
  CHECK(read.predictions[0].predicted == written.predictions[0].predicted);
}

TEST_CASE("results_file: a failed write leaves the earlier results file intact") {
  testing::TempDir dir;
  const auto path = dir.path() / "results.h5";
  SessionResult result = ReducedThesis();
  WriteResults(result, path);
  const auto size_before = std::filesystem::file_size(path);
  result.runs.back().id = "bad/id";  // fails mid-write, after other runs were written
  CHECK_THROWS_AS(WriteResults(result, path), InputError);
  CHECK(std::filesystem::file_size(path) == size_before);
  CHECK(ReadResults(path).runs.back().id == "1.519");
  // No temporary file is left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
    ++files;
  CHECK(files == 1);
}

TEST_CASE("results_file: a file that is not a results file is refused with its name") {
  testing::TempDir dir;
  const auto path = dir.path() / "notes.h5";
  { std::ofstream(path) << "not hdf5"; }
  CHECK_THROWS_WITH(ReadResults(path), Catch::Contains("notes.h5") && Catch::Contains("HDF5"));
}

}  // namespace
}  // namespace impactlab
