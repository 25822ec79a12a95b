// The graticule search on generated photos whose scenes once defeated it,
// against the generator's exact mapping. The photos come from the session
// generator (`impactlab synth`), not from committed images, so they follow
// the renderer.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "digitize/digitize.h"
#include "digitize/lattice.h"
#include "synth/session_generator.h"
#include "tests/digitize/photo_scenes.h"
#include "tests/digitize/randomised_session.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {}  // namespace

// Seed 3 of the quick preset, run 0.713 (a person reads every grid line of
// both photos). Its contact pulse is long: the trace's upper level is a
// bright straight line across most of the screen, with twice a grid line's
// Hough votes, between two horizontal lines; the bezel's lip, 0.3 division
// beyond the grid, is as bright. In the phone photo glare and tilt leave the
// vertical lines right of the middle faint, too faint to be among the Hough
// candidates. The lattice search filled the gaps with traces' sloped
// stretches crossing the transversal in step (a lattice of half the spacing)
// and took the level or the lip for a grid line, and the photo was refused
// ("its line x = 10 div is not in the photo"; polaroid: "only 125 of 534
// measurements ... look like a grid line", after two minutes).
TEST_CASE("graticule: a long bright contact level and faint far grid lines do not mislead it") {
  for (const PhotoStyle style : {PhotoStyle::kPhone, PhotoStyle::kPolaroid}) {
    INFO(PhotoStyleName(style));
    testing::TempDir dir;
    SynthOptions synth;
    synth.preset = "quick";
    synth.style = style;
    synth.seed = 3;
    const SynthSummary summary = GenerateSession(dir.path() / "s", synth);
    const nlohmann::json* photo_truth = nullptr;
    for (const auto& run : summary.truth["runs"]) {
      if (run["id"] == "0.713") photo_truth = &run["photo"];
    }
    REQUIRE(photo_truth != nullptr);
    const GraticuleMapping truth = testing::MappingFromTruth((*photo_truth)["mapping"]);

    const Photo photo = LoadPhoto(dir.path() / "s" / (*photo_truth)["file"].get<std::string>());
    const GraticuleOptions options;
    const GraticuleFit fit = FindGraticule(PreparePhoto(photo, options), {10, 8}, options);
    CHECK(fit.residual_px < 0.5);
    // About 1.5 times the worst seen (0.17 px phone, 0.12 px polaroid).
    CHECK(testing::WorstMappingError(fit, truth) < 0.3);
  }
}

// A long contact level running along an inner grid line, a few hundredths of
// a division off it, on a blurred, low-resolution photo whose graticule is lit
// almost as brightly as the traces: the two merge into one broad line, so the
// grid line is seen where the fit puts it at only a few of its places, yet
// its neighbours and the outermost lines fix the lattice. (The external
// low-resolution set's run 0.902: "its line y = -3 div is not in the photo
// (seen at 9 of 30 places)".)
TEST_CASE("graticule: an inner line merged with a contact level along most of its length") {
  testing::RunScene run = testing::StandardRunScene();
  ScreenTrace& contact = run.scene.traces[2];
  // Low at -3.6 div, high at -2.95 div from x = 0.6 to 9 div.
  contact.settings = testing::Settings(100e-6, 1.0 / 0.65, -3.6, {-4.0, -2.4});
  contact.settings.impact = 2;
  for (std::size_t i = 0; i < contact.time_s.size(); ++i) {
    const double t = contact.time_s[i];
    contact.volts[i] = t >= 60e-6 && t < 900e-6 ? 1.0 : 0.0;
  }
  for (const double grid_level : {0.5, 0.7}) {
    RenderOptions options;
    options.style = PhotoStyle::kLowres;
    options.seed = 11;
    RenderedPhoto photo = RenderOscillograph(run.scene, options);
    testing::BrightenGraticule(photo.image, photo, grid_level);
    INFO("graticule redrawn at " << grid_level << " of full scale");
    const GraticuleOptions graticule;
    const GraticuleFit fit = FindGraticule(
        PreparePhoto({photo.image, "merged-line.jpg"}, graticule), {10, 8}, graticule);
    // The same photo without the contact level: 0.62 px at 1000 px wide.
    CHECK(testing::WorstMappingError(fit, photo) < 0.8);
  }
}

namespace {

// A photo of a generated randomised session, and its true mapping.
struct RandomisedPhoto {
  Photo photo;
  GraticuleMapping truth;
  double halftone_period_px = 0.0;  // a print's screen, as drawn (0: none)
  bool dark_traces = false;         // a negative, or a print (dark ink on paper)
};

// Every photo of a generated randomised quick session (`width_px` 0: each
// photo's own drawn size; `handling`: with marks, tape and prints).
std::vector<std::pair<std::string, RandomisedPhoto>> LoadRandomisedSession(
    const testing::TempDir& dir, unsigned seed, int width_px = 0, bool handling = false) {
  SynthOptions synth = testing::RandomisedSynth(seed);
  synth.width_px = width_px;
  // Most cases were found without the handling (marks about the traces,
  // tape, prints), which draws from a stream of its own.
  synth.photo_handling = handling;
  const SynthSummary summary = GenerateSession(dir.path() / "s", synth);
  std::vector<std::pair<std::string, RandomisedPhoto>> photos;
  for (const char* kind : {"runs", "calibrations"}) {
    for (const auto& item : summary.truth[kind]) {
      const auto& photo = item["photo"];
      if (photo.is_null()) continue;
      photos.push_back({item["id"].get<std::string>(),
                        {LoadPhoto(dir.path() / "s" / photo["file"].get<std::string>()),
                         testing::MappingFromTruth(photo["mapping"]),
                         photo["look"].value("halftone_period_px", 0.0),
                         photo["look"].value("polarity", "") == "negative"}});
    }
  }
  return photos;
}

RandomisedPhoto LoadRandomised(const testing::TempDir& dir, unsigned seed, const std::string& id,
                               bool handling = false) {
  for (auto& [photo_id, photo] : LoadRandomisedSession(dir, seed, 0, handling)) {
    if (photo_id == id) return std::move(photo);
  }
  FAIL("no photo " << id << " in seed " << seed);
  return {};
}

// The graticule found on randomised seed `seed`'s photo `id` (the photo's
// own drawn size; `handling`: with marks, tape and prints), and its worst
// error against the truth, px.
struct FoundGraticule {
  GraticuleFit fit;
  double worst_px = 0.0;
};

FoundGraticule FindRandomised(unsigned seed, const std::string& id, bool handling = false) {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, seed, id, handling);
  const GraticuleOptions options;
  GraticuleFit fit = FindGraticule(PreparePhoto(p.photo, options), {10, 8}, options);
  const double worst = testing::WorstMappingError(fit, p.truth);
  return {std::move(fit), worst};
}

}  // namespace

// Randomised seed 8 drawn 1000 px wide (the synth test's sample),
// calibration L-0.713: the Hough lattice lay a division right, its line
// x = 10 on the print's white border and the grid's line x = 0, in the
// bezel's shade, a division left of its x = 0. Both are hidden everywhere by
// something far brighter than a line, so neither refused the lattice, and
// the calibration read 32 % of its sweep through a mapping a division off:
// its run's left bar came out 13 % of X0 high. Seen as a line and not an
// edge, the lattice's x = 10 is seen nowhere and the line beyond x = 0 at
// 16 of 24 places: the lattice a division left passes every check and
// doubts nothing back, and is the grid.
TEST_CASE("graticule: an outermost line only an edge stands for moves the lattice onto the grid") {
  testing::TempDir dir;
  int found = 0;
  for (const auto& [id, p] : LoadRandomisedSession(dir, 8, 1000)) {
    if (id != "L-0.713") continue;
    const GraticuleOptions options;
    const GraticuleFit fit = FindGraticule(PreparePhoto(p.photo, options), {10, 8}, options);
    const double worst = testing::WorstMappingError(fit, p.truth);
    // Measured 0.64 px of a 51.6 px division.
    INFO("worst " << worst << " px of a " << fit.px_per_div << " px division");
    CHECK(worst < 0.05 * fit.px_per_div);
    ++found;
  }
  CHECK(found == 1);
}

// Randomised seeds 4005 and 4019 (with the generator's handling),
// calibrations: printed figures whose ink fades out towards the
// right, their lines x = 7, 8, 9 at 0.80, 0.55, 0.30 (4005) and 0.98, 0.73,
// 0.48 (4019) of the grid's usual height, x = 10 seen at 1 and 6 of 24
// places. Refused as a lattice a division too wide ("its line x = 10 div is
// not in the photo"); the lines' fall, carried on one line, leaves nothing
// to see there, and the lattice is the grid.
TEST_CASE("graticule: an outermost line where a print's ink fades out does not refuse it") {
  for (const unsigned seed : {4005u, 4019u}) {
    const FoundGraticule g = FindRandomised(seed, "R-0.713", /*handling=*/true);
    INFO("seed " << seed << ": worst " << g.worst_px << " px of a " << g.fit.px_per_div
                 << " px division");
    CHECK(g.worst_px < 0.02 * g.fit.px_per_div);
  }
}

// Randomised seed 1027, calibration L-0.713 (a scanned print): the screen's
// edge, a division left of the grid, is a dark line as sharp as a grid
// line, and the Hough lattice took it for x = 0, one division off ("its line
// x = 0 div is not in the photo"). Moved a division the way the unseen line
// points, every line is seen.
TEST_CASE(
    "graticule: a lattice placed a division off by the screen's edge is moved onto the grid") {
  const FoundGraticule g = FindRandomised(1027, "L-0.713");
  // Measured 0.077 and 0.054 px.
  CHECK(g.fit.residual_px < 0.2);
  CHECK(g.worst_px < 0.2);
}

// Randomised seed 1013, calibration L-0.405 (a scanned print): a division
// below the grid the screen's dark edge meets the print's white border. As
// a profile across it the step has a peak over its ramp, and the lattice,
// right to a pixel, was refused ("the photo shows a grid line at y = -5 div
// too"). A line has the same background either side; an edge does not.
TEST_CASE("graticule: a print's border a division beyond the grid is no extra grid line") {
  const FoundGraticule g = FindRandomised(1013, "L-0.405");
  // Measured 0.087 and 0.054 px.
  CHECK(g.fit.residual_px < 0.2);
  CHECK(g.worst_px < 0.2);
}

// Randomised seed 1018, calibration: a grid lit at 1.7 % of full
// scale inside a print's bright frame. No grid line is a Hough peak next to
// the frame's lines; the eleven together, as an evenly spaced comb, are.
TEST_CASE("graticule: a grid too faint for its lines to be peaks one by one is found as a comb") {
  const FoundGraticule g = FindRandomised(1018, "R-0.405");
  // Measured 0.54 and 0.30 px.
  CHECK(g.fit.residual_px < 0.8);
  CHECK(g.worst_px < 0.5);
}

// Randomised seed 2015 (with the generator's handling), calibration:
// a grid at 1.3 % of a trace's brightness, lines 0.4 px wide, under glare
// and sensor noise. Three of its eleven vertical lines are among the Hough
// peaks in step, too few for a family, but each family's comb holds every
// one of its lines: the two combs alone make the lattice, which the lines'
// fit and the checks after it accept.
TEST_CASE("graticule: a grid whose peaks hold too few lines in step is made of its combs alone") {
  const FoundGraticule g = FindRandomised(2015, "R-0.405", /*handling=*/true);
  INFO("residual " << g.fit.residual_px << " px, worst " << g.worst_px << " px");
  // Measured 0.53 and 0.30 px (42 px per division).
  CHECK(g.fit.residual_px < 0.8);
  CHECK(g.worst_px < 0.6);
}

// A lattice a division off fits its lines as well as the right one: its
// outermost line on an edge (the screen meeting the bezel, a print's border)
// or in glare, the grid's own line beyond it hidden by a trace. Such a
// graticule must be moved onto the grid or refused, never taken: a division
// off shifts every volt and second read from the photo. Randomised seeds 1-3
// at 1000 px held two such photos, both taken before: seed 1's run 0.405
// (now refused) and seed 3's calibration R-0.405 (now moved onto the grid).
// Seed 4's run 0.713 is still taken a division off (its left line on the
// print's edge, its right one in glare, each seen at a few places): the gap
// this test does not cover.
TEST_CASE("graticule: a randomised photo's graticule is right or refused, never a division off") {
  int right = 0, refused = 0;
  for (unsigned seed = 1; seed <= 3; ++seed) {
    testing::TempDir dir;
    for (const auto& [id, p] : LoadRandomisedSession(dir, seed, 1000)) {
      INFO("seed " << seed << " photo " << id);
      const GraticuleOptions options;
      try {
        const GraticuleFit fit = FindGraticule(PreparePhoto(p.photo, options), {10, 8}, options);
        CHECK(testing::WorstMappingError(fit, p.truth) < 0.1 * fit.px_per_div);
        ++right;
      } catch (const InputError&) {
        ++refused;
      }
    }
  }
  // 16 right and 2 refused when written.
  CHECK(right >= 14);
}

// Randomised seed 1006 with the generator's handling. Calibration
// is a figure printed on blank paper through a 3.5 px screen: dots only
// where the figure has ink, and with the ink spread round dots whose
// diagonal (sum) harmonic vanishes, which the screen's search required; the
// screen was not found. Calibration R-0.713's Hough lattice lay a division
// off in both families: moved once, the line beyond the other family's end
// still showed, and it was refused ("its line x = 10 div is not in the
// photo (seen at 0 of 24 places)"). Moved again, every line is seen.
TEST_CASE(
    "graticule: a print's screen without its sum frequency, and a lattice off in both families") {
  testing::TempDir dir;
  int prints = 0;
  for (const auto& [id, p] : LoadRandomisedSession(dir, 1006, 0, /*handling=*/true)) {
    INFO("photo " << id);
    const GraticuleOptions options;
    const PreparedPhoto prepared = PreparePhoto(p.photo, options);
    if (p.halftone_period_px > 0.0) {
      ++prints;
      // Found at 3.52 px for 3.51 px drawn.
      CHECK(prepared.halftone_period_px == Approx(p.halftone_period_px).epsilon(0.03));
    } else {
      CHECK(prepared.halftone_period_px == 0.0);
    }
    const GraticuleFit fit = FindGraticule(prepared, {10, 8}, options);
    // Measured 0.01-0.22 px (R-0.713: 0.07 px).
    CHECK(testing::WorstMappingError(fit, p.truth) < 0.35);
  }
  CHECK(prints == 1);
}

// Randomised seed 1003 (the generator's handling on, as in bench_robustness),
// run 0.713: a graticule at 3 % of the traces' brightness in a grainy
// photo, crossed by hairs. Noise votes in every Hough cell in proportion to
// the photo's length across that direction, longest near the diagonals, and
// the bare sums chose a direction 30 degrees off the vertical grid lines:
// the lattice was six divisions off and refused ("the photo shows a grid
// line at x = -1 div too"). Taken above the local floor, and the two
// families taken together, near perpendicular, the grid's directions win.
TEST_CASE("graticule: a faint grid in a grainy photo is searched along the grid's directions") {
  const FoundGraticule found = FindRandomised(1003, "0.713", /*handling=*/true);
  // Measured 0.59 px and 0.14 px (299 px per division).
  CHECK(found.fit.residual_px < 0.8);
  CHECK(found.worst_px < 0.3);
}

// Randomised seed 1003 (with the generator's handling), run 0.405: a
// barrel-distorted negative whose horizontal grid lines are fainter than
// its traces. Matched apart, the horizontal family took the contact level
// and a trace's crests for grid lines, in a progression spaced 33 px at one
// end and 25 at the other, while the vertical lines stayed parallel: no
// view of a grid does that (the perspective that spaces one family unevenly
// turns the other's lines), and the lattice missed its lines by 14.7 px RMS.
// Matched again with the perspective the vertical lines allow, it is the grid.
TEST_CASE(
    "graticule: a family bent by perspective the other family does not show is matched again") {
  const FoundGraticule found = FindRandomised(1003, "0.405", /*handling=*/true);
  // Measured 0.87 px and 0.55 px (128 px per division, lines 5 px wide).
  CHECK(found.fit.residual_px < 1.0);
  CHECK(found.worst_px < 0.9);
}

// Randomised seed 1005 (with the generator's handling), calibration L-0.405:
// a small positive photo whose middle is mostly the light panel round the
// scope and its black bezel. Judged on the grey levels, the tones below the
// median reached further than those above, the photo was taken for a
// negative, and the grid was looked for in the dark gaps between its lines
// ("the best lattice misses its lines by 3.54 px RMS"). The thin features
// decide: bright lines on a positive, dark ones on a negative or a print.
TEST_CASE("photo: the polarity is the thin features' and not the broad tones' round the screen") {
  testing::TempDir dir;
  for (const auto& [id, p] : LoadRandomisedSession(dir, 1005, 0, /*handling=*/true)) {
    INFO("photo " << id);
    const GraticuleOptions options;
    const PreparedPhoto prepared = PreparePhoto(p.photo, options);
    CHECK(prepared.dark_traces == p.dark_traces);
    if (id == "L-0.405") {
      const GraticuleFit fit = FindGraticule(prepared, {10, 8}, options);
      // Measured 0.019 px (33 px per division).
      CHECK(testing::WorstMappingError(fit, p.truth) < 0.1);
    }
  }
}

// The graticule of a halftone print `p`, its screen's period checked against
// the one drawn (within 3 %) before the lattice is searched through it.
GraticuleFit GraticuleThroughScreen(const RandomisedPhoto& p) {
  const GraticuleOptions options;
  const PreparedPhoto prepared = PreparePhoto(p.photo, options);
  CHECK(prepared.halftone_period_px == Approx(p.halftone_period_px).epsilon(0.03));
  return FindGraticule(prepared, {10, 8}, options);
}

// Randomised seed 1018 (with the generator's handling), run 0.405: a figure
// printed through a 6.3 px screen 3 degrees off the grid's lines, whose
// lower left took no ink (the grid there was fainter than the printer's
// threshold). The screen's dots are modulated by the grid's lines, which
// puts sidebands beside its peak where a comb's neighbouring harmonics would
// be, and the screen was not found; found and descreened, the grid's line
// x = 0 was seen at only 6 of its 24 places, all where it was printed, and
// the lattice, right, was refused as too large ("its line x = 0 div is not
// in the photo").
TEST_CASE("graticule: a print's screen along the grid and a grid printed over part of the figure") {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, 1018, "0.405", /*handling=*/true);
  // Its screen found at 6.39 px for 6.34 px drawn.
  const GraticuleFit fit = GraticuleThroughScreen(p);
  // Measured 0.34 px (80 px per division, lines 6 px wide).
  CHECK(testing::WorstMappingError(fit, p.truth) < 0.6);
}

// Randomised seed 1009 (with the generator's handling), calibration:
// a figure printed through a 6.6 px screen 2.4 degrees off the grid's
// lines, whose dots' transform vanishes at the screen's sum frequency. Its
// peak lies at the grid's 7th harmonic, with the figure's sidebands beside
// it, and the screen was not found: read as a photo, its lines as rows of
// dots, the lattice (right to a pixel) was refused ("the best lattice misses
// its lines by 1.68 px RMS"). Its peak is as strong turned a right angle and
// stands well above the grid's lower harmonics: a screen, not a comb.
TEST_CASE("graticule: a print's screen along the grid without its sum frequency") {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, 1009, "R-0.713", /*handling=*/true);
  // Its screen found at 6.74 px for 6.61 px drawn.
  const GraticuleFit fit = GraticuleThroughScreen(p);
  // Measured 0.36 px RMS and about 0.2 px (46 px per division).
  CHECK(fit.residual_px < 0.6);
  CHECK(testing::WorstMappingError(fit, p.truth) < 0.5);
}

// Randomised seed 1031 (with the generator's handling), run 0.405: a
// 3383 px photo of a print in noise, its grid lines 1.7 px wide. In the
// 500 px working copy a line is a quarter of a pixel, lost in the grain,
// and the horizontal family was matched through the traces' levels ("the
// two families of lines found are not one perspective view of a grid").
// Looked for again in finer working copies, as a person looks closer, the
// lattice is found and passes the same checks.
TEST_CASE("graticule: a lattice not found in the working copy is looked for closer") {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, 1031, "0.405", /*handling=*/true);
  const GraticuleOptions options;
  const PreparedPhoto prepared = PreparePhoto(p.photo, options);
  std::string why;
  // The working copy holds no lattice of the grid's: none, or (its faint
  // family matched again through a comb) one far off the grid, which its
  // lines refuse (measured 426 px off at a corner).
  if (const auto lattice =
          digitize::FindLattice(prepared, {10, 8}, options.max_rotation_deg, &why)) {
    const double f = prepared.shrink;
    const cv::Matx33d photo_from_working(f, 0.0, 0.5 * (f - 1), 0.0, f, 0.5 * (f - 1), 0.0, 0.0,
                                         1.0);
    const cv::Vec3d corner = photo_from_working * lattice->working_from_screen * cv::Vec3d(0, 4, 1);
    CHECK(cv::norm(cv::Point2d(corner[0] / corner[2], corner[1] / corner[2]) -
                   p.truth.ImageFromScreen({0.0, 4.0})) >
          0.5 * p.truth.PixelsPerDivisionAt({5.0, 0.0}));
  }
  const GraticuleFit fit = FindGraticule(prepared, {10, 8}, options);
  // Measured 0.17 px RMS and 0.09 px (197 px per division).
  CHECK(fit.residual_px < 0.4);
  CHECK(testing::WorstMappingError(fit, p.truth) < 0.3);
}

// Randomised seed 1022 (with the generator's handling), calibration:
// a grid at 2 % of full scale, its lines half a pixel wide, under sensor
// noise of 3 % (a person sees it contrast-stretched). Its pixels lie below
// the ridge votes' floor of three noise sigmas, and the vertical family's
// Hough direction was 13 degrees off the grid's lines ("found 2 of the 11
// vertical grid lines in step"). Looked at again with the floor at one and
// a half sigmas, the grid's long lines add up and the lattice is found.
TEST_CASE("graticule: a faint grid under heavy noise is looked for again with a lower floor") {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, 1022, "R-0.713", /*handling=*/true);
  const GraticuleOptions options;
  const PreparedPhoto prepared = PreparePhoto(p.photo, options);
  std::string why;
  CHECK_FALSE(digitize::FindLattice(prepared, {10, 8}, options.max_rotation_deg, &why));
  CHECK(digitize::FindLattice(prepared, {10, 8}, options.max_rotation_deg, &why,
                              digitize::kFaintRidgeFloorSigmas));
  const GraticuleFit fit = FindGraticule(prepared, {10, 8}, options);
  // Measured 0.42 px RMS (45 px per division) and 0.17 px.
  CHECK(fit.residual_px < 0.6);
  CHECK(testing::WorstMappingError(fit, p.truth) < 0.5);
}

// Randomised seed 2002 (with the generator's handling), run 0.405: a
// figure printed through a 5.8 px screen and scanned at 655 px, 26 px per
// division. Its working copy was the photo itself, and what descreening
// leaves of the dots at that scale made a lattice of its own: a lattice 7
// divisions off passed every check and was taken. Searched no finer than
// half the screen's period, it is refused, as a person who cannot read the
// grid's lines refuses it (they barely stand out of the screen's tone).
TEST_CASE("graticule: a print is not searched finer than its screen allows") {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, 2002, "0.405", /*handling=*/true);
  const GraticuleOptions options;
  const PreparedPhoto prepared = PreparePhoto(p.photo, options);
  // Found at 5.76 px for 5.81 px drawn.
  REQUIRE(prepared.halftone_period_px == Approx(p.halftone_period_px).epsilon(0.03));
  REQUIRE(prepared.shrink < 0.5 * prepared.halftone_period_px);
  try {
    const GraticuleFit fit = FindGraticule(prepared, {10, 8}, options);
    CHECK(testing::WorstMappingError(fit, p.truth) < 0.1 * fit.px_per_div);
  } catch (const InputError& error) {
    // Refused, "the best lattice misses its lines by 1.86 px RMS".
    CHECK(std::string(error.what()).find("not found") != std::string::npos);
  }
}

// Randomised seed 1002 (with the generator's handling), run 0.713: a faint
// grid on a photographed print. The Hough lattice lay a division low; its
// lines said a line showed left of its left one (the screen's shading
// meeting the bezel), and moved that way it fitted worse, so it was refused.
// Each lattice a division from the first is tried, and the one lattice whose
// lines say nothing against it is the grid.
TEST_CASE("graticule: a lattice whose lines point the wrong way is found among its neighbours") {
  const FoundGraticule g = FindRandomised(1002, "0.713", /*handling=*/true);
  // Measured 1.06 px RMS and 0.75 px (78 px per division).
  CHECK(g.fit.residual_px < 1.5);
  CHECK(g.worst_px < 1.0);
}

// Randomised seed 1020 (with the generator's handling), calibration L-0.713:
// a faint grid photographed 18 degrees off the screen's normal, 78 px per
// division, its lines measured to 1.02 px RMS; refused at 1 px, a 75th of a
// division, though every line was where the lattice put it.
TEST_CASE("graticule: a large photo's faint lines are held to a share of a division") {
  const FoundGraticule g = FindRandomised(1020, "L-0.713", /*handling=*/true);
  CHECK(g.fit.residual_px > 1.0);  // the fixed pixel limit's refusal
  CHECK(g.fit.residual_px < 0.02 * g.fit.px_per_div);
  // Measured 0.52 px.
  CHECK(g.worst_px < 1.0);
}

// Randomised seed 1004 (with the generator's handling), calibration:
// a faint grid in a coarse JPEG, 126 px per division. Twelve vertical Hough
// lines were in step, and the lattice took the wrong eleven, a division off:
// its fit, bent by the line it had not, was refused at 3.73 px RMS ("the
// best lattice misses its lines"), and the lattice a division over, which
// every check accepts, was never tried.
TEST_CASE("graticule: a lattice refused by its fit is looked for among its neighbours") {
  const FoundGraticule g = FindRandomised(1004, "R-0.713", /*handling=*/true);
  // Measured 2.47 px RMS, within a 50th of a division, and 1.77 px.
  CHECK(g.fit.residual_px < 0.02 * g.fit.px_per_div);
  CHECK(g.worst_px < 0.03 * g.fit.px_per_div);
}

// Randomised seed 2026 (with the generator's handling), calibration:
// a 1362 px photo of a grid with hand marks and a blurred lens. The working
// copy's Hough lines placed a lattice two divisions off, and its lines said
// against it ("its line y = 2 div is not in the photo"); no move of a
// division mended it, and the search stopped there. Refused by its lines, a
// lattice is looked for closer as one not found is, and the grid is found.
TEST_CASE("graticule: a lattice refused by its lines is looked for closer") {
  const FoundGraticule g = FindRandomised(2026, "R-0.713", /*handling=*/true);
  // Measured 0.91 px RMS and 1.60 px (83 px per division, its lens's 1.3 %
  // barrel left to the lines' residual).
  CHECK(g.fit.residual_px < 0.02 * g.fit.px_per_div);
  CHECK(g.worst_px < 0.03 * g.fit.px_per_div);
}

// Randomised seed 3016 (with the generator's handling), run 0.713: a grid lit
// at 5 % of full scale in a grainy negative (3 % grain), 55 px a division.
// Each measurement averaged 0.04 division of its line and found the centre
// among the grain's bumps: the true lattice missed its lines by 1.66 px RMS
// and the search's was refused at 4.59 px ("the best lattice misses its
// lines"). Refused so, the lines are measured again over 0.3 division each.
TEST_CASE("graticule: a faint grid in grain is measured along longer stretches of its lines") {
  const FoundGraticule g = FindRandomised(3016, "0.713", /*handling=*/true);
  // Measured 0.46 px RMS, and within 0.25 px of the true mapping.
  CHECK(g.fit.residual_px < 0.02 * g.fit.px_per_div);
  CHECK(g.worst_px < 0.02 * g.fit.px_per_div);
}

// Randomised seed 2002 (with the generator's handling), run 0.405: a print
// whose grid lines, under a pixel wide, are lost in its 5.8 px screen. Its
// lattice off the grid is refused at 1.86 px RMS; measured over longer
// stretches the screen's rows of dots would pass as lines, so a print's
// lines are not measured again.
TEST_CASE("graticule: a print's lattice along its screen's rows is not measured again") {
  testing::TempDir dir;
  const RandomisedPhoto p = LoadRandomised(dir, 2002, "0.405", /*handling=*/true);
  const GraticuleOptions options;
  CHECK_THROWS_AS(FindGraticule(PreparePhoto(p.photo, options), {10, 8}, options), InputError);
}

}  // namespace impactlab
