// A result's fields, listed once.
//
// As an options struct lists its settings (options/settings.h), a result
// struct lists what it holds, beside its declaration, in the order the file
// keeps it:
//
//   template <typename Self, typename Visit>
//   static void VisitFields(Self& self, Visit&& visit) {
//     visit("xmax", self.xmax, Quantity::kLength, "each rebound's maximum");
//   }
//
// That one list is how the result is written to a results file and read
// back (WriteFields, ReadFields in io/result_fields_hdf5.h): a field added to
// the list is stored and restored with nothing else to change. How a field is
// stored follows from its type:
//   double                 a scalar dataset, with its units
//   std::vector<double>    a 1-D dataset (none when empty; read back empty)
//   Estimate               a dataset and `<name>_std_error` (none when {0, 0}: not known)
//   std::optional<Estimate> the same, none when empty
//   std::vector<Estimate>  two 1-D datasets, `<name>` and `<name>_std_error` (none when empty)
//   SquareMatrix           a 2-D dataset, n x n (none when empty)
//   std::optional<double>  a scalar dataset, none when empty
//   std::vector<std::string> a 1-D dataset of strings (written even when empty)
//   std::string            an attribute of the result's group
//   int, bool              an integer attribute of the result's group (bool: 0 or 1)
// Two wrappers change when a field is left out:
//   IfAny(x)      a string or a number left out when empty or 0 (0: not known)
//   EvenEmpty(x)  a vector written even when empty (its presence says it was looked
//                 for), an Estimate even when {0, 0}
// Two store what has no type of its own above (none when empty):
//   Square(values)         a row-major n x n std::vector<double>: a 2-D dataset
//   Column(rows, &Row::m)  a double member of every row of a vector (a
//                          table's column): a 1-D dataset
// A result may list a member struct's own fields among its own by calling
// that struct's VisitFields with `visit` (FitStatus in fit/least_squares.h).
// A name is relative to the result's group and may reach into a subgroup
// ("rebounds/xmax"); "a@b" is the attribute b (a string, strings, int or
// bool) of the result's dataset a, written when a is. A field stored only
// when an earlier one holds something is listed under an `if` on that one:
// it is read back after it.
// The meaning is for the documentation (docs/results.md lists every name).
#pragma once

#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

namespace impactlab {

// What a number measures, so that the file labels it in the session's units.
enum class Quantity {
  kDimensionless,  // "1"
  kSeconds,
  kVolts,
  kVoltsSquared,
  kLength,
  kSpeed,
  kHertz,
  kStiffness,  // force/length
  kDamping,    // force*time/length
  kMass,
  kAcceleration,
  kPercent,  // "%"
  kPixels,   // "px", of a photo
  kPixelsSquared,
  kDivisions,       // "div", of an oscillograph's graticule
  kChannel,         // a log channel's own units (UnitLabels::channel)
  kPressure,        // force/length^2: a material's modulus
  kHertzStiffness,  // force/length^1.5: k of Hertz's F = k x^(3/2)
};

// An n x n matrix, row-major (a covariance); empty when not known.
struct SquareMatrix {
  std::vector<double> values;

  std::size_t size() const {
    return static_cast<std::size_t>(std::llround(std::sqrt(static_cast<double>(values.size()))));
  }
  bool empty() const { return values.empty(); }
};

// How a listed field is stored where its type alone does not say (see above).
enum class Storage {
  // Left out of the file when it holds nothing: a string when empty, a
  // number when 0 (which then means "not known").
  kIfAny,
  // Written even when empty: a vector's presence says it was looked for (e.g.
  // a photo's hand marks); an Estimate even when {0, 0}.
  kEvenEmpty,
  // A row-major n x n std::vector<double> (a covariance): a 2-D dataset.
  kSquare,
};
template <Storage How, typename T>
struct StoredAs {
  T& field;
};
template <typename T>
using IfAnyField = StoredAs<Storage::kIfAny, T>;
template <typename T>
IfAnyField<T> IfAny(T& field) {
  return {field};
}
template <typename T>
StoredAs<Storage::kEvenEmpty, T> EvenEmpty(T& field) {
  return {field};
}
template <typename T>
StoredAs<Storage::kSquare, T> Square(T& values) {
  return {values};
}

// A double member of every row of a vector, stored as a column (see above).
template <typename Rows, typename Member>
struct ColumnField {
  Rows& rows;
  Member member;  // a pointer to a member of Rows' value type
};
template <typename Rows, typename Member>
ColumnField<Rows, Member> Column(Rows& rows, Member member) {
  return {rows, member};
}

// The member a listed field is, through its wrapper.
template <typename T>
T& FieldOf(T& field) {
  return field;
}
template <Storage How, typename T>
T& FieldOf(StoredAs<How, T> wrapped) {
  return wrapped.field;
}

namespace result_fields_detail {

struct AnyVisit {
  template <typename Field>
  void operator()(const char*, Field&&, Quantity, const char*) const {}
};

}  // namespace result_fields_detail

// A result struct with a list of its fields.
template <typename T>
concept HasFields = requires(T& result) {
  std::remove_const_t<T>::VisitFields(result, result_fields_detail::AnyVisit{});
};

}  // namespace impactlab
