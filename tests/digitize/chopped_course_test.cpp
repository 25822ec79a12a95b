// A sparse chopper's few short dashes: a continuous line crossing the band (a
// scratch, a ring's arc) runs through its wide gaps, where the beam was
// blanked, and is not the trace's course.
#include <algorithm>
#include <optional>
#include <vector>

#include <catch2/catch.hpp>

#include "digitize/course_search.h"
#include "digitize/trace_track.h"

namespace impactlab {
namespace {

// A course of dashes `dash` columns long every `period` columns over
// `columns`, with one unbroken run of `run` columns from `run_from` in place
// of the dashes there.
std::vector<digitize::Chosen> DashedCourse(int columns, int dash, int period, int run_from,
                                           int run) {
  std::vector<digitize::Chosen> chosen;
  for (int c = 0; c < columns; ++c) {
    const bool in_run = c >= run_from && c < run_from + run;
    const bool in_dash = c % period < dash && (c < run_from - 2 || c >= run_from + run + 2);
    if (!in_run && !in_dash) continue;
    const bool joined = !chosen.empty() && chosen.back().column == c - 1;
    chosen.push_back(
        {c, 0, joined ? digitize::CoarsePath::kOnCourse : digitize::CoarsePath::kRestart});
  }
  return chosen;
}

std::size_t CountIn(const std::vector<digitize::Chosen>& foreign, int from, int to) {
  return static_cast<std::size_t>(
      std::count_if(foreign.begin(), foreign.end(),
                    [&](const digitize::Chosen& c) { return c.column >= from && c.column < to; }));
}

// The course without the columns `drop` says, the next column seen after
// each bridged on course.
std::vector<digitize::Chosen> Without(std::vector<digitize::Chosen> chosen,
                                      bool (*drop)(int column)) {
  std::erase_if(chosen, [&](const digitize::Chosen& c) { return drop(c.column); });
  return chosen;
}

}  // namespace

TEST_CASE("chopped course: a run across two of a sparse chopper's wide gaps is foreign") {
  // Dashes of 4 columns every 24 (randomised seed 1008's run 0.405): a
  // scratch the course followed for 51 columns, two periods, crossed two
  // gaps where the beam was blanked. Three periods (72 columns) were asked
  // before, and the scratch stood as the trace's course.
  const std::vector<digitize::Chosen> sparse = DashedCourse(350, 4, 24, 177, 51);
  const std::vector<digitize::Chosen> foreign = digitize::ForeignRuns(sparse);
  CHECK(CountIn(foreign, 177, 228) == 51);
  CHECK(foreign.size() == 51);
  // Where the line crosses a vertical grid line it loses a column or two (a
  // candidate there must outshine the line): still one run.
  CHECK(CountIn(digitize::ForeignRuns(Without(sparse, [](int c) { return c == 200 || c == 201; })),
                177, 228) == 49);
  // Dashes a short break apart (a stretch seen in five of its six
  // columns) are not a line: not judged.
  CHECK(digitize::ForeignRuns(Without(sparse, [](int c) {
          return c >= 177 && c < 228 && c % 6 == 0;
        })).empty());
  // A run no longer than a period and a gap may be a dash whose blur
  // reached a neighbour's: not judged.
  CHECK(digitize::ForeignRuns(DashedCourse(350, 4, 24, 177, 40)).empty());
  // A fine chopper's gaps (3 columns) may be bridged by blur and glow: only
  // three periods (15 columns) tell, as before.
  CHECK(digitize::ForeignRuns(DashedCourse(350, 2, 5, 177, 14)).empty());
  CHECK(CountIn(digitize::ForeignRuns(DashedCourse(350, 2, 5, 177, 16)), 177, 193) == 16);
}

TEST_CASE("chopped course: a line taken all along is foreign to the beam's chopper") {
  // A hair along the band outshone the dashes column by column (randomised
  // seed 1019's run 0.713): the course is one unbroken run and shows no
  // chopper of its own, so it alone cannot be judged.
  std::vector<digitize::Chosen> line;
  for (int c = 20; c < 330; ++c) {
    line.push_back(
        {c, 0, c == 20 ? digitize::CoarsePath::kRestart : digitize::CoarsePath::kOnCourse});
  }
  CHECK_FALSE(digitize::ChopperOf(line).has_value());
  CHECK(digitize::ForeignRuns(line).empty());
  // The other displacement trace, on the same chopped beam, shows the
  // chopper: dashes of 4 columns every 24.
  const std::optional<digitize::Chopper> beam =
      digitize::ChopperOf(DashedCourse(350, 4, 24, 400, 0));
  REQUIRE(beam.has_value());
  CHECK(beam->dash_columns == Approx(4.0));
  CHECK(beam->gap_columns == Approx(20.0));
  CHECK(digitize::ForeignRuns(line, beam).size() == line.size());
  // A dashed course is judged by its own chopper, as before: its dashes are
  // its own, whatever the beam's.
  const std::vector<digitize::Chosen> dashes = DashedCourse(350, 4, 24, 400, 0);
  CHECK(digitize::ForeignRuns(dashes, beam).empty());
  // A line no longer than a period and a gap of the beam's chopper may be a
  // dash blurred into its neighbour: not judged.
  std::vector<digitize::Chosen> short_line(line.begin(), line.begin() + 40);
  CHECK(digitize::ForeignRuns(short_line, beam).empty());
}

}  // namespace impactlab
