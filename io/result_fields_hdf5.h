// A listed result (io/result_fields.h) written to and read from a group of a
// results file, field by field as its list says.
#pragma once

#include <string>

#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/result_fields.h"
#include "model/estimate.h"

namespace impactlab {

// Writes every listed field of `result` into `group` (created if absent);
// numbers labelled in `units`. Fields that hold nothing (an empty vector or
// matrix, an Estimate {0, 0}) are left out.
template <typename Result>
requires HasFields<const Result>
void WriteFields(Hdf5File& f, const Hdf5Extras& extras, const std::string& group,
                 const Result& result, const UnitLabels& units) {
  if (!f.Exists(group)) f.CreateGroup(group);
  Result::VisitFields(
      result, [&](const char* name, const auto& field, Quantity quantity, const char* /*meaning*/) {
        using Field = std::remove_cvref_t<decltype(field)>;
        const std::string path = group + "/" + name;
        const std::string unit = UnitOf(quantity, units);
        if constexpr (std::is_same_v<Field, double>) {
          f.WriteScalar(path, field, unit);
        } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
          if (!field.empty()) f.WriteVector(path, field, unit);
        } else if constexpr (std::is_same_v<Field, Estimate>) {
          if (field.value != 0.0 || field.sigma != 0.0) {
            f.WriteScalar(path, field.value, unit);
            f.WriteScalar(path + "_std_error", field.sigma, unit);
          }
        } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
          if (!field.empty())
            extras.WriteMatrix(path, field.size(), field.size(), field.values, unit);
        } else if constexpr (std::is_same_v<Field, std::string>) {
          f.SetAttribute(group, name, field);
        } else {
          static_assert(std::is_same_v<Field, int>, "a listed field's type has no storage");
          f.SetAttribute(group, name, static_cast<long long>(field));
        }
      });
}

// Reads every listed field of `group` into `result`; a field the file does
// not hold (left out as empty, or written before the field existed) keeps
// its value in `result`.
template <typename Result>
requires HasFields<Result>
void ReadFields(const Hdf5File& f, const std::string& group, Result& result) {
  Result::VisitFields(result, [&](const char* name, auto& field, Quantity, const char*) {
    using Field = std::remove_cvref_t<decltype(field)>;
    const std::string path = group + "/" + name;
    if constexpr (std::is_same_v<Field, std::string>) {
      if (f.HasAttribute(group, name)) field = f.ReadStringAttribute(group, name);
    } else if constexpr (std::is_same_v<Field, int>) {
      if (f.HasAttribute(group, name))
        field = static_cast<int>(f.ReadIntegerAttribute(group, name));
    } else if (f.Exists(path)) {
      if constexpr (std::is_same_v<Field, double>) {
        field = f.ReadScalar(path);
      } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
        field = f.ReadVector(path);
      } else if constexpr (std::is_same_v<Field, Estimate>) {
        field = {f.ReadScalar(path), f.ReadScalarIfPresent(path + "_std_error").value_or(0.0)};
      } else {
        static_assert(std::is_same_v<Field, SquareMatrix>, "a listed field's type has no storage");
        field.values = f.ReadVector(path);  // n x n, row-major
      }
    }
  });
}

// Calls visit(name, quantity, meaning) for every listed field of a Result,
// for documentation and tests.
template <typename Result, typename Visit>
requires HasFields<Result>
void ForEachField(Visit&& visit) {
  Result result{};
  Result::VisitFields(result, [&](const char* name, auto&, Quantity quantity, const char* meaning) {
    visit(name, quantity, meaning);
  });
}

}  // namespace impactlab
