// A listed result (options/result_fields.h) written to and read from a group
// of a results file, field by field as its list says.
#pragma once

#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "io/hdf5_extras.h"
#include "io/hdf5_file.h"
#include "io/units.h"
#include "model/estimate.h"
#include "options/result_fields.h"

namespace impactlab {

// A quantity's units in the session's system.
inline std::string UnitOf(Quantity quantity, const UnitLabels& units) {
  switch (quantity) {
    case Quantity::kDimensionless:
      return "1";
    case Quantity::kSeconds:
      return "s";
    case Quantity::kVolts:
      return "V";
    case Quantity::kVoltsSquared:
      return "V^2";
    case Quantity::kLength:
      return units.length;
    case Quantity::kSpeed:
      return units.speed;
    case Quantity::kHertz:
      return "Hz";
  }
  return "1";
}

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
        } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
          if (field) {
            f.WriteScalar(path, field->value, unit);
            f.WriteScalar(path + "_std_error", field->sigma, unit);
          }
        } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
          if (!field.empty()) {
            std::vector<double> values, sigmas;
            for (const Estimate& e : field) values.push_back(e.value), sigmas.push_back(e.sigma);
            f.WriteVector(path, values, unit);
            f.WriteVector(path + "_std_error", sigmas, unit);
          }
        } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
          if (!field.empty())
            extras.WriteMatrix(path, field.size(), field.size(), field.values, unit);
        } else if constexpr (std::is_same_v<Field, std::string>) {
          f.SetAttribute(group, name, field);
        } else {
          static_assert(std::is_same_v<Field, int> || std::is_same_v<Field, bool>,
                        "a listed field's type has no storage");
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
      if (f.HasAttribute(group, name)) {
        field = static_cast<int>(f.ReadIntegerAttribute(group, name));
      }
    } else if constexpr (std::is_same_v<Field, bool>) {
      if (f.HasAttribute(group, name)) field = f.ReadIntegerAttribute(group, name) != 0;
    } else if (f.Exists(path)) {
      if constexpr (std::is_same_v<Field, double>) {
        field = f.ReadScalar(path);
      } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
        field = f.ReadVector(path);
      } else if constexpr (std::is_same_v<Field, Estimate>) {
        field = {f.ReadScalar(path), f.ReadScalarIfPresent(path + "_std_error").value_or(0.0)};
      } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
        field =
            Estimate{f.ReadScalar(path), f.ReadScalarIfPresent(path + "_std_error").value_or(0.0)};
      } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
        const std::vector<double> values = f.ReadVector(path);
        const std::vector<double> sigmas = f.Exists(path + "_std_error")
                                               ? f.ReadVector(path + "_std_error")
                                               : std::vector<double>(values.size(), 0.0);
        field.clear();
        for (std::size_t i = 0; i < values.size(); ++i) {
          field.push_back({values[i], i < sigmas.size() ? sigmas[i] : 0.0});
        }
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
