// `impactlab synth`: sessions the reader accepts, reproducible from a seed,
// whose CSV and typed-in runs reduce back to the truth.
#include "synth/session_generator.h"

#include <array>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include <catch2/catch.hpp>

#include "io/manifest.h"
#include "pipeline/reduce.h"
#include "tests/support/temp_dir.h"
#include "tests/synth/manifest_match.h"

namespace impactlab {
namespace {

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Typed-in maxima are rounded to 0.001 in, which limits what e they give.
double form_tolerance(const nlohmann::json& truth) {
  return truth["form"] == "typed-in" ? 1e-2 : 2e-3;
}

SynthOptions QuickSmallPhotos(PhotoStyle style, std::uint64_t seed) {
  SynthOptions o;
  o.preset = "quick";
  o.style = style;
  o.seed = seed;
  o.width_px = 600;  // small photos keep the test fast
  o.csv_run = true;
  o.typed_run = true;
  return o;
}

TEST_CASE(
    "synth: every style gives a session the manifest reader accepts without warnings, holding "
    "the values the generator planned") {
  for (PhotoStyle style : {PhotoStyle::kClean, PhotoStyle::kPolaroid, PhotoStyle::kPhone,
                           PhotoStyle::kNegative, PhotoStyle::kLowres, PhotoStyle::kRandomised}) {
    INFO(PhotoStyleName(style));
    testing::TempDir dir;
    const SynthSummary summary = GenerateSession(dir.path() / "s", QuickSmallPhotos(style, 2));
    CHECK(summary.runs == 4);
    CHECK(summary.photos == 6);  // 2 photo runs: a run photo and two calibrations each
    const ManifestReadResult read = ReadManifest(dir.path() / "s");
    CHECK(read.warnings.empty());
    CHECK(read.session.runs.size() == 4);
    CHECK(read.session.calibrations.size() == 6);
    CHECK(summary.truth["runs"].size() == 4);
    testing::CheckReadsBack(summary.manifest, read.session);
    // The manifest gives X0 as written down, to 6 digits, the truth exactly.
    CHECK(summary.manifest.runs[0].initial_displacement ==
          Approx(summary.truth["runs"][0]["initial_displacement"].get<double>()).epsilon(1e-5));
  }
}

TEST_CASE("synth: the same seed writes the same bytes, another seed does not") {
  testing::TempDir dir;
  GenerateSession(dir.path() / "a", QuickSmallPhotos(PhotoStyle::kPhone, 7));
  GenerateSession(dir.path() / "b", QuickSmallPhotos(PhotoStyle::kPhone, 7));
  GenerateSession(dir.path() / "c", QuickSmallPhotos(PhotoStyle::kPhone, 8));
  for (const char* file : {"session.toml", "runs/0.405.jpg", "traces/csv-0.550-right.csv"}) {
    INFO(file);
    CHECK(Slurp(dir.path() / "a" / file) == Slurp(dir.path() / "b" / file));
    CHECK(Slurp(dir.path() / "a" / file) != Slurp(dir.path() / "c" / file));
  }
}

TEST_CASE("synth: a randomised session draws each photo's scope settings and records its look") {
  std::set<std::string> positions;
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    testing::TempDir dir;
    const SynthSummary summary =
        GenerateSession(dir.path() / "s", QuickSmallPhotos(PhotoStyle::kRandomised, seed));
    for (const auto& run : summary.truth["runs"]) {
      if (run["form"] != "photo") continue;
      const nlohmann::json& look = run["photo"]["look"];
      INFO("seed " << seed << " run " << run["id"] << ": " << look.dump());
      for (const char* key : {"width_px", "jpeg_quality", "polarity", "bit_depth", "blur_px",
                              "chop_slot_div", "chop_duty", "beam_fwhm_div", "slow_brightness",
                              "contact_position", "graticule_brightness", "hand_marks"}) {
        CHECK(look.contains(key));
      }
      CHECK(look["chop_duty"].get<double>() >= 0.2);
      CHECK(look["chop_slot_div"].get<double>() <= 0.5);
      // A line's light across it, in pixels at a slow trace core's brightness.
      const auto number = [&look](const char* key) { return look[key].get<double>(); };
      CHECK(number("graticule_line_px") ==
            Approx(number("graticule_brightness") * number("graticule_fwhm_div") *
                   number("px_per_div")));
      CHECK(number("beam_line_px") == Approx(number("slow_brightness") * number("beam_fwhm_px")));
      positions.insert(look["contact_position"].get<std::string>());
      // The bands lie on the 8-division screen and do not overlap.
      const auto& s = run["settings"];
      std::vector<std::array<double, 2>> bands;
      for (const char* trace : {"right", "left", "contact"}) {
        bands.push_back(s[trace]["band_div"].get<std::array<double, 2>>());
        CHECK(bands.back()[0] >= -4.0);
        CHECK(bands.back()[1] <= 4.0);
        CHECK(bands.back()[0] < bands.back()[1]);
      }
      for (std::size_t i = 0; i < bands.size(); ++i) {
        for (std::size_t j = i + 1; j < bands.size(); ++j) {
          CHECK((bands[i][1] <= bands[j][0] + 1e-9 || bands[j][1] <= bands[i][0] + 1e-9));
        }
      }
      // The file is as drawn: JPEG at its quality, else lossless.
      const std::string file = run["photo"]["file"];
      CHECK((look["jpeg_quality"].get<double>() > 0) == file.ends_with(".jpg"));
    }
    for (const auto& calibration : summary.truth["calibrations"]) {
      if (calibration.contains("photo")) CHECK(calibration["photo"].contains("look"));
    }
  }
  CHECK(positions.size() >= 2);
}

TEST_CASE("synth: CSV and typed-in runs reduce to the simulated maxima and contact time") {
  testing::TempDir dir;
  const SynthSummary summary =
      GenerateSession(dir.path() / "s", QuickSmallPhotos(PhotoStyle::kClean, 3));
  const SessionResult result = ReduceSession(ReadManifest(dir.path() / "s").session, {});
  for (const auto& truth : summary.truth["runs"]) {
    const std::string form = truth["form"];
    if (form == "photo") continue;
    const RunResult* run = result.FindRun(truth["id"]);
    REQUIRE(run != nullptr);
    INFO(run->id << ": " << run->Status());
    REQUIRE(run->ok);
    const double x0 = truth["initial_displacement"];
    const double tolerance = form == "csv" ? 1e-3 * x0 : 6e-4;  // typed: rounded to 0.001
    for (std::size_t n = 0; n < 5; ++n) {
      CHECK(std::abs(run->measured.xmax[n] - truth["rebounds"]["xmax"][n].get<double>()) <=
            tolerance);
    }
    CHECK(
        *run->measured.contact_time ==
        Approx(truth["contact"]["duration_s"].get<double>()).epsilon(form == "csv" ? 3e-3 : 1e-3));
    // The fitted K against the simulated element: eq. 37 from tau_c and zeta.
    CHECK(run->fits.kelvin_voigt->stiffness->value ==
          Approx(truth["kelvin_voigt"]["stiffness"].get<double>()).epsilon(0.02));
  }
}

TEST_CASE("synth: a Poynting-Thomson session's rebounds keep the simulated restitution") {
  testing::TempDir dir;
  SynthOptions o = QuickSmallPhotos(PhotoStyle::kClean, 4);
  o.contact_model = "poynting-thomson";
  const SynthSummary summary = GenerateSession(dir.path() / "s", o);
  const SessionResult result = ReduceSession(ReadManifest(dir.path() / "s").session, {});
  for (const auto& truth : summary.truth["runs"]) {
    if (truth["form"] == "photo") continue;
    CHECK(truth.contains("poynting_thomson"));
    const RunResult* run = result.FindRun(truth["id"]);
    REQUIRE(run != nullptr);
    REQUIRE(run->ok);
    // Every impact of a linear contact keeps the same fraction of the speed.
    CHECK(run->fits.kelvin_voigt->restitution.value ==
          Approx(truth["restitution"].get<double>()).epsilon(form_tolerance(truth)));
  }
}

TEST_CASE("synth: a non-empty output folder is refused, and so is an unknown preset") {
  testing::TempDir dir;
  std::filesystem::create_directories(dir.path() / "s");
  std::ofstream(dir.path() / "s" / "keep.txt") << "mine";
  CHECK_THROWS_WITH(GenerateSession(dir.path() / "s", QuickSmallPhotos(PhotoStyle::kClean, 1)),
                    Catch::Contains("not empty"));
  SynthOptions bad = QuickSmallPhotos(PhotoStyle::kClean, 1);
  bad.preset = "huge";
  CHECK_THROWS_AS(GenerateSession(dir.path() / "t", bad), std::invalid_argument);
}

TEST_CASE("synth: the bundled thesis photo session reads cleanly and matches its truth file") {
  const auto samples = std::filesystem::path(IMPACTLAB_SOURCE_DIR) / "sample_data";
  const ManifestReadResult read = ReadManifest(samples / "thesis-photos");
  CHECK(read.warnings.empty());
  const auto truth = nlohmann::json::parse(Slurp(samples / "thesis-photos.truth.json"));
  CHECK(truth["schema"] == "impactlab-synth-truth");
  REQUIRE(truth["runs"].size() == read.session.runs.size());
  for (std::size_t i = 0; i < read.session.runs.size(); ++i) {
    CHECK(truth["runs"][i]["id"] == read.session.runs[i].id);
    CHECK(read.session.runs[i].photo.has_value());
  }
}

}  // namespace
}  // namespace impactlab
