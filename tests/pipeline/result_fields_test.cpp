// Every listed field of a result (options/result_fields.h) survives the results
// file: each is filled with its own value, written, read back and compared,
// so a field added to a list is checked with nothing added here.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <catch2/catch.hpp>

#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/result_fields_hdf5.h"
#include "tests/pipeline/every_field.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

using testing::EveryField;
using testing::FillEveryField;
using testing::ForEachListedResult;

// What a result's list reads beside its own fields, set before it is filled
// and read as the file's layout sets it: a run's fields depend on its status
// and maxima; a two-point fit's contact time's source is an attribute of the
// contact time, which the fit's own list writes.
template <typename Result>
void SetContext(Result& result) {
  if constexpr (std::is_same_v<Result, RunResult>) {
    result.ok = true;
    result.measured.xmax = {0.25};
  }
}
template <typename Result>
void WriteBeside(Hdf5File& f, const std::string& group) {
  if constexpr (std::is_same_v<Result, RunFits>)
    f.WriteScalar(group + "/contact_time_used", 1e-3, "s");
}

template <typename Result>
void CheckRoundTrip() {
  INFO(typeid(Result).name());
  testing::TempDir dir;
  Result written;
  SetContext(written);
  FillEveryField(written);
  const auto file = dir.path() / "fields.h5";
  WriteHdf5Atomically(file, [&](Hdf5File& f) {
    f.CreateGroup("/result");
    WriteBeside<Result>(f, "/result");
    WriteFields(f, Hdf5Extras(f), "/result", written, LabelsFor(UnitSystem::kInLbfS));
  });
  Result read;
  SetContext(read);
  ReadFields(Hdf5File::OpenReadOnly(file), "/result", read);
  CHECK(EveryField(read) == EveryField(written));
  // Every field was given a value: none left at its default.
  const Result defaults{};
  const std::vector<std::string> filled = EveryField(written), unset = EveryField(defaults);
  for (std::size_t i = 0; i < filled.size() && i < unset.size(); ++i) {
    CHECK(filled[i] != unset[i]);
  }
}

TEST_CASE("result_fields: every listed field of every result type is written and read back") {
  ForEachListedResult([]<typename Result>() { CheckRoundTrip<Result>(); });
}

// Whether docs/results.md names `field` as a dataset or an attribute.
bool Documented(const std::string& docs, const std::string& field) {
  for (const std::string& form : {"/" + field + "`", "@" + field + "`", "`" + field + "`"}) {
    if (docs.find(form) != std::string::npos) return true;
  }
  return false;
}

TEST_CASE("result_fields: docs/results.md names every listed field") {
  std::ifstream in(std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "docs" / "results.md");
  const std::string docs((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE_FALSE(docs.empty());
  ForEachListedResult([&]<typename Result>() {
    Result filled;  // so that a field listed only beside another's value is seen
    SetContext(filled);
    FillEveryField(filled);
    Result::VisitFields(filled, [&](const char* name, auto&&, Quantity, const char*) {
      INFO(typeid(Result).name() << " " << name);
      CHECK(Documented(docs, name));
    });
  });
}

TEST_CASE("result_fields: a field that holds nothing is left out and reads back as nothing") {
  testing::TempDir dir;
  BarRebounds bar;
  bar.xmax = {0.3};
  const auto file = dir.path() / "fields.h5";
  WriteHdf5Atomically(file, [&](Hdf5File& f) {
    WriteFields(f, Hdf5Extras(f), "/bar", bar, LabelsFor(UnitSystem::kSI));
  });
  const Hdf5File f = Hdf5File::OpenReadOnly(file);
  CHECK(f.Exists("/bar/xmax"));
  CHECK(f.ReadStringAttribute("/bar/xmax", "units") == "m");
  CHECK_FALSE(f.Exists("/bar/duration"));
  CHECK_FALSE(f.Exists("/bar/release_x"));
  BarRebounds read;
  ReadFields(f, "/bar", read);
  CHECK(read.xmax == bar.xmax);
  CHECK(read.duration.empty());
  CHECK(read.release.sigma == 0.0);
}

}  // namespace
}  // namespace impactlab
