// Ways a trace running beside something else is read as the trace: its
// profile beside a parallel grid line (FindLineCentre, digitize/line_profile.h)
// or a tick's end (GridCrossings, digitize/screen_geometry.h), and a course
// that left it for a label (StrayExcursions,
// digitize/course_search.h). All on inputs made in closed form.
#include <algorithm>
#include <cmath>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/course_search.h"
#include "digitize/line_profile.h"
#include "digitize/screen_geometry.h"

namespace impactlab::digitize {
namespace {

double Gaussian(double u, double centre, double fwhm) {
  const double z = (u - centre) / (fwhm / 2.3548);
  return std::exp(-0.5 * z * z);
}

// Across a trace (FWHM 8 px at offset 0) printed in the same ink as a grid
// line (FWHM 7.7 px) running beside it `gap_px` away: dark ink where either
// is, saturating (1 - (1 - a)(1 - b)), on a 0.05 ground.
Profile BesideALine(double gap_px, double trace_centre_px) {
  Profile profile;
  profile.direction = {0.0, 1.0};
  profile.step_px = 0.25;
  profile.start_px = -24.0;
  for (double u = -24.0; u <= 24.0 + 1e-9; u += profile.step_px) {
    const double trace = Gaussian(u, trace_centre_px, 8.0), line = Gaussian(u, gap_px, 7.7);
    profile.values.push_back(static_cast<float>(0.05 + 1.0 - (1.0 - trace) * (1.0 - line)));
  }
  profile.crossings.push_back({gap_px, 7.7, 1.5 * 7.7});
  return profile;
}

CentreSettings PrintSettings(double line_fwhm_px) {
  CentreSettings settings;
  settings.search_px = 3.0;
  settings.crossing_height = 1.0;
  settings.crossing_fwhm_px = line_fwhm_px;
  return settings;
}

// One candidate per column on the given rows (NaN: none), linked on course
// except where `restarts` says.
struct Course {
  std::vector<std::vector<Node>> columns;
  std::vector<Chosen> chosen;
};

Course CourseThrough(const std::vector<double>& rows, const std::vector<int>& restarts) {
  Course course;
  course.columns.resize(rows.size());
  for (int c = 0; c < static_cast<int>(rows.size()); ++c) {
    if (std::isnan(rows[c])) continue;
    Node node;
    node.column = c;
    node.row = rows[c];
    node.value = 1.0f;
    course.columns[c].push_back(node);
    const bool restart = std::find(restarts.begin(), restarts.end(), c) != restarts.end();
    course.chosen.push_back({c, 0, restart ? CoarsePath::kRestart : CoarsePath::kOnCourse});
  }
  return course;
}

}  // namespace

TEST_CASE("line centre: a trace beside a parallel grid line is measured apart from it") {
  // 9.5 px apart, 1.2 widths: at half maximum the two merge into one line
  // about 17 px wide unless the line's modelled light is taken off. Ink
  // saturates where the two overlap, so taking the line's light off as if
  // it added leans the centre up to a third of a pixel away from the line.
  for (const double truth : {-0.5, 0.0, 0.4}) {
    const LineCentre apart = FindLineCentre(BesideALine(9.5, truth), PrintSettings(7.7));
    REQUIRE(apart.found);
    CHECK(apart.fwhm_px == Approx(8.0).margin(1.0));
    CHECK(apart.offset_px == Approx(truth).margin(0.5));
  }
  // The premise: without knowing the grid line's width, nothing is taken
  // off, and the width is the two lines' together.
  const LineCentre merged = FindLineCentre(BesideALine(9.5, 0.0), PrintSettings(0.0));
  REQUIRE(merged.found);
  CHECK(merged.fwhm_px > 1.4 * 8.0);
}

TEST_CASE("line centre: a line across the trace is not taken off as one beside it") {
  // A grid line the trace crosses at a shallow angle is wide along the
  // profile (here 3 of its widths): it is no line beside the trace, and the
  // result is the one a grid line of unknown width gives.
  Profile profile = BesideALine(9.5, 0.0);
  profile.crossings.front().fwhm_px = 3.0 * 7.7;
  const LineCentre across = FindLineCentre(profile, PrintSettings(7.7));
  Profile unknown = BesideALine(9.5, 0.0);
  unknown.crossings.front().fwhm_px = 3.0 * 7.7;
  const LineCentre reference = FindLineCentre(unknown, PrintSettings(0.0));
  REQUIRE(across.found);
  CHECK(across.fwhm_px == reference.fwhm_px);
  CHECK(across.offset_px == reference.offset_px);
}

TEST_CASE("course search: an excursion reached and left by unexplained jumps is a stray") {
  // 30 rows a division: the trace at row 100 sloping down 0.2 rows a column,
  // lost for columns 40-69, where the course took a label at row 10.
  std::vector<double> rows(120);
  for (int c = 0; c < 120; ++c) rows[c] = 100.0 + 0.2 * c;
  for (int c = 40; c < 45; ++c) rows[c] = NAN;
  for (int c = 45; c < 65; ++c) rows[c] = 10.0 + 0.05 * (c % 3);
  for (int c = 65; c < 70; ++c) rows[c] = NAN;
  const Course course = CourseThrough(rows, {45, 70});
  const std::vector<Chosen> stray = StrayExcursions(course.chosen, course.columns, 30.0);
  REQUIRE(stray.size() == 20);
  CHECK(stray.front().column == 45);
  CHECK(stray.back().column == 64);
}

TEST_CASE("course search: jumps the course's own slope explains are no stray") {
  // A fast flank: the course falls 4 rows a column and loses the trace for
  // six columns on the way down and again on the way back up; where it
  // reappears is where its slope pointed.
  std::vector<double> rows(90, NAN);
  for (int c = 0; c < 30; ++c) rows[c] = 20.0 + 4.0 * c;    // down to row 136
  for (int c = 36; c < 50; ++c) rows[c] = 160.0 + 0.1 * c;  // the bottom, flat-ish
  for (int c = 56; c < 90; ++c) rows[c] = 180.0 - 4.0 * (c - 56);
  // Reaching the bottom, the flank's slope points at 20 + 4 * 36 = 164;
  // leaving it, the next flank's slope points back at its end.
  const Course course = CourseThrough(rows, {36, 56});
  CHECK(StrayExcursions(course.chosen, course.columns, 30.0).empty());
}

TEST_CASE("course search: an excursion at either end of the course is not judged") {
  // Nothing beyond it to agree with: the start may be where the trace is.
  std::vector<double> rows(80);
  for (int c = 0; c < 20; ++c) rows[c] = 10.0;
  for (int c = 20; c < 25; ++c) rows[c] = NAN;
  for (int c = 25; c < 80; ++c) rows[c] = 100.0;
  const Course course = CourseThrough(rows, {25});
  CHECK(StrayExcursions(course.chosen, course.columns, 30.0).empty());
}

// A profile 60 px long (0.5 px steps, 100 px a division) centred on
// `origin_div`, running along `direction` (screen divisions), near the
// horizontal centre axis's minor tick at x = 4.4 (from y = -0.1 to 0.1) of
// a 10 x 8 screen; a grid line's light is taken to reach 0.06 division
// (1.5 widths of 0.04).
Profile NearATick(cv::Point2d origin_div, cv::Point2d direction) {
  direction /= cv::norm(direction);
  Profile profile;
  profile.origin_px = origin_div * 100.0;
  profile.direction = direction;
  profile.step_px = 0.5;
  profile.start_px = -30.0;
  profile.values.assign(121, 0.0f);
  const GridCrossings grid({10, 8}, 0.04, 1.5);
  grid.AddTo(profile, origin_div - 0.3 * direction, origin_div + 0.3 * direction);
  return profile;
}

TEST_CASE("grid crossings: a profile reaching a tick's light is cut short of it, not thrown away") {
  // Straight down the screen at x = 4.43 from y = 0.7 to 0.1: the tick's
  // light reaches round its end at y = 0.1 to 0.1 + sqrt(0.06^2 - 0.03^2).
  Profile profile = NearATick({4.43, 0.4}, {0.0, -1.0});
  CHECK(profile.BesideShortLine());
  CHECK(profile.clear_lo_px == -HUGE_VAL);
  const double lit_from_px = 100.0 * (0.4 - 0.1 - std::sqrt(0.06 * 0.06 - 0.03 * 0.03));
  CHECK(profile.clear_hi_px == Approx(lit_from_px));
  // Reaching 20 px either side of the origin is enough: it is cut there.
  REQUIRE(CutToClearStretch(profile, 20.0));
  CHECK_FALSE(profile.BesideShortLine());
  const double end_px = profile.OffsetAt(static_cast<int>(profile.values.size()) - 1);
  CHECK(profile.OffsetAt(0) == -30.0);
  CHECK(end_px <= lit_from_px);
  CHECK(end_px > lit_from_px - profile.step_px);
  // Asked to reach 26 px, it cannot be used.
  Profile again = NearATick({4.43, 0.4}, {0.0, -1.0});
  CHECK_FALSE(CutToClearStretch(again, 26.0));
}

TEST_CASE("grid crossings: a profile whose origin lies in a tick's light cannot be cut clear") {
  Profile profile = NearATick({4.43, 0.13}, {0.0, -1.0});
  REQUIRE(profile.BesideShortLine());
  CHECK(profile.clear_lo_px == 0.0);
  CHECK(profile.clear_hi_px == 0.0);
  CHECK_FALSE(CutToClearStretch(profile, 1.0));
}

TEST_CASE("grid crossings: a profile passing a tick's end further than its light is not spoiled") {
  // From (4.50, 0.75) to (4.45, 0.15): its end lies within 0.06 of the tick
  // across (0.05) and beyond its end (0.05), but 0.07 from the end itself.
  const Profile profile = NearATick({4.475, 0.45}, {-0.05, -0.6});
  CHECK_FALSE(profile.BesideShortLine());
  // Moved 0.02 closer, its end is 0.043 from the tick's: lit.
  CHECK(NearATick({4.455, 0.43}, {-0.05, -0.6}).BesideShortLine());
}

}  // namespace impactlab::digitize
