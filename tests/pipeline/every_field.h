// Every listed field of a result (options/result_fields.h) as text, and a
// value of its own for each: what the round-trip tests compare, so that a
// field added to a list is compared with nothing added to them.
#pragma once

#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include <fmt/format.h>

#include "fit/contact_law_fit.h"
#include "fit/kelvin_voigt_session.h"
#include "fit/kelvin_voigt_two_point.h"
#include "io/session.h"
#include "io/specimen.h"
#include "model/estimate.h"
#include "options/result_fields.h"
#include "pipeline/session_result.h"
#include "rebounds/bar_rebounds.h"

namespace impactlab::testing {

// Every result type with a field list, the session's own last.
using ListedResults =
    std::tuple<BarRebounds, CellCalibration, ContactLawFit, KelvinVoigtLeastSquaresFit,
               PoyntingThomsonLeastSquaresFit, ChannelAnalysis, PhotoOverlay, StageSeconds,
               RunMeasurement, RunFits, RunResult, KelvinVoigtTwoPointFit, SessionKelvinVoigt,
               DampingLine, ComparedRestitutionModel, ComparedContactLaw, ModelComparison,
               LogSourceResult, ChannelComparison, LogComparison, RunPrediction, Apparatus,
               Specimen, SessionResult>;

template <typename Field>
constexpr bool IsColumnField = false;
template <typename Rows, typename Member>
constexpr bool IsColumnField<ColumnField<Rows, Member>> = true;
template <typename Listed>
constexpr bool IsSquareField = false;
template <typename T>
constexpr bool IsSquareField<StoredAs<Storage::kSquare, T>> = true;

// Calls visit.template operator()<Result>() for every listed result type.
template <typename Visit>
void ForEachListedResult(Visit&& visit) {
  [&]<typename... Result>(std::tuple<Result...>*) {
    (visit.template operator()<Result>(), ...);
  }(static_cast<ListedResults*>(nullptr));
}

// Gives every listed field of `result` a value of its own, unlike its
// default and every other field's (a field listed only when an earlier one
// holds something is reached, since the earlier one then does).
template <typename Result>
void FillEveryField(Result& result) {
  int k = 1;
  Result::VisitFields(result, [&](const char*, auto&& listed, Quantity, const char*) {
    auto& field = FieldOf(listed);
    using Field = std::remove_cvref_t<decltype(field)>;
    const double v = 0.5 + k++;
    if constexpr (IsSquareField<std::remove_cvref_t<decltype(listed)>>) {
      field = {v, 0.25, 0.25, 2 * v};
    } else if constexpr (std::is_same_v<Field, double>) {
      field = v;
    } else if constexpr (std::is_same_v<Field, std::optional<double>>) {
      field = v;
    } else if constexpr (std::is_same_v<Field, std::vector<double>>) {
      field = {v, -v, 2 * v};
    } else if constexpr (std::is_same_v<Field, std::vector<std::string>>) {
      field = {fmt::format("line {}", v), fmt::format("line {}", -v)};
    } else if constexpr (std::is_same_v<Field, Estimate>) {
      field = {v, v / 8};
    } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
      field = Estimate{v, v / 16};
    } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
      field = {{v, v / 8}, {-v, v / 4}};
    } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
      field.values = {v, 0.25, 0.25, 2 * v};
    } else if constexpr (IsColumnField<Field>) {
      field.rows.resize(3);
      for (std::size_t i = 0; i < 3; ++i) field.rows[i].*field.member = v * (i + 1.0);
    } else if constexpr (std::is_same_v<Field, std::string>) {
      field = fmt::format("text {}", v);
    } else if constexpr (std::is_same_v<Field, bool>) {
      field = !field;
    } else {
      field = k + 3;
    }
  });
}

// Every listed field of `result` as "<prefix><name> = <value>", in list order.
template <typename Result>
std::vector<std::string> EveryField(const Result& result, const std::string& prefix = "") {
  std::vector<std::string> out;
  Result::VisitFields(result, [&](const char* name, auto&& listed, Quantity, const char*) {
    const auto& field = FieldOf(listed);
    using Field = std::remove_cvref_t<decltype(field)>;
    std::string text;
    if constexpr (std::is_same_v<Field, std::vector<double>> ||
                  std::is_same_v<Field, std::vector<std::string>>) {
      text = fmt::format("{}", fmt::join(field, " | "));
    } else if constexpr (std::is_same_v<Field, std::optional<double>>) {
      text = field ? fmt::format("{}", *field) : "none";
    } else if constexpr (std::is_same_v<Field, Estimate>) {
      text = fmt::format("{} ± {}", field.value, field.sigma);
    } else if constexpr (std::is_same_v<Field, std::optional<Estimate>>) {
      text = field ? fmt::format("{} ± {}", field->value, field->sigma) : "none";
    } else if constexpr (std::is_same_v<Field, std::vector<Estimate>>) {
      for (const Estimate& e : field) text += fmt::format("{} ± {}; ", e.value, e.sigma);
    } else if constexpr (std::is_same_v<Field, SquareMatrix>) {
      text = fmt::format("{}", fmt::join(field.values, " "));
    } else if constexpr (IsColumnField<Field>) {
      for (const auto& row : field.rows) text += fmt::format("{} ", row.*field.member);
    } else {
      text = fmt::format("{}", field);
    }
    out.push_back(prefix + name + " = " + text);
  });
  return out;
}

}  // namespace impactlab::testing
