// A listed result (options/result_fields.h) written to and read from a group
// of a results file, field by field as its list says.
#pragma once

#include <optional>
#include <string>
#include <string_view>
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
    case Quantity::kStiffness:
      return units.stiffness;
    case Quantity::kDamping:
      return units.damping;
    case Quantity::kMass:
      return units.mass;
    case Quantity::kAcceleration:
      return units.acceleration;
    case Quantity::kPercent:
      return "%";
    case Quantity::kPixels:
      return "px";
    case Quantity::kPixelsSquared:
      return "px^2";
    case Quantity::kDivisions:
      return "div";
    case Quantity::kChannel:
      return units.channel;
    case Quantity::kPressure:
      return units.pressure;
    case Quantity::kHertzStiffness:
      return units.hertz_stiffness;
  }
  return "1";
}

namespace result_fields_detail {

template <typename T>
struct Wrapping {
  static constexpr bool kIfAny = false, kEvenEmpty = false;
};
template <typename T>
struct Wrapping<IfAnyField<T>> {
  static constexpr bool kIfAny = true, kEvenEmpty = false;
};
template <typename T>
struct Wrapping<EvenEmptyField<T>> {
  static constexpr bool kIfAny = false, kEvenEmpty = true;
};

// A listed name's object in the file, relative to `group` ("/" the root).
inline std::string FieldPath(const std::string& group, std::string_view name) {
  return (group.ends_with('/') ? group : group + "/") + std::string(name);
}

// Where a string field is kept: an attribute of the group, or of a dataset ("a@b").
struct AttributePlace {
  std::string object, name;
};
inline AttributePlace AttributeOf(const std::string& group, std::string_view name) {
  const std::size_t at = name.find('@');
  if (at == std::string_view::npos) return {group, std::string(name)};
  return {FieldPath(group, name.substr(0, at)), std::string(name.substr(at + 1))};
}

}  // namespace result_fields_detail

// Writes every listed field of `result` into `group` (created if absent);
// numbers labelled in `units`. Fields that hold nothing (an empty vector or
// matrix, an Estimate {0, 0}, an empty optional) are left out, as the list's
// IfAny fields are when empty or 0; its EvenEmpty vectors and estimates are
// written.
template <typename Result>
requires HasFields<const Result>
void WriteFields(Hdf5File& f, const Hdf5Extras& extras, const std::string& group,
                 const Result& result, const UnitLabels& units) {
  using namespace result_fields_detail;
  if (!f.Exists(group)) f.CreateGroup(group);
  Result::VisitFields(
      result, [&](const char* name, auto&& listed, Quantity quantity, const char* /*meaning*/) {
        using Wrap = Wrapping<std::remove_cvref_t<decltype(listed)>>;
        const auto& field = FieldOf(listed);
        using Field = std::remove_cvref_t<decltype(field)>;
        const std::string path = FieldPath(group, name);
        const std::string unit = UnitOf(quantity, units);
        if constexpr (std::is_same_v<Field, double>) {
          if (!Wrap::kIfAny || field != 0.0) f.WriteScalar(path, field, unit);
        } else if constexpr (std::is_same_v<Field, std::optional<double>>) {
          if (field) f.WriteScalar(path, *field, unit);
        } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
          if (Wrap::kEvenEmpty || !field.empty()) f.WriteVector(path, field, unit);
        } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
          f.WriteStrings(path, field);
        } else if constexpr (std::is_same_v<Field, Estimate>) {
          if (Wrap::kEvenEmpty || field.value != 0.0 || field.sigma != 0.0) {
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
          const AttributePlace place = AttributeOf(group, name);
          // A dataset's attribute is written with it (the group exists).
          const bool on_dataset = place.object != group;
          if ((!Wrap::kIfAny || !field.empty()) && (!on_dataset || f.Exists(place.object))) {
            f.SetAttribute(place.object, place.name, field);
          }
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
  using namespace result_fields_detail;
  Result::VisitFields(result, [&](const char* name, auto&& listed, Quantity, const char*) {
    auto& field = FieldOf(listed);
    using Field = std::remove_cvref_t<decltype(field)>;
    const std::string path = FieldPath(group, name);
    if constexpr (std::is_same_v<Field, std::string>) {
      const AttributePlace place = AttributeOf(group, name);
      if ((place.object == group || f.Exists(place.object)) &&
          f.HasAttribute(place.object, place.name)) {
        field = f.ReadStringAttribute(place.object, place.name);
      }
    } else if constexpr (std::is_same_v<Field, int>) {
      if (f.HasAttribute(group, name)) {
        field = static_cast<int>(f.ReadIntegerAttribute(group, name));
      }
    } else if constexpr (std::is_same_v<Field, bool>) {
      if (f.HasAttribute(group, name)) field = f.ReadIntegerAttribute(group, name) != 0;
    } else if (f.Exists(path)) {
      if constexpr (std::is_same_v<Field, double> || std::is_same_v<Field, std::optional<double>>) {
        field = f.ReadScalar(path);
      } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
        field = f.ReadVector(path);
      } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
        field = f.ReadStrings(path);
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
  Result::VisitFields(result, [&](const char* name, auto&&, Quantity quantity,
                                  const char* meaning) { visit(name, quantity, meaning); });
}

}  // namespace impactlab
