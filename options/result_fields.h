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
//   std::string            an attribute of the result's group
//   int, bool              an integer attribute of the result's group (bool: 0 or 1)
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
};

// An n x n matrix, row-major (a covariance); empty when not known.
struct SquareMatrix {
  std::vector<double> values;

  std::size_t size() const {
    return static_cast<std::size_t>(std::llround(std::sqrt(static_cast<double>(values.size()))));
  }
  bool empty() const { return values.empty(); }
};

namespace result_fields_detail {

struct AnyVisit {
  template <typename Field>
  void operator()(const char*, Field&, Quantity, const char*) const {}
};

}  // namespace result_fields_detail

// A result struct with a list of its fields.
template <typename T>
concept HasFields = requires(T& result) {
  std::remove_const_t<T>::VisitFields(result, result_fields_detail::AnyVisit{});
};

}  // namespace impactlab
