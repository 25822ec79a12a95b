#include "pipeline/numerical_failure.h"

#include <stdexcept>

#include <catch2/catch.hpp>

#include "fit/contact_law_fit.h"

namespace impactlab {
namespace {

TEST_CASE("numerical_failure: an integration that fails ends that fit alone, saying why") {
  const ContactLawFit fit = FitOrNumericalFailure<ContactLawFit>(
      []() -> ContactLawFit { throw std::runtime_error("step size 1e-18 s below the minimum"); },
      [](ContactLawFit& f) { f.law = "hertz"; });
  CHECK(fit.law == "hertz");
  CHECK_FALSE(fit.status.Ran());
  CHECK(fit.reason == "the fit's integration failed: step size 1e-18 s below the minimum");
}

TEST_CASE("numerical_failure: a fit that runs is returned as it is") {
  ContactLawFit made;
  made.law = "kelvin_voigt";
  made.reason = "kept";
  const ContactLawFit fit = FitOrNumericalFailure<ContactLawFit>(
      [&] { return made; }, [](ContactLawFit& f) { f.law = "unused"; });
  CHECK(fit.law == "kelvin_voigt");
  CHECK(fit.reason == "kept");
}

TEST_CASE("numerical_failure: a programming error is not taken for the data's failure") {
  CHECK_THROWS_AS(
      FitOrNumericalFailure<ContactLawFit>(
          []() -> ContactLawFit { throw std::logic_error("a bug"); }, [](ContactLawFit&) {}),
      std::logic_error);
}

}  // namespace
}  // namespace impactlab
