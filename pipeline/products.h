// The session-level products of `reduce` (docs/reduction.md, "Products"):
// what a reduce is asked to make, and, in its results, what it made and why
// it skipped the others.
//
// Asked: the [products] table of session.toml and the `--products.KEY` flags
// (one list, options/settings.h, like every stage's settings). A product is
// made only when it is asked for AND the session's data can inform it (a
// contact law whose parameters the data cannot fix is not fitted;
// leave-one-out needs three runs). Product selection never enters a run's
// fingerprint: asking for one more product later reuses every measurement.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace impactlab {

// The contact laws fitted across the runs (fit/contact_law_fit.h), one each.
struct ContactLawProducts {
  bool kelvin_voigt = true;     // zeta from the maxima; K from contact times
  bool hertz = true;            // elastic; k from contact times (needs them)
  bool hunt_crossley = true;    // chi from the maxima; k from contact times; n = 3/2
  bool hunt_crossley_n = true;  // n free as well (needs contact times at several speeds)
  bool hertz_damper = true;     // F = k x^n + c x' (needs contact times)

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("kelvin_voigt", self.kelvin_voigt, "fit the Kelvin-Voigt law across the runs");
    visit("hertz", self.hertz, "fit the elastic Hertz law (needs contact times)");
    visit("hunt_crossley", self.hunt_crossley, "fit Hunt-Crossley with n = 3/2");
    visit("hunt_crossley_n", self.hunt_crossley_n,
          "fit Hunt-Crossley with n free (needs contact times at several speeds)");
    visit("hertz_damper", self.hertz_damper,
          "fit Hertz with a linear damper (needs contact times)");
  }
};

struct ProductOptions {
  // The restitution models (per-run, common, linear-in-speed) and the laws'
  // predictions of the maxima, compared across three runs or more.
  bool model_comparison = true;
  // Poynting-Thomson with one parameter set for every run (two runs or more).
  bool joint_fits = true;
  ContactLawProducts contact_laws;
  // Each contact law's 68 % intervals: the linearised one where the chi^2
  // screen accepts it, else the profile-likelihood interval.
  bool intervals = true;
  // Leave-one-run-out refits of the model comparison and the contact laws
  // (three runs or more).
  bool leave_one_out = true;
  // Each digitized photo's overlay at a quarter of its width as an HDF5 image
  // in the results file (the overlay's JPEG is always kept).
  bool thumbnails = true;

  template <typename Self, typename Visit>
  static void VisitSettings(Self& self, Visit&& visit) {
    visit("model_comparison", self.model_comparison,
          "compare the restitution models across the runs (3 runs or more)");
    visit("joint_fits", self.joint_fits, "fit Poynting-Thomson jointly to the runs (2 or more)");
    visit("contact_laws", self.contact_laws, "");
    visit("intervals", self.intervals,
          "the contact laws' 68 % intervals (profile where the linear one fails)");
    visit("leave_one_out", self.leave_one_out,
          "refit without each run and predict it (3 runs or more)");
    visit("thumbnails", self.thumbnails, "photo overlays as HDF5 images in the results file");
  }
  bool Check(std::string*) const { return true; }
};

// What became of one product in a reduce.
struct ProductRecord {
  std::string name;    // the product's key below `products.`, e.g. "contact_laws.hertz"
  bool made = false;   // asked for and informed by the data
  std::string reason;  // when skipped: "not asked", or "the data cannot inform it: ..."

  // "made", or "skipped: <reason>" (the results file's form).
  std::string Status() const { return made ? "made" : "skipped: " + reason; }
};

inline constexpr std::string_view kNotAsked = "not asked";
inline constexpr std::string_view kUninformed = "the data cannot inform it: ";

// The record of product `name`: made when asked for and nothing keeps the
// data from informing it (`uninformed` empty), else skipped with why.
inline ProductRecord DecideProduct(std::string name, bool asked, const std::string& uninformed) {
  if (!asked) return {std::move(name), false, std::string(kNotAsked)};
  if (!uninformed.empty()) return {std::move(name), false, std::string(kUninformed) + uninformed};
  return {std::move(name), true, ""};
}

}  // namespace impactlab
