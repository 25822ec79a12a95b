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

// A quantity's unit kind, as UnitOfKind (io/units.h), a fit's
// `parameter_unit_kinds` and the campaign's conversions name it: "s",
// "length", "speed", "stiffness", "damping", "mass", "pressure",
// "hertz_stiffness"; "1" for the rest.
inline std::string UnitKindOf(Quantity quantity) {
  switch (quantity) {
    case Quantity::kSeconds:
      return "s";
    case Quantity::kLength:
      return "length";
    case Quantity::kSpeed:
      return "speed";
    case Quantity::kStiffness:
      return "stiffness";
    case Quantity::kDamping:
      return "damping";
    case Quantity::kMass:
      return "mass";
    case Quantity::kPressure:
      return "pressure";
    case Quantity::kHertzStiffness:
      return "hertz_stiffness";
    default:
      return "1";
  }
}

namespace result_fields_detail {

template <typename T>
struct Wrapping {
  static constexpr bool kIfAny = false, kEvenEmpty = false, kSquare = false;
};
template <Storage How, typename T>
struct Wrapping<StoredAs<How, T>> {
  static constexpr bool kIfAny = How == Storage::kIfAny, kEvenEmpty = How == Storage::kEvenEmpty,
                        kSquare = How == Storage::kSquare;
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

template <typename Field>
struct IsColumn : std::false_type {};
template <typename Rows, typename Member>
struct IsColumn<ColumnField<Rows, Member>> : std::true_type {};

// Whether a field of this type is an attribute (of the group, or "a@b" of a
// dataset); strings are one only as "a@b", else a dataset.
template <typename Field>
constexpr bool kIsAttribute =
    std::is_same_v<Field, std::string> || std::is_same_v<Field, int> ||
    std::is_same_v<Field, bool> || std::is_same_v<Field, std::vector<std::string>>;

inline bool IsAttributeOfDataset(std::string_view name) {
  return name.find('@') != std::string_view::npos;
}

// The size n of a row-major n x n matrix's values.
inline std::size_t SquareSize(const std::vector<double>& values) {
  return static_cast<std::size_t>(std::llround(std::sqrt(static_cast<double>(values.size()))));
}

inline void WriteEstimates(Hdf5File& f, const std::string& path, const std::vector<Estimate>& all,
                           const std::string& unit) {
  std::vector<double> values, sigmas;
  for (const Estimate& e : all) values.push_back(e.value), sigmas.push_back(e.sigma);
  f.WriteVector(path, values, unit);
  f.WriteVector(path + "_std_error", sigmas, unit);
}

inline std::vector<Estimate> ReadEstimates(const Hdf5File& f, const std::string& path) {
  const std::vector<double> values = f.ReadVector(path);
  const std::vector<double> sigmas = f.Exists(path + "_std_error")
                                         ? f.ReadVector(path + "_std_error")
                                         : std::vector<double>(values.size(), 0.0);
  std::vector<Estimate> all;
  for (std::size_t i = 0; i < values.size(); ++i) {
    all.push_back({values[i], i < sigmas.size() ? sigmas[i] : 0.0});
  }
  return all;
}

// A column read back into the rows, as many as it holds (more rows made as needed).
template <typename Rows, typename Member>
void ReadColumn(const Hdf5File& f, const std::string& path, ColumnField<Rows, Member> column) {
  const std::vector<double> values = f.ReadVector(path);
  if (column.rows.size() < values.size()) column.rows.resize(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) column.rows[i].*column.member = values[i];
}

}  // namespace result_fields_detail

// Writes every listed field of `result` into `group` (created if absent);
// numbers labelled in `units`. Fields that hold nothing (an empty vector,
// matrix or column, an Estimate {0, 0}, an empty optional) are left out, as
// the list's IfAny fields are when empty or 0; its EvenEmpty vectors and
// estimates are written.
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
        if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
          if (!IsAttributeOfDataset(name)) {
            f.WriteStrings(path, field);
            return;
          }
        }
        if constexpr (kIsAttribute<Field>) {
          const AttributePlace place = AttributeOf(group, name);
          // A dataset's attribute is written with it (the group exists).
          if (place.object != group && !f.Exists(place.object)) return;
          if constexpr (std::is_same_v<Field, std::string>) {
            if (!Wrap::kIfAny || !field.empty()) f.SetAttribute(place.object, place.name, field);
          } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
            extras.SetStringsAttribute(place.object, place.name, field);
          } else {
            f.SetAttribute(place.object, place.name, static_cast<long long>(field));
          }
        } else if constexpr (std::is_same_v<Field, double>) {
          if (!Wrap::kIfAny || field != 0.0) f.WriteScalar(path, field, unit);
        } else if constexpr (std::is_same_v<Field, std::optional<double>>) {
          if (field) f.WriteScalar(path, *field, unit);
        } else if constexpr (std::is_same_v<Field, std::vector<double>> && Wrap::kSquare) {
          const std::size_t n = SquareSize(field);
          if (n > 0) extras.WriteMatrix(path, n, n, field, unit);
        } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
          if (Wrap::kEvenEmpty || !field.empty()) f.WriteVector(path, field, unit);
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
          if (!field.empty()) WriteEstimates(f, path, field, unit);
        } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
          if (!field.empty())
            extras.WriteMatrix(path, field.size(), field.size(), field.values, unit);
        } else {
          static_assert(IsColumn<Field>::value, "a listed field's type has no storage");
          if (!field.rows.empty()) {
            std::vector<double> values;
            for (const auto& row : field.rows) values.push_back(row.*field.member);
            f.WriteVector(path, values, unit);
          }
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
    auto&& field = FieldOf(listed);
    using Field = std::remove_cvref_t<decltype(field)>;
    const std::string path = FieldPath(group, name);
    if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
      if (!IsAttributeOfDataset(name)) {
        if (f.Exists(path)) field = f.ReadStrings(path);
        return;
      }
    }
    if constexpr (kIsAttribute<Field>) {
      const AttributePlace place = AttributeOf(group, name);
      if ((place.object != group && !f.Exists(place.object)) ||
          !f.HasAttribute(place.object, place.name)) {
        return;
      }
      if constexpr (std::is_same_v<Field, std::string>) {
        field = f.ReadStringAttribute(place.object, place.name);
      } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
        field = ReadStringsAttribute(f.path(), place.object, place.name);
      } else if constexpr (std::is_same_v<Field, int>) {
        field = static_cast<int>(f.ReadIntegerAttribute(place.object, place.name));
      } else {
        field = f.ReadIntegerAttribute(place.object, place.name) != 0;
      }
    } else if (f.Exists(path)) {
      if constexpr (std::is_same_v<Field, double> || std::is_same_v<Field, std::optional<double>>) {
        field = f.ReadScalar(path);
      } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
        field = f.ReadVector(path);  // a Square one as n x n, row-major
      } else if constexpr (std::is_same_v<Field, Estimate>) {
        field = {f.ReadScalar(path), f.ReadScalarIfPresent(path + "_std_error").value_or(0.0)};
      } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
        field =
            Estimate{f.ReadScalar(path), f.ReadScalarIfPresent(path + "_std_error").value_or(0.0)};
      } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
        field = ReadEstimates(f, path);
      } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
        field.values = f.ReadVector(path);  // n x n, row-major
      } else {
        static_assert(IsColumn<Field>::value, "a listed field's type has no storage");
        ReadColumn(f, path, field);
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
