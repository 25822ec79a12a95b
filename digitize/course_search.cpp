#include "digitize/course_search.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "digitize/select.h"

namespace impactlab::digitize {

namespace {

// Path costs, in units of one full-height peak's reward.
constexpr double kBendWeight = 0.5;    // per (dy div off the course's slope)^2 / (dx div)
constexpr double kSteepWeight = 0.02;  // per (dy div)^2 / (dx div): keeps a course from wandering
constexpr double kGapWeight = 2.0;     // per division of gap
constexpr double kRestartCost = 3.0;   // a trace reappearing off its course after a gap
constexpr double kJumpCost = 2.0;      // a contact trace's step, whatever its height
constexpr double kRewardOffset = 0.1;  // a peak must be a tenth of the level to pay

}  // namespace

// The best-scoring course through the columns' candidates by dynamic
// programming: per column one candidate or none, rewarded for its peak and
// charged for leaving the course, steepness, gaps and restarts.
std::vector<Chosen> BestCourse(const std::vector<std::vector<Node>>& columns, const TrackGrid& grid,
                               double level, bool step_trace, int max_gap, OneWay one_way) {
  std::vector<Node> nodes;
  std::vector<int> first_of(grid.columns + 1, 0);
  for (int c = 0; c < grid.columns; ++c) {
    first_of[c] = static_cast<int>(nodes.size());
    nodes.insert(nodes.end(), columns[c].begin(), columns[c].end());
  }
  first_of[grid.columns] = static_cast<int>(nodes.size());
  // best_up_to[c]: the best-scoring node in columns 0..c (index), for restarts.
  std::vector<int> best_up_to(grid.columns, -1);
  // column_best[c]: the best score in column c. Leaving the course and gaps
  // only cost, so no node of a column scores more than that less the gap:
  // columns that cannot beat the best link so far are passed over.
  std::vector<double> column_best(grid.columns, -std::numeric_limits<double>::infinity());
  const double dx_unit = 1.0 / grid.px_per_div;
  // A one-way course restarts from the best node it can reach, not the best
  // of all: per whole row of `furthest` (from the least), the best node of
  // the columns passed; those up to a row beyond the reach are taken too.
  double least = 0.0;
  std::vector<int> restart_from;
  if (one_way.direction != 0 && !nodes.empty()) {
    double most = -std::numeric_limits<double>::infinity();
    least = std::numeric_limits<double>::infinity();
    for (const Node& n : nodes) {
      least = std::min(least, one_way.direction * n.row);
      most = std::max(most, one_way.direction * n.row);
    }
    least = std::floor(least);
    restart_from.assign(static_cast<std::size_t>(most - least) + 2, -1);
  }
  const auto row_bucket = [&](double furthest) {
    return std::clamp(static_cast<int>(std::floor(furthest - least)), 0,
                      static_cast<int>(restart_from.size()) - 1);
  };
  for (int c = 0; c < grid.columns; ++c) {
    if (!restart_from.empty() && c - 2 >= 0) {
      for (int k = first_of[c - 2]; k < first_of[c - 1]; ++k) {
        int& b = restart_from[static_cast<std::size_t>(row_bucket(nodes[k].furthest))];
        if (b < 0 || nodes[k].score > nodes[b].score) b = k;
      }
    }
    for (int k = first_of[c]; k < first_of[c + 1]; ++k) {
      Node& node = nodes[k];
      const double reward = std::min(node.value / level, 1.5) - kRewardOffset + node.hint_reward;
      // How far this node lies in a one-way course's direction; a course
      // that has gone further than `back_rows` beyond it cannot reach it.
      const double ahead = one_way.direction * node.row;
      const auto reachable = [&](const Node& from) {
        return one_way.direction == 0 || ahead >= from.furthest - one_way.back_rows;
      };
      double best = 0.0, best_slope = 0.0, best_trust = 0.0, best_furthest = ahead;
      int previous = -1;
      unsigned char link = CoarsePath::kOnCourse;
      for (int d = 1; d <= max_gap && c - d >= 0; ++d) {
        const double dx = d * dx_unit;
        const double gap = kGapWeight * (d - 1) * dx_unit;
        if (!(column_best[c - d] - gap > best)) continue;
        for (int j = first_of[c - d]; j < first_of[c - d + 1]; ++j) {
          const Node& from = nodes[j];
          if (!reachable(from)) continue;
          // Rows grow downwards; slopes here are in rows' direction, div/div.
          const double dy = (node.row - from.row) * dx_unit;
          const double off_course = dy - from.slope * dx;
          double bend =
              kBendWeight * from.trust * off_course * off_course / dx + kSteepWeight * dy * dy / dx;
          unsigned char kind = CoarsePath::kOnCourse;
          if (step_trace && bend > kJumpCost) bend = kJumpCost, kind = CoarsePath::kStep;
          const double score = from.score - bend - gap;
          if (score > best) {
            best = score, previous = j, link = kind;
            best_furthest = std::max(ahead, from.furthest);
            if (step_trace) {
              best_slope = 0.0, best_trust = 1.0;  // a contact trace's levels are flat
            } else {
              // The course's slope, smoothed over the last few columns; trust
              // in it grows with the path's length.
              const double weight = std::min(1.0, d / 4.0);
              best_slope =
                  from.trust > 0.0 ? (1.0 - weight) * from.slope + weight * dy / dx : dy / dx;
              best_trust = std::min(1.0, from.trust + 0.2 * d);
            }
          }
        }
      }
      // After a gap the trace may reappear anywhere, at a price.
      if (c - 2 >= 0) {
        int j = best_up_to[c - 2];
        if (!restart_from.empty()) {
          j = -1;
          const int reach = row_bucket(ahead + one_way.back_rows);
          for (int b = 0; b <= reach; ++b) {
            const int i = restart_from[static_cast<std::size_t>(b)];
            if (i >= 0 && (j < 0 || nodes[i].score > nodes[j].score)) j = i;
          }
        }
        if (j >= 0 && nodes[j].score - kRestartCost > best) {
          best = nodes[j].score - kRestartCost, previous = j, link = CoarsePath::kRestart;
          best_furthest = std::max(ahead, nodes[j].furthest);
          best_slope = 0.0, best_trust = step_trace ? 1.0 : 0.0;
        }
      }
      node.slope = best_slope;
      node.trust = step_trace ? 1.0 : best_trust;
      node.furthest = previous >= 0 ? best_furthest : ahead;
      node.score = reward + best;
      node.previous = previous;
      node.link = link;
      column_best[c] = std::max(column_best[c], node.score);
    }
    best_up_to[c] = c > 0 ? best_up_to[c - 1] : -1;
    for (int k = first_of[c]; k < first_of[c + 1]; ++k) {
      if (best_up_to[c] < 0 || nodes[k].score > nodes[best_up_to[c]].score) best_up_to[c] = k;
    }
  }
  std::vector<Chosen> chosen;
  for (int k = best_up_to[grid.columns - 1]; k >= 0; k = nodes[k].previous) {
    chosen.push_back({nodes[k].column, k - first_of[nodes[k].column], nodes[k].link});
  }
  std::reverse(chosen.begin(), chosen.end());
  return chosen;
}

namespace {

// Runs of neighbouring columns on a course, unbroken by restarts.
struct Run {
  std::size_t first = 0, end = 0;  // into `chosen`
};

std::vector<Run> RunsOf(const std::vector<Chosen>& chosen) {
  std::vector<Run> runs;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    const bool joined = i > 0 && chosen[i].column == chosen[i - 1].column + 1 &&
                        chosen[i].link != CoarsePath::kRestart;
    if (!joined) runs.push_back({i, i});
    runs.back().end = i + 1;
  }
  return runs;
}

}  // namespace

std::optional<Chopper> ChopperOf(const std::vector<Chosen>& chosen) {
  const std::vector<Run> runs = RunsOf(chosen);
  // Chopped: many runs, nearly all of a dash's length (a continuous trace
  // seen in pieces has few, of every length).
  constexpr std::size_t kMinRuns = 10;
  constexpr double kRegularShare = 0.8;
  if (runs.size() < kMinRuns) return std::nullopt;
  std::vector<float> lengths;
  for (const Run& r : runs) lengths.push_back(static_cast<float>(r.end - r.first));
  const double usual = MedianOf(lengths);
  const auto regular =
      std::count_if(lengths.begin(), lengths.end(), [&](float l) { return l <= 2.0 * usual; });
  if (regular < kRegularShare * static_cast<double>(runs.size())) return std::nullopt;
  // The chopper's period on the course: a dash and the gap after it.
  std::vector<float> gaps;
  for (std::size_t k = 1; k < runs.size(); ++k) {
    gaps.push_back(
        static_cast<float>(chosen[runs[k].first].column - chosen[runs[k - 1].end - 1].column - 1));
  }
  // A chopper the columns resolve: its gaps two columns or more. Finer
  // chopping (dense dot chains) leaves runs that grid lines and their
  // ticks cut, not the chopper, and says nothing of a foreign line.
  const double usual_gap = MedianOf(gaps);
  if (usual_gap < 2.0) return std::nullopt;
  return Chopper{usual, usual_gap};
}

// A chopped trace is drawn in only part of each chopper slot, so its course
// holds candidates in runs of neighbouring columns no longer than a dash,
// all alike, over about the chopper's duty of its columns. A run spanning
// several of the chopper's periods, on a course that is otherwise under
// kChoppedShare occupied, is something else the course took: a scratch or a hair crossing
// the band, whose continuous line out-earns sparse dashes column by column
// (and may even continue the trace's course where it crosses it). Returns
// those runs' candidates. With the beam's chopper known from another trace,
// a course that took a continuous line for all its length (a hair along the
// band outshining the dashes) shows no chopper of its own, and its runs are
// judged against the beam's.
std::vector<Chosen> ForeignRuns(const std::vector<Chosen>& chosen, std::optional<Chopper> beam) {
  constexpr double kChoppedShare = 0.6;  // of the rest of the course's columns
  constexpr int kMinColumns = 8;
  constexpr double kPeriods = 3.0;  // a foreign run spans more of the chopper's periods
  if (chosen.empty()) return {};
  const std::vector<Run> runs = RunsOf(chosen);
  std::optional<Chopper> own = ChopperOf(chosen);
  if (!own && !beam) return {};
  const Chopper chopper = own ? *own : *beam;
  const double usual = chopper.dash_columns, usual_gap = chopper.gap_columns;
  const double period = usual + usual_gap;
  // A chopper's blanking is in time, and the sweep draws time along the
  // columns: its gaps span the same columns however steep the trace. Where
  // they are wide (as long as its dashes at least, and kWideGapColumns: no
  // blur or glow fills them), a run across two of them (a period and a
  // gap) crossed where the beam was blanked twice, whatever the chopper's
  // duty: a sparse chopper's few short dashes leave three periods room for
  // a scratch or a ring's arc a division long.
  constexpr double kWideGapColumns = 4.0;
  const bool wide_gaps = usual_gap >= std::max(kWideGapColumns, usual);
  const double foreign_length =
      wide_gaps ? std::min(kPeriods * period, period + usual_gap) : kPeriods * period;
  // Between wide gaps, a break of a few columns, under half a gap, is no
  // blanking: a line crossing the band loses them where it crosses a
  // vertical grid line (there a candidate must outshine the line, a strip
  // pixel and a half either side), and the runs either side of such a break
  // are judged as one, as long as it is seen in nearly all its columns
  // (kSeenShare: a line crosses a grid line once a division). Dashes a
  // short gap apart are seen in far fewer.
  constexpr int kGridBreakColumns = 3;
  constexpr double kSeenShare = 0.85;
  std::vector<Run> judged;
  for (const Run& r : runs) {
    const int gap =
        judged.empty() ? 0 : chosen[r.first].column - chosen[judged.back().end - 1].column - 1;
    if (wide_gaps && !judged.empty() && chosen[r.first].link != CoarsePath::kRestart &&
        gap <= kGridBreakColumns && gap < 0.5 * usual_gap) {
      judged.back().end = r.end;
    } else {
      judged.push_back(r);
    }
  }
  const int span = chosen.back().column - chosen.front().column + 1;
  std::vector<Chosen> foreign;
  for (const Run& r : judged) {
    const auto length = static_cast<double>(chosen[r.end - 1].column - chosen[r.first].column + 1);
    if (length < std::max<double>(kMinColumns, foreign_length)) continue;
    if (static_cast<double>(r.end - r.first) < kSeenShare * length) continue;
    const double rest_seen = static_cast<double>(chosen.size() - (r.end - r.first));
    if (own && !(rest_seen < kChoppedShare * (span - length))) continue;
    foreign.insert(foreign.end(), chosen.begin() + r.first, chosen.begin() + r.end);
  }
  return foreign;
}

std::vector<Chosen> StrayExcursions(const std::vector<Chosen>& chosen,
                                    const std::vector<std::vector<Node>>& columns,
                                    double jump_rows) {
  const auto row_of = [&](const Chosen& c) { return columns[c.column][c.index].row; };
  // The slope (rows per column) over up to kSlopeColumns at one end of
  // chosen[first, end).
  constexpr int kSlopeColumns = 4;
  const auto end_slope = [&](std::size_t first, std::size_t end, bool at_end) {
    const std::size_t a = at_end ? end - 1 : first;
    std::size_t b = a;
    while (true) {
      if (std::abs(chosen[b].column - chosen[a].column) >= kSlopeColumns) break;
      if (at_end ? b == first : b + 1 == end) break;
      b = at_end ? b - 1 : b + 1;
    }
    const int dc = chosen[a].column - chosen[b].column;
    return dc != 0 ? (row_of(chosen[a]) - row_of(chosen[b])) / dc : 0.0;
  };
  // Pieces between restarts, [first, end) into `chosen`.
  struct Piece {
    std::size_t first = 0, end = 0;
  };
  std::vector<Piece> pieces;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (i == 0 || chosen[i].link == CoarsePath::kRestart) pieces.push_back({i, i});
    pieces.back().end = i + 1;
  }
  // How far the course after a restart lands from where the piece before
  // it pointed, and the reverse, whichever is less (rows).
  const auto miss = [&](const Piece& before, const Piece& after) {
    const Chosen& from = chosen[before.end - 1];
    const Chosen& to = chosen[after.first];
    const int dc = to.column - from.column;
    const double forward =
        std::abs(row_of(to) - (row_of(from) + end_slope(before.first, before.end, true) * dc));
    const double backward =
        std::abs(row_of(from) - (row_of(to) - end_slope(after.first, after.end, false) * dc));
    return std::min(forward, backward);
  };
  // Excursions: runs of pieces joined by explained restarts, [first, end)
  // into `pieces`.
  std::vector<Piece> groups;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    if (k == 0 || miss(pieces[k - 1], pieces[k]) > jump_rows) groups.push_back({k, k});
    groups.back().end = k + 1;
  }
  std::vector<Chosen> stray;
  for (std::size_t g = 1; g + 1 < groups.size(); ++g) {
    // The courses either side agree across it.
    const Piece& before = pieces[groups[g - 1].end - 1];
    const Piece& after = pieces[groups[g + 1].first];
    if (miss(before, after) > jump_rows) continue;
    const std::size_t from = pieces[groups[g].first].first, to = pieces[groups[g].end - 1].end;
    stray.insert(stray.end(), chosen.begin() + from, chosen.begin() + to);
  }
  return stray;
}

// Whether `course` (on the candidates `kept`) runs more than `away_rows`
// from the `suspect` candidates (on `all`) in at least half their columns,
// its row taken between its own candidates either side.
bool RunsElsewhere(const std::vector<Chosen>& course, const std::vector<std::vector<Node>>& kept,
                   const std::vector<Chosen>& suspect, const std::vector<std::vector<Node>>& all,
                   double away_rows) {
  if (course.empty()) return false;
  std::size_t away = 0, next = 0;
  for (const Chosen& s : suspect) {
    while (next < course.size() && course[next].column < s.column) ++next;
    double row = 0.0;
    if (next < course.size() && course[next].column == s.column) {
      row = kept[s.column][course[next].index].row;
    } else if (next > 0 && next < course.size()) {
      const Chosen& a = course[next - 1];
      const Chosen& b = course[next];
      const double f = static_cast<double>(s.column - a.column) / (b.column - a.column);
      row = (1.0 - f) * kept[a.column][a.index].row + f * kept[b.column][b.index].row;
    } else {
      continue;  // beyond the course's ends: no course there to compare
    }
    away += std::abs(row - all[s.column][s.index].row) > away_rows;
  }
  return 2 * away >= suspect.size();
}

}  // namespace impactlab::digitize
