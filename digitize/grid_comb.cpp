#include "digitize/grid_comb.h"

#include <algorithm>
#include <cmath>

#include "digitize/select.h"

namespace impactlab::digitize {

namespace {

// Step of the spacing and phase searched, profile positions: a tooth then
// lies within a quarter position of a line, inside the +-1 it is read over.
constexpr double kSearchStep = 0.5;
// A line's share of a comb's score is at most this many times the comb's
// typical (median) line: a frame or a trace in step adds no more than a
// grid line would.
constexpr double kLineCap = 1.5;

// The most the lifted profile holds within one position of `at`.
double ToothAt(const std::vector<double>& lifted, double at) {
  const int centre = static_cast<int>(std::lround(at));
  double best = 0.0;
  for (int i = centre - 1; i <= centre + 1; ++i) {
    if (i >= 0 && i < static_cast<int>(lifted.size())) best = std::max(best, lifted[i]);
  }
  return best;
}

// A window of teeth scored as its lines' votes, each capped near the
// window's median line (a comb whose lines are mostly unseen scores 0).
double WindowScore(const double* teeth, int n_lines, std::vector<double>& scratch) {
  scratch.assign(teeth, teeth + n_lines);
  const auto middle = scratch.begin() + n_lines / 2;
  const double cap = kLineCap * SelectNth(scratch.begin(), middle, scratch.end());
  double score = 0.0;
  for (int k = 0; k < n_lines; ++k) score += std::min(teeth[k], cap);
  return score;
}

}  // namespace

std::vector<double> AboveFloor(const std::vector<double>& profile, int half) {
  const int size = static_cast<int>(profile.size());
  std::vector<double> lifted(size, 0.0);
  // The window [lo, hi] kept sorted as it slides, where selecting each
  // window's median afresh was 8 % of a photo session's reduce (the lattice
  // floors every direction's rho profile). Where one value enters as another
  // leaves (all but the profile's ends), the entering one takes the leaving
  // one's place and moves along the few that keep it out of order: a
  // vector's insert and erase cost four times as much.
  std::vector<double> sorted;
  sorted.reserve(2 * static_cast<std::size_t>(std::max(half, 0)) + 1);
  int lo = 0, hi = -1;
  for (int i = 0; i < size; ++i) {
    const int hi_to = std::min(size - 1, i + half), lo_to = std::max(0, i - half);
    if (hi < hi_to && lo < lo_to && hi + 1 == hi_to && lo + 1 == lo_to) {
      const double in = profile[++hi], out = profile[lo++];
      double* s = sorted.data();
      const int n = static_cast<int>(sorted.size());
      int k = static_cast<int>(std::lower_bound(s, s + n, out) - s);
      if (in > out) {
        for (; k + 1 < n && s[k + 1] < in; ++k) s[k] = s[k + 1];
      } else {
        for (; k > 0 && s[k - 1] > in; --k) s[k] = s[k - 1];
      }
      s[k] = in;
    }
    for (; hi < hi_to; ++hi) {
      const double in = profile[hi + 1];
      sorted.insert(std::upper_bound(sorted.begin(), sorted.end(), in), in);
    }
    for (; lo < lo_to; ++lo) {
      sorted.erase(std::lower_bound(sorted.begin(), sorted.end(), profile[lo]));
    }
    lifted[i] = std::max(0.0, profile[i] - sorted[sorted.size() / 2]);
  }
  return lifted;
}

std::vector<CombLine> FindComb(const std::vector<double>& profile, int n_lines, double min_spacing,
                               double max_spacing) {
  const double size = static_cast<double>(profile.size());
  if (n_lines < 2 || !(min_spacing >= 2.0) || !(max_spacing >= min_spacing) ||
      size < n_lines * min_spacing) {
    return {};
  }
  const std::vector<double> lifted = AboveFloor(profile, static_cast<int>(min_spacing));
  double best_score = 0.0, best_spacing = 0.0, best_first = 0.0;
  std::vector<double> teeth, scratch;
  for (double spacing = min_spacing; spacing <= max_spacing; spacing += kSearchStep) {
    for (double phase = 0.0; phase < spacing; phase += kSearchStep) {
      teeth.clear();
      for (double at = phase; at <= size - 1.0; at += spacing) teeth.push_back(ToothAt(lifted, at));
      for (int start = 0; start + n_lines <= static_cast<int>(teeth.size()); ++start) {
        const double score = WindowScore(teeth.data() + start, n_lines, scratch);
        if (score > best_score) {
          best_score = score, best_spacing = spacing, best_first = phase + start * spacing;
        }
      }
    }
  }
  std::vector<CombLine> lines;
  if (!(best_score > 0.0)) return lines;
  // Each line at the profile's own peak near its tooth: perspective spaces
  // the lines unevenly, by a few percent across the grid.
  const int reach = std::max(1, static_cast<int>(best_spacing / 6.0));
  for (int k = 0; k < n_lines; ++k) {
    const int tooth = static_cast<int>(std::lround(best_first + k * best_spacing));
    int peak = -1;
    for (int i = std::max(0, tooth - reach); i <= std::min<int>(size - 1, tooth + reach); ++i) {
      if (peak < 0 || lifted[i] > lifted[peak]) peak = i;
    }
    if (peak < 0 || !(lifted[peak] > 0.0)) continue;
    // Sub-position: the parabola through the peak and its neighbours.
    double offset = 0.0;
    if (peak > 0 && peak + 1 < static_cast<int>(size)) {
      const double a = lifted[peak - 1], b = lifted[peak], c = lifted[peak + 1];
      const double curvature = a - 2.0 * b + c;
      if (curvature < 0.0) offset = std::clamp(0.5 * (a - c) / curvature, -0.5, 0.5);
    }
    lines.push_back({peak + offset, lifted[peak]});
  }
  return lines;
}

}  // namespace impactlab::digitize
