// The digitizer on photos of a digital scope's screen (PhotoStyle::kDigital):
// a dotted graticule, coloured pixelated waveforms, on-screen text and
// menus, against the generator's exact mapping.
#include <string>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "digitize/digitize.h"
#include "synth/session_generator.h"
#include "tests/digitize/photo_scenes.h"
#include "tests/digitize/randomised_session.h"
#include "tests/support/temp_dir.h"

namespace impactlab {

// Every photo of six quick digital sessions (36). Each dotted graticule
// found is the screen's, to a pixel or two anywhere on it: none is taken a
// division or more off it, on the panel's menus and text, as 5 of them were
// (50-91 px) before its lines were measured along stretches longer than
// their dots' spacing and judged so, and as 2 lattices found among the dots
// alone were (51-57 px) before their outermost lines decided; and most are
// found (27 of 36 when this was written, 22 before the search among the
// dots; the rest are refused, saying why).
TEST_CASE("digital screen: a dotted graticule found is the screen's, and most are found") {
  int found = 0, photos = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    testing::TempDir dir;
    const SynthSummary summary =
        GenerateSession(dir.path() / "s", testing::SynthOf("quick", PhotoStyle::kDigital, seed));
    std::vector<const nlohmann::json*> truths;
    for (const auto& run : summary.truth["runs"]) truths.push_back(&run["photo"]);
    for (const auto& calibration : summary.truth["calibrations"]) {
      if (calibration.contains("photo")) truths.push_back(&calibration["photo"]);
    }
    for (const nlohmann::json* photo_truth : truths) {
      const std::string file = (*photo_truth)["file"];
      INFO("seed " << seed << " " << file);
      const Photo photo = LoadPhoto(dir.path() / "s" / file);
      const GraticuleOptions options;
      ++photos;
      try {
        const GraticuleFit fit = FindGraticule(PreparePhoto(photo, options), {10, 8}, options);
        ++found;
        const GraticuleMapping truth = testing::MappingFromTruth((*photo_truth)["mapping"]);
        CHECK(testing::WorstMappingError(fit, truth) < 2.0);
        CHECK(fit.dotted);  // a raster's graticule: its steps are placed to a column
      } catch (const InputError&) {
        // Refused: said why (tests/digitize/errors_test.cpp pins the wording).
      }
    }
  }
  INFO(found << " of " << photos << " found");
  CHECK(photos == 36);
  CHECK(found >= 25);
}

// The styles of a CRT's photo: solid graticule lines, never taken for a
// raster's dots (whose columns would widen a contact time's error).
TEST_CASE("digital screen: a CRT photo's graticule is not dotted") {
  for (const PhotoStyle style : {PhotoStyle::kClean, PhotoStyle::kPolaroid, PhotoStyle::kPhone,
                                 PhotoStyle::kNegative, PhotoStyle::kLowres}) {
    testing::TempDir dir;
    const SynthSummary summary =
        GenerateSession(dir.path() / "s", testing::SynthOf("quick", style, 1));
    for (const auto& run : summary.truth["runs"]) {
      const std::string file = run["photo"]["file"];
      INFO(PhotoStyleName(style) << " " << file);
      const Photo photo = LoadPhoto(dir.path() / "s" / file);
      const GraticuleOptions options;
      CHECK_FALSE(FindGraticule(PreparePhoto(photo, options), {10, 8}, options).dotted);
    }
  }
}

}  // namespace impactlab
