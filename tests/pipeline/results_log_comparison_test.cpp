// A results file written before a log's comparison kept its instants (the
// sources' `impact_time` were the instants compared, each `impact_method`
// beginning with the channel compared) still reads: the comparison's
// instants and channel come from the sources. The older layout is made from
// today's file with HDF5 itself, as the older writer laid it out.
#include <string>

#include <hdf5.h>
#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "pipeline/results_file.h"
#include "tests/support/sample_data.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

void Remove(hid_t file, const std::string& link) {
  if (H5Lexists(file, link.c_str(), H5P_DEFAULT) > 0) {
    REQUIRE(H5Ldelete(file, link.c_str(), H5P_DEFAULT) >= 0);
  }
}

void Overwrite(hid_t file, const std::string& dataset, double value) {
  const hid_t d = H5Dopen2(file, dataset.c_str(), H5P_DEFAULT);
  REQUIRE(d >= 0);
  REQUIRE(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value) >= 0);
  H5Dclose(d);
}

void SetText(hid_t file, const std::string& object, const std::string& name,
             const std::string& value) {
  REQUIRE(H5Adelete_by_name(file, object.c_str(), name.c_str(), H5P_DEFAULT) >= 0);
  // As io/hdf5_file.cpp writes a text: a variable-length UTF-8 string.
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t a = H5Acreate_by_name(file, object.c_str(), name.c_str(), type, space, H5P_DEFAULT,
                                    H5P_DEFAULT, H5P_DEFAULT);
  REQUIRE(a >= 0);
  const char* text = value.c_str();
  REQUIRE(H5Awrite(a, type, &text) >= 0);
  H5Aclose(a);
  H5Sclose(space);
  H5Tclose(type);
}

TEST_CASE("results_log_comparison: a file whose sources held the instants compared reads") {
  const SessionResult today =
      ReduceSession(ReadManifest(testing::kSampleData / "logs-two-link").session, {});
  REQUIRE(today.logs.size() == 1);
  const LogResult& log = today.logs[0];
  REQUIRE(log.comparison);
  const LogComparison& compared = *log.comparison;
  REQUIRE(compared.simulation_impact_s);
  // The sample's simulation jumps hardest at a4; the comparison is on a3.
  REQUIRE(log.sources.at(1).impact_method != compared.impact_channel);

  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteResults(today, path);
  {
    const hid_t file = H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    REQUIRE(file >= 0);
    const std::string g = "/logs/" + log.id;
    REQUIRE(H5Adelete_by_name(file, (g + "/comparison").c_str(), "impact_channel", H5P_DEFAULT) >=
            0);
    for (const char* name : {"experiment_impact", "simulation_impact"}) {
      Remove(file, g + "/comparison/" + name);
      Remove(file, g + "/comparison/" + name + std::string("_std_error"));
    }
    Overwrite(file, g + "/simulation/impact_time", compared.simulation_impact_s->value);
    SetText(file, g + "/simulation", "impact_method",
            compared.impact_channel +
                ", the channel compared; this source's strongest jump is accelerometer a4's, "
                "at 1.68750 s");
    H5Fclose(file);
  }
  const LogResult older = ReadResults(path).logs.at(0);
  REQUIRE(older.comparison);
  CHECK(older.comparison->impact_channel == compared.impact_channel);
  REQUIRE(older.comparison->experiment_impact_s);
  REQUIRE(older.comparison->simulation_impact_s);
  CHECK(older.comparison->experiment_impact_s->value == compared.experiment_impact_s->value);
  CHECK(older.comparison->simulation_impact_s->value == compared.simulation_impact_s->value);
  CHECK(older.comparison->channels.size() == compared.channels.size());
}

}  // namespace
}  // namespace impactlab
