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

#include "fit/contact_law_fit.h"
#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/result_fields_hdf5.h"
#include "pipeline/session_result.h"
#include "rebounds/bar_rebounds.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

// Gives every listed field of `result` a value of its own, unlike its
// default and every other field's.
template <typename Result>
void FillEveryField(Result& result) {
  int k = 1;
  Result::VisitFields(result, [&](const char*, auto& field, Quantity, const char*) {
    using Field = std::remove_cvref_t<decltype(field)>;
    const double v = 0.5 + k++;
    if constexpr (std::is_same_v<Field, double>) {
      field = v;
    } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
      field = {v, -v, 2 * v};
    } else if constexpr (std::is_same_v<Field, Estimate>) {
      field = {v, v / 8};
    } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
      field = Estimate{v, v / 16};
    } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
      field = {{v, v / 8}, {-v, v / 4}};
    } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
      field.values = {v, 0.25, 0.25, 2 * v};
    } else if constexpr (std::is_same_v<Field, std::string>) {
      field = fmt::format("text {}", v);
    } else if constexpr (std::is_same_v<Field, bool>) {
      field = !field;
    } else {
      field = k + 3;
    }
  });
}

// Every listed field as text, in list order.
template <typename Result>
std::vector<std::string> EveryField(Result& result) {
  std::vector<std::string> out;
  Result::VisitFields(result, [&](const char* name, auto& field, Quantity, const char*) {
    using Field = std::remove_cvref_t<decltype(field)>;
    std::string text;
    if constexpr (std::is_same_v<Field, std::vector<double>>) {
      text = fmt::format("{}", fmt::join(field, " "));
    } else if constexpr (std::is_same_v<Field, Estimate>) {
      text = fmt::format("{} ± {}", field.value, field.sigma);
    } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
      text = field ? fmt::format("{} ± {}", field->value, field->sigma) : "none";
    } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
      for (const Estimate& e : field) text += fmt::format("{} ± {}; ", e.value, e.sigma);
    } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
      text = fmt::format("{}", fmt::join(field.values, " "));
    } else {
      text = fmt::format("{}", field);
    }
    out.push_back(std::string(name) + " = " + text);
  });
  return out;
}

template <typename Result>
void CheckRoundTrip() {
  testing::TempDir dir;
  Result written;
  FillEveryField(written);
  const auto file = dir.path() / "fields.h5";
  WriteHdf5Atomically(file, [&](Hdf5File& f) {
    WriteFields(f, Hdf5Extras(f), "/result", written, LabelsFor(UnitSystem::kInLbfS));
  });
  Result read;
  ReadFields(Hdf5File::OpenReadOnly(file), "/result", read);
  CHECK(EveryField(read) == EveryField(written));
}

TEST_CASE("result_fields: every listed field of a bar's rebounds is written and read back") {
  CheckRoundTrip<BarRebounds>();
}

TEST_CASE("result_fields: every listed field of a cell's calibration is written and read back") {
  CheckRoundTrip<CellCalibration>();
}

TEST_CASE("result_fields: every listed field of a contact law's fit is written and read back") {
  CheckRoundTrip<ContactLawFit>();
}

TEST_CASE(
    "result_fields: every listed field of a run's least-squares fit is written and read back") {
  CheckRoundTrip<LeastSquaresSummary>();
}

TEST_CASE(
    "result_fields: every listed field of a log channel's analysis is written and read back") {
  CheckRoundTrip<LogChannelResult>();
}

// Whether docs/results.md names `field` as a dataset or an attribute.
bool Documented(const std::string& docs, const std::string& field) {
  for (const std::string& form : {"/" + field + "`", "@" + field + "`", "`" + field + "`"}) {
    if (docs.find(form) != std::string::npos) return true;
  }
  return false;
}

template <typename Result>
void CheckDocumented() {
  std::ifstream in(std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "docs" / "results.md");
  const std::string docs((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE_FALSE(docs.empty());
  ForEachField<Result>([&](const char* name, Quantity, const char*) {
    INFO(name);
    CHECK(Documented(docs, name));
  });
}

TEST_CASE("result_fields: docs/results.md names every listed field") {
  CheckDocumented<BarRebounds>();
  CheckDocumented<CellCalibration>();
  CheckDocumented<ContactLawFit>();
  CheckDocumented<LeastSquaresSummary>();
  CheckDocumented<LogChannelResult>();
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
