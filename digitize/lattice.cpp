#include "digitize/lattice.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <numeric>
#include <vector>

#include <fmt/format.h>

#include "digitize/grid_comb.h"
#include "digitize/line_profile.h"
#include "digitize/select.h"

namespace impactlab::digitize {

float RidgeFloor(const cv::Mat1f& ridge, double floor_sigmas, float* median) {
  // The noise is judged in the middle of the frame, where the screen is: the
  // flat surround of a scanned print would make it look smaller than it is.
  std::vector<float> sample;
  for (int row = ridge.rows / 5; row < ridge.rows * 4 / 5; row += 2) {
    const float* p = ridge.ptr<float>(row);
    for (int col = ridge.cols / 5; col < ridge.cols * 4 / 5; col += 2) sample.push_back(p[col]);
  }
  float centre = 0.0f, sigma = 0.0f;
  if (!sample.empty()) {
    const auto middle = sample.begin() + sample.size() / 2;
    centre = SelectNth(sample.begin(), middle, sample.end());
    for (float& v : sample) v = std::abs(v - centre);
    sigma = 1.4826f * SelectNth(sample.begin(), middle, sample.end());
  }
  if (median) *median = centre;
  return std::max(centre + static_cast<float>(floor_sigmas) * sigma, 0.005f);
}

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

// The Hough accumulator covers normal angles [-45, 135) degrees, so that
// neither family (normals near 0 and near 90 degrees for rotations within
// +-45) wraps around its ends.
constexpr double kThetaFirstDeg = -45.0;
constexpr double kThetaStepDeg = 0.5;
constexpr int kThetaBins = 360;
// How far a family's lines may turn from its dominant direction (perspective).
constexpr double kFamilySpreadDeg = 20.0;
// How far the two families' dominant directions may be from perpendicular.
constexpr double kFamilyAngleDeg = 10.0;
// A grid line must lie within this fraction of the local spacing of where the
// progression puts it.
constexpr double kMatchTolerance = 0.15;
// ... and run within this angle of the direction its neighbours' course puts
// it at. A family's lines turn smoothly from one to the next (perspective);
// a trace's slope or a scratch that happens to cross the transversal in step
// does not, and without this check such junk fills in for faint grid lines
// (a lattice of half the spacing then outscores the true one).
constexpr double kDirectionToleranceDeg = 2.0;
// ... and the family's directions turn by at most this much per line. A
// grid seen at 25 degrees of tilt turns its lines by at most 0.7 degree per
// division, a phone held at a steep angle by 1.4; the lines a bright speck
// or blob casts in the Hough votes (one through it in every direction) fan
// out by several degrees per step, and a run of them in step along the
// transversal took the place of a faint grid's family (randomised seed
// 1026's run 0.713: 6.6 degrees per line).
constexpr double kMaxTurnPerLineDeg = 2.5;
// How far a family's perspective (its progression's c, per line) may be from
// what the other family's turn (radians per line) says it is. A homography
// that makes one family's lines converge spaces the other's unevenly, by
// the same parameter: c of the horizontal lines equals the turn q of the
// vertical ones, and c of the vertical lines -q of the horizontal ones.
// Measured on 81 right lattices of randomised photos: within 0.0036; on
// wrong ones, bent through a print's frame or traces in step: 0.025-0.26.
constexpr double kPerspectiveTolerance = 0.015;
// A screen's divisions are square: seen tilted (up to 25 degrees) and in
// perspective, one family's spacing lies within these factors of the other's.
constexpr double kMinSpacingRatio = 0.7, kMaxSpacingRatio = 1.45;
// A grid line's votes count at most this many times the lattice's typical
// line's (the ridge points' own cap, applied to whole lines).
constexpr double kLineVoteCap = 1.5;

struct HoughLine {
  double theta_rad = 0.0;  // normal direction
  double rho_px = 0.0;     // x cos + y sin = rho, coordinates from the working copy's centre
  double votes = 0.0;
};

struct RidgePoint {
  float x = 0.0f, y = 0.0f;  // from the working copy's centre
  float weight = 0.0f;       // its height above the noise, capped near a grid line's
};

// Thin bright structure: ridge pixels `floor_sigmas` above the noise, thinned
// to those that are a local maximum across x or across y. Each votes with its
// height, so that faint lines in heavy noise still add up, capped at about a
// grid line's height, so that the bright traces do not outvote the grid.
std::vector<RidgePoint> RidgePoints(const cv::Mat1f& ridge, double floor_sigmas,
                                    float* unit_weight) {
  float median = 0.0f;
  const float threshold = RidgeFloor(ridge, floor_sigmas, &median);

  const float cx = 0.5f * (ridge.cols - 1), cy = 0.5f * (ridge.rows - 1);
  std::vector<RidgePoint> points;
  for (int row = 2; row + 2 < ridge.rows; ++row) {
    const float* above = ridge.ptr<float>(row - 1);
    const float* p = ridge.ptr<float>(row);
    const float* below = ridge.ptr<float>(row + 1);
    for (int col = 2; col + 2 < ridge.cols; ++col) {
      const float v = p[col];
      if (v <= threshold) continue;
      const bool across_x = v >= p[col - 1] && v >= p[col + 1];
      const bool across_y = v >= above[col] && v >= below[col];
      if (across_x || across_y) points.push_back({col - cx, row - cy, v - median});
    }
  }
  if (points.empty()) return points;
  std::vector<float> weights;
  for (const RidgePoint& p : points) weights.push_back(p.weight);
  const auto mid = weights.begin() + weights.size() / 2;
  const float cap = 1.5f * SelectNth(weights.begin(), mid, weights.end());
  for (RidgePoint& p : points) p.weight = std::min(p.weight, cap);
  *unit_weight = *mid;
  return points;
}

class Accumulator {
 public:
  Accumulator(const std::vector<RidgePoint>& points, cv::Size size, float unit_weight)
      : rho_offset_(static_cast<int>(std::ceil(0.5 * std::hypot(size.width, size.height))) + 1),
        rho_bins_(2 * rho_offset_ + 1),
        unit_(unit_weight),
        votes_(kThetaBins, rho_bins_, 0.0f),
        voted_(kThetaBins, false) {
    for (const RidgePoint& p : points) {
      xs_.push_back(p.x), ys_.push_back(p.y), weights_.push_back(p.weight);
    }
  }

  // Holds the votes in the directions (bins) where `fill` is set, every
  // `stride`th direction of those, and no others. A direction voted in by an
  // earlier, coarser pass keeps its votes: they would come out the same.
  void Hold(const std::vector<bool>& fill, int stride) {
    std::vector<int> bins;
    for (int t = 0; t < kThetaBins; ++t) {
      const bool wanted = fill[t] && t % stride == 0;
      if (wanted && !voted_[t]) bins.push_back(t);
      if (!wanted && voted_[t]) votes_.row(t).setTo(0.0f);
      voted_[t] = wanted;
    }
    // Several directions at a time: consecutive points along a line vote in
    // the same cell, and each addition would wait for the one before.
    constexpr int kTogether = 8;
    std::size_t i = 0;
    for (; i + kTogether <= bins.size(); i += kTogether) VoteIn<kTogether>(&bins[i]);
    for (; i < bins.size(); ++i) VoteIn<1>(&bins[i]);
  }

  // How many ridge points lie along each rho in direction t and its two
  // neighbours, whatever their height: a faint line's points count as much
  // as a frame's, and it shows by its length.
  std::vector<double> CountProfile(int t) const {
    std::vector<double> profile(rho_bins_, 0.0);
    const float offset = rho_offset_ + 0.5f;
    for (int tt = std::max(0, t - 1); tt <= std::min(kThetaBins - 1, t + 1); ++tt) {
      const float c = static_cast<float>(std::cos(Theta(tt)));
      const float s = static_cast<float>(std::sin(Theta(tt)));
      for (std::size_t i = 0; i < xs_.size(); ++i) {
        profile[static_cast<int>(xs_[i] * c + ys_[i] * s + offset)] += 1.0;
      }
    }
    return profile;
  }
  int rho_offset() const { return rho_offset_; }
  float unit() const { return unit_; }

  static double Theta(double bin) { return (kThetaFirstDeg + bin * kThetaStepDeg) * kDegree; }
  static int Bin(double theta_deg) {
    return static_cast<int>(std::lround((theta_deg - kThetaFirstDeg) / kThetaStepDeg));
  }

  // How much direction t's votes concentrate in a few lines: the sum of its
  // strongest cells, each smoothed along rho first so that the uneven
  // projection of the pixel grid (worst at 45 degrees, where bins alternately
  // catch one and two pixel diagonals) does not count, and taken above the
  // local floor of its neighbours along rho. Noise votes in every cell, in
  // proportion to the photo's length across that direction, which is
  // longest near the diagonals: in a noisy photo (grain, a coarse JPEG, a
  // panel's texture) the bare sums grew toward the ends of the range
  // searched and outweighed a faint grid (randomised seeds 1003's and 1008's
  // runs 0.713 took directions 24 and 32 degrees off the grid's).
  double Energy(int t) const {
    constexpr int kLines = 24;
    constexpr int kFloorHalfWidth = 8;  // bins: several times a line's width
    std::vector<double> smoothed(rho_bins_);
    const float* row = votes_.ptr<float>(t);
    smoothed[0] = smoothed[rho_bins_ - 1] = 0.0;
    for (int r = 1; r + 1 < rho_bins_; ++r) {
      smoothed[r] = 0.25 * row[r - 1] + 0.5 * row[r] + 0.25 * row[r + 1];
    }
    std::vector<double> lifted = AboveFloor(smoothed, kFloorHalfWidth);
    std::nth_element(lifted.begin(), lifted.begin() + kLines, lifted.end(), std::greater<double>());
    double sum = 0.0;
    for (int i = 0; i < kLines; ++i) sum += lifted[i];
    return sum;
  }

  // The direction (bin) in [lo, hi] whose votes concentrate most, smoothed
  // over neighbouring directions.
  int DominantBin(int lo, int hi) const {
    std::vector<double> energy(kThetaBins, 0.0);
    for (int t = std::max(0, lo - 1); t <= std::min(kThetaBins - 1, hi + 1); ++t) {
      energy[t] = Energy(t);
    }
    int best = lo;
    double best_energy = -1.0;
    for (int t = lo; t <= hi; ++t) {
      const double e =
          energy[std::max(0, t - 1)] + 2.0 * energy[t] + energy[std::min(kThetaBins - 1, t + 1)];
      if (e > best_energy) best_energy = e, best = t;
    }
    return best;
  }

  // Local maxima in directions [lo, hi], strongest first, at most `limit`.
  std::vector<HoughLine> Peaks(int lo, int hi, double min_share, std::size_t limit) const {
    float strongest = 0.0f;
    for (int t = lo; t <= hi; ++t) {
      const float* row = votes_.ptr<float>(t);
      strongest = std::max(strongest, *std::max_element(row, row + rho_bins_));
    }
    // At least the votes of a short stretch of line.
    const float floor_votes = std::max(8.0f * unit_, static_cast<float>(min_share * strongest));
    constexpr int kRhoReach = 3;  // and two directions either side
    std::vector<HoughLine> peaks;
    for (int t = lo; t <= hi; ++t) {
      const float* row = votes_.ptr<float>(t);
      for (int r = kRhoReach; r + kRhoReach < rho_bins_; ++r) {
        const float v = row[r];
        if (v < floor_votes) continue;
        bool is_max = true;
        // Its own direction first: most cells fail there, next to it in memory.
        for (const int dt : {0, -1, 1, -2, 2}) {
          if (!is_max) break;
          const int tt = t + dt;
          if (tt < 0 || tt >= kThetaBins) continue;
          const float* other = votes_.ptr<float>(tt);
          for (int dr = -kRhoReach; dr <= kRhoReach; ++dr) {
            if (dt == 0 && dr == 0) continue;
            // Ties go to the first in scan order.
            const float w = other[r + dr];
            if (w > v || (w == v && (dt < 0 || (dt == 0 && dr < 0)))) {
              is_max = false;
              break;
            }
          }
        }
        if (!is_max) continue;
        // Sub-bin position: the vote-weighted mean of the neighbourhood.
        double sum = 0.0, theta_sum = 0.0, rho_sum = 0.0;
        for (int dt = -1; dt <= 1; ++dt) {
          const int tt = std::clamp(t + dt, 0, kThetaBins - 1);
          for (int dr = -1; dr <= 1; ++dr) {
            const double w = votes_(tt, r + dr);
            sum += w, theta_sum += w * (t + dt), rho_sum += w * (r + dr);
          }
        }
        peaks.push_back(
            {Theta(theta_sum / sum), rho_sum / sum - rho_offset_, static_cast<double>(v)});
      }
    }
    std::sort(peaks.begin(), peaks.end(),
              [](const HoughLine& a, const HoughLine& b) { return a.votes > b.votes; });
    if (peaks.size() > limit) peaks.resize(limit);
    return peaks;
  }

 private:
  // Every point's vote in directions bins[0 .. kCount), a block of points
  // at a time: their cells first, which has no dependencies and vectorises,
  // then the additions, in the points' order.
  template <int kCount>
  void VoteIn(const int* bins) {
    std::array<float, kCount> c, s;
    std::array<float*, kCount> rows;
    for (int k = 0; k < kCount; ++k) {
      c[k] = static_cast<float>(std::cos(Theta(bins[k])));
      s[k] = static_cast<float>(std::sin(Theta(bins[k])));
      rows[k] = votes_.ptr<float>(bins[k]);
    }
    const float offset = rho_offset_ + 0.5f;
    constexpr int kBlock = 64;
    std::array<std::array<int, kBlock>, kCount> cells;
    const int n = static_cast<int>(xs_.size());
    for (int from = 0; from < n; from += kBlock) {
      const int m = std::min(kBlock, n - from);
      const float* x = xs_.data() + from;
      const float* y = ys_.data() + from;
      const float* w = weights_.data() + from;
      for (int k = 0; k < kCount; ++k) {
        for (int i = 0; i < m; ++i) {
          cells[k][i] = static_cast<int>(x[i] * c[k] + y[i] * s[k] + offset);
        }
      }
      for (int i = 0; i < m; ++i) {
        for (int k = 0; k < kCount; ++k) rows[k][cells[k][i]] += w[i];
      }
    }
  }

  int rho_offset_;
  int rho_bins_;
  float unit_;  // a typical vote
  cv::Mat1f votes_;
  std::vector<bool> voted_;               // per direction: holds its votes
  std::vector<float> xs_, ys_, weights_;  // the ridge points, each quantity apart
};

// u(n) = (a n + b) / (c n + 1): equally spaced lines seen in perspective.
struct Progression1d {
  double a = 1.0, b = 0.0, c = 0.0;
  double operator()(double n) const { return (a * n + b) / (c * n + 1.0); }
  double Spacing(double n) const { return std::abs((*this)(n + 0.5) - (*this)(n - 0.5)); }
};

// Least squares of a n + b - c n u = u; affine (c = 0) below three points.
Progression1d FitProgression(const std::vector<std::pair<int, double>>& points) {
  Progression1d model;
  const auto& [n0, u0] = points.front();
  const auto& [n1, u1] = points.back();
  model.a = (u1 - u0) / (n1 - n0);
  model.b = u0 - model.a * n0;
  if (points.size() < 3) return model;
  // Normal equations on the stack: this runs thousands of times per photo.
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0.0, 0.0, 0.0);
  for (const auto& [n, u] : points) {
    const cv::Vec3d row(n, 1.0, -n * u);
    normal += row * row.t();
    rhs += u * row;
  }
  cv::Vec3d x;
  if (!cv::solve(normal, rhs, x, cv::DECOMP_LU)) return model;
  model.a = x[0], model.b = x[1], model.c = x[2];
  return model;
}

struct FamilyMatch {
  std::vector<std::pair<int, int>> lines;  // (index n, candidate), n increasing
  double score = 0.0;                      // votes of the lines in the best window
  int window_start = 0;                    // first index of the grid's n_lines lines
  bool window_certain = false;             // enough lines seen to place the window
};

// The lines' directions along the family, theta(n) = p + q n: near enough
// for perspective, whose pencil of lines turns smoothly with n.
struct DirectionCourse {
  double p = 0.0, q = 0.0;
  double operator()(double n) const { return p + q * n; }
};

DirectionCourse FitCourse(const std::vector<std::pair<int, double>>& directions) {
  double sn = 0.0, st = 0.0, snn = 0.0, snt = 0.0;
  for (const auto& [n, t] : directions) sn += n, st += t, snn += n * n, snt += n * t;
  const double count = static_cast<double>(directions.size());
  const double det = count * snn - sn * sn;
  DirectionCourse course;
  course.q = det > 0.0 ? (count * snt - sn * st) / det : 0.0;
  course.p = (st - course.q * sn) / count;
  return course;
}

// A family's candidate lines: position along the transversal, direction
// (radians, from the family's) and votes, and their order along the
// transversal, so that a line is looked for only among those near where a
// progression puts it (Grow looks thousands of times per photo).
struct Candidates {
  std::vector<double> u, theta, votes;
  std::vector<int> by_u;           // indices, in order of u
  std::vector<double> u_in_order;  // u[by_u[i]]

  // The candidate with the most votes (the first of equals) within
  // `tolerance` of `predicted` and `direction_tolerance` of `direction`; -1
  // when none.
  int Find(double predicted, double tolerance, double direction, double direction_tolerance) const {
    std::size_t from = 0, to = u.size();
    // Bounds a little wide of the exact test below, which decides.
    const double margin = 1e-9 * (1.0 + std::abs(predicted) + tolerance);
    const double lo = predicted - tolerance - margin, hi = predicted + tolerance + margin;
    if (lo <= hi) {
      from = std::lower_bound(u_in_order.begin(), u_in_order.end(), lo) - u_in_order.begin();
      to = std::upper_bound(u_in_order.begin(), u_in_order.end(), hi) - u_in_order.begin();
    }
    int best = -1;
    for (std::size_t k = from; k < to; ++k) {
      const int i = by_u[k];
      if (std::abs(u[i] - predicted) <= tolerance &&
          std::abs(theta[i] - direction) <= direction_tolerance &&
          (best < 0 || votes[i] > votes[best] || (votes[i] == votes[best] && i < best))) {
        best = i;
      }
    }
    return best;
  }
};

// Grows a progression from candidates j (index 0) and k (index m) outward,
// one index at a time, refitting as it goes.
FamilyMatch Grow(const Candidates& candidates, int j, int k, int m, int n_lines,
                 std::optional<double> expected_c) {
  const std::vector<double>& u = candidates.u;
  const std::vector<double>& theta = candidates.theta;
  const std::vector<double>& votes = candidates.votes;
  std::vector<std::pair<int, double>> points = {{0, u[j]}, {m, u[k]}};
  std::vector<std::pair<int, double>> directions = {{0, theta[j]}, {m, theta[k]}};
  std::vector<std::pair<int, int>> matched = {{0, j}, {m, k}};
  const double direction_tolerance = kDirectionToleranceDeg * kDegree;
  DirectionCourse course = FitCourse(directions);
  auto find = [&](const Progression1d& model, int n) {
    return candidates.Find(model(n), kMatchTolerance * model.Spacing(n), course(n),
                           direction_tolerance);
  };
  auto add = [&](int n, int candidate) {
    points.emplace_back(n, u[candidate]);
    directions.emplace_back(n, theta[candidate]);
    matched.emplace_back(n, candidate);
  };
  const double max_turn = kMaxTurnPerLineDeg * kDegree;
  auto turns_slowly = [&](int n, int candidate) {
    std::vector<std::pair<int, double>> with = directions;
    with.emplace_back(n, theta[candidate]);
    if (!(std::abs(FitCourse(with).q) <= max_turn)) return false;
    // When the other family's turn is known, the perspective must match it.
    if (!expected_c) return true;
    std::vector<std::pair<int, double>> at = points;
    at.emplace_back(n, u[candidate]);
    return at.size() < 3 || std::abs(FitProgression(at).c - *expected_c) <= kPerspectiveTolerance;
  };
  Progression1d model = FitProgression(points);
  for (int n = 1; n < m; ++n) {
    if (const int c = find(model, n); c >= 0 && turns_slowly(n, c)) add(n, c);
  }
  model = FitProgression(points);
  course = FitCourse(directions);
  // Outward one index at a time on either side, for as long as the lines
  // matched could still be one grid's (n_lines, and one either side that the
  // window drops). Unseen indices do not stop it: faint lines (glare, a
  // fading print) leave gaps, and the lines beyond them are the grid's too.
  int lo = 0, hi = m, seen_lo = 0, seen_hi = m;
  const int max_span = n_lines + 2;
  bool open[2] = {true, true};  // upward, downward
  while (open[0] || open[1]) {
    for (int side = 0; side < 2; ++side) {
      if (!open[side]) continue;
      const bool upward = side == 0;
      const int n = upward ? ++hi : --lo;
      // Perspective must keep the lines in order and the spacing finite.
      if ((upward ? n - seen_lo : seen_hi - n) + 1 > max_span || !(model.Spacing(n) > 0.0) ||
          std::abs(model.c * n) > 0.8) {
        open[side] = false;
        continue;
      }
      if (const int c = find(model, n); c >= 0 && turns_slowly(n, c)) {
        add(n, c);
        model = FitProgression(points);
        course = FitCourse(directions);
        (upward ? seen_hi : seen_lo) = n;
      }
    }
  }
  std::sort(matched.begin(), matched.end());
  // Indices start at 0; the best window of n_lines consecutive indices.
  const int first = matched.front().first;
  for (auto& [n, c] : matched) n -= first;
  const int span = matched.back().first + 1;
  FamilyMatch result;
  result.lines = matched;
  // A window's score: its lines' votes, each at most kLineVoteCap times the
  // window's typical line (the median over its indices, an unseen line
  // counting 0). Otherwise one long bright line in step by a stretch of the
  // tolerance (the bezel's lip 0.3 division beyond the grid, a trace's flat
  // stretch) outvotes the grid lines a wrong progression gives up for it.
  std::vector<double> window_votes(n_lines);
  for (int start = std::min(0, span - n_lines); start <= std::max(0, span - n_lines); ++start) {
    std::fill(window_votes.begin(), window_votes.end(), 0.0);
    for (const auto& [n, c] : matched) {
      if (n >= start && n < start + n_lines) window_votes[n - start] = votes[c];
    }
    std::vector<double> sorted = window_votes;
    const auto middle = sorted.begin() + n_lines / 2;
    std::nth_element(sorted.begin(), middle, sorted.end());
    const double cap = kLineVoteCap * *middle;
    double score = 0.0;
    for (const double v : window_votes) score += std::min(v, cap);
    if (score > result.score) result.score = score, result.window_start = start;
  }
  result.window_certain = span >= n_lines;
  return result;
}

// Which candidate lines are the grid's, and their indices. Runs are grown
// from pairs of the 24 strongest candidates, and of those from `extra_anchors`
// on (a comb's lines, appended after the peaks: faint, but in step).
std::optional<FamilyMatch> MatchFamily(const std::vector<HoughLine>& lines, double theta_rad,
                                       int n_lines, double min_spacing_px, double max_spacing_px,
                                       std::optional<double> expected_c = std::nullopt,
                                       std::size_t extra_anchors = 0) {
  // Positions along the transversal through the centre, across the family.
  Candidates candidates;
  std::vector<double>& u = candidates.u;
  for (const HoughLine& line : lines) {
    u.push_back(line.rho_px / std::cos(line.theta_rad - theta_rad));
    candidates.theta.push_back(line.theta_rad - theta_rad);
    candidates.votes.push_back(line.votes);
  }
  candidates.by_u.resize(u.size());
  std::iota(candidates.by_u.begin(), candidates.by_u.end(), 0);
  std::stable_sort(candidates.by_u.begin(), candidates.by_u.end(),
                   [&](int a, int b) { return u[a] < u[b]; });
  for (const int i : candidates.by_u) candidates.u_in_order.push_back(u[i]);
  std::optional<FamilyMatch> best;
  std::vector<int> anchors(std::min<std::size_t>(lines.size(), 24));
  std::iota(anchors.begin(), anchors.end(), 0);
  for (std::size_t i = std::max(extra_anchors, anchors.size());
       extra_anchors > 0 && i < lines.size(); ++i) {
    anchors.push_back(static_cast<int>(i));
  }
  for (const int j : anchors) {
    for (const int k : anchors) {
      if (u[k] <= u[j]) continue;
      for (int m = 1; m <= 3; ++m) {
        const double spacing = (u[k] - u[j]) / m;
        if (spacing < min_spacing_px || spacing > max_spacing_px) continue;
        if (std::abs(candidates.theta[k] - candidates.theta[j]) >
            m * kMaxTurnPerLineDeg * kDegree) {
          continue;
        }
        FamilyMatch match = Grow(candidates, j, k, m, n_lines, expected_c);
        if (!best || match.score > best->score) best = std::move(match);
      }
    }
  }
  return best;
}

// A family's perspective as its matched lines show it: the progression's c
// (the spacing's relative change per line is about -2c) and the course's
// turn q, radians per line.
struct Perspective {
  double c = 0.0, q = 0.0;
};
Perspective PerspectiveOf(const std::vector<HoughLine>& lines, const FamilyMatch& match,
                          double theta_rad) {
  std::vector<std::pair<int, double>> points, directions;
  for (const auto& [n, c] : match.lines) {
    points.emplace_back(n, lines[c].rho_px / std::cos(lines[c].theta_rad - theta_rad));
    directions.emplace_back(n, lines[c].theta_rad - theta_rad);
  }
  return {FitProgression(points).c, FitCourse(directions).q};
}

// A family's lines l(n) = A + n B in normalised homogeneous coordinates, fitted
// to the matched Hough lines (each line's cross product with the model is 0).
struct Pencil {
  cv::Vec3d a, b;
  cv::Vec3d operator()(double n) const { return a + n * b; }
};

cv::Vec3d HomogeneousLine(const HoughLine& line, double scale) {
  return {std::cos(line.theta_rad), std::sin(line.theta_rad), -line.rho_px / scale};
}

Pencil FitPencil(const std::vector<HoughLine>& lines, const FamilyMatch& match, double scale) {
  cv::Mat1d design(3 * static_cast<int>(match.lines.size()), 6);
  int row = 0;
  for (const auto& [n, c] : match.lines) {
    const cv::Vec3d l = HomogeneousLine(lines[c], scale);
    const cv::Matx33d cross(0.0, -l[2], l[1], l[2], 0.0, -l[0], -l[1], l[0], 0.0);
    for (int i = 0; i < 3; ++i, ++row) {
      for (int k = 0; k < 3; ++k) {
        design(row, k) = cross(i, k);
        design(row, 3 + k) = n * cross(i, k);
      }
    }
  }
  cv::Mat1d solution;
  cv::SVD::solveZ(design, solution);
  return {{solution(0), solution(1), solution(2)}, {solution(3), solution(4), solution(5)}};
}

cv::Point2d Intersect(const cv::Vec3d& l1, const cv::Vec3d& l2) {
  const cv::Vec3d p = l1.cross(l2);
  return {p[0] / p[2], p[1] / p[2]};
}

// Mean ridge response along the line between two points (normalised
// coordinates), the brightest of a 3 x 3 neighbourhood at each step.
double LineEvidence(const cv::Mat1f& ridge, cv::Point2d from, cv::Point2d to, double scale) {
  const cv::Point2d centre(0.5 * (ridge.cols - 1), 0.5 * (ridge.rows - 1));
  constexpr int kSteps = 48;
  double sum = 0.0;
  int count = 0;
  for (int i = 1; i < kSteps; ++i) {
    const cv::Point2d p = centre + (from + (to - from) * (static_cast<double>(i) / kSteps)) * scale;
    const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y));
    if (x < 1 || y < 1 || x + 1 >= ridge.cols || y + 1 >= ridge.rows) continue;
    float best = 0.0f;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) best = std::max(best, ridge(y + dy, x + dx));
    }
    sum += best;
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

// Places a family's window of n_lines indices when fewer lines were seen:
// the window whose unseen lines stand out most along their predicted course
// (between the other family's outermost seen lines). A line stands out by
// the ridge on its course less that a quarter division either side: the
// ridge alone is as high in a noisy surround (a phone's front panel, the
// bezel) as on a faint grid line, and would pull the window off the screen.
void PlaceWindow(FamilyMatch& match, const Pencil& pencil, const Pencil& other, int other_lo,
                 int other_hi, int n_lines, const cv::Mat1f& ridge, double scale) {
  if (match.window_certain) return;
  const int span = match.lines.back().first + 1;
  auto along = [&](double n) {
    const cv::Vec3d line = pencil(n);
    return LineEvidence(ridge, Intersect(line, other(other_lo)), Intersect(line, other(other_hi)),
                        scale);
  };
  double best = -std::numeric_limits<double>::infinity();
  for (int start = span - n_lines; start <= 0; ++start) {
    double evidence = 0.0;
    for (int n = start; n < start + n_lines; ++n) {
      if (n >= 0 && n < span) continue;
      evidence += along(n) - 0.5 * (along(n - 0.25) + along(n + 0.25));
    }
    if (evidence > best) best = evidence, match.window_start = start;
  }
}

}  // namespace

cv::Matx33d FitHomography(const std::vector<cv::Point2d>& from,
                          const std::vector<cv::Point2d>& to) {
  CV_Assert(from.size() == to.size() && from.size() >= 4);
  auto normaliser = [](const std::vector<cv::Point2d>& points) {
    cv::Point2d mean(0.0, 0.0);
    for (const cv::Point2d& p : points) mean += p;
    mean *= 1.0 / points.size();
    double spread = 0.0;
    for (const cv::Point2d& p : points) spread += cv::norm(p - mean);
    const double s = std::sqrt(2.0) * points.size() / std::max(spread, 1e-12);
    return cv::Matx33d(s, 0.0, -s * mean.x, 0.0, s, -s * mean.y, 0.0, 0.0, 1.0);
  };
  const cv::Matx33d t_from = normaliser(from), t_to = normaliser(to);
  cv::Mat1d design(2 * static_cast<int>(from.size()), 9);
  for (std::size_t i = 0; i < from.size(); ++i) {
    const cv::Vec3d p = t_from * cv::Vec3d(from[i].x, from[i].y, 1.0);
    const cv::Vec3d q = t_to * cv::Vec3d(to[i].x, to[i].y, 1.0);
    const double rows[2][9] = {{-p[0], -p[1], -1.0, 0.0, 0.0, 0.0, q[0] * p[0], q[0] * p[1], q[0]},
                               {0.0, 0.0, 0.0, -p[0], -p[1], -1.0, q[1] * p[0], q[1] * p[1], q[1]}};
    for (int r = 0; r < 2; ++r) {
      for (int k = 0; k < 9; ++k) design(2 * static_cast<int>(i) + r, k) = rows[r][k];
    }
  }
  cv::Mat1d h;
  cv::SVD::solveZ(design, h);
  const cv::Matx33d normalised(h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8));
  cv::Matx33d result = t_to.inv() * normalised * t_from;
  return result * (1.0 / result(2, 2));
}

std::optional<Lattice> FindLattice(const PreparedPhoto& photo, std::array<int, 2> divisions,
                                   double max_rotation_deg, std::string* why,
                                   double ridge_floor_sigmas) {
  const cv::Mat1f& ridge = photo.ridge;
  float unit_weight = 0.0f;
  const std::vector<RidgePoint> points = RidgePoints(ridge, ridge_floor_sigmas, &unit_weight);
  if (points.size() < 50) {
    *why = "no thin lines in the photo";
    return std::nullopt;
  }
  // The two families: normals near 0 degrees (vertical lines) and near 90,
  // their directions first found in every fourth direction (2 degrees apart),
  // then the lines in all directions near them.
  const double reach_deg = std::min(44.0, max_rotation_deg + 15.0);
  const int family_lo[2] = {Accumulator::Bin(-reach_deg), Accumulator::Bin(90.0 - reach_deg)};
  const int family_hi[2] = {Accumulator::Bin(reach_deg), Accumulator::Bin(90.0 + reach_deg)};
  constexpr int kCoarse = 4;
  std::vector<bool> fill(kThetaBins, false);
  for (int f = 0; f < 2; ++f) {
    for (int t = family_lo[f]; t <= family_hi[f]; ++t) fill[t] = t % kCoarse == 0;
  }
  // The fine pass reuses the coarse pass's directions: a direction's votes
  // are the same whichever pass casts them.
  Accumulator accumulator(points, ridge.size(), unit_weight);
  accumulator.Hold(fill, kCoarse);
  // The two directions are taken together, as the pair whose votes
  // concentrate most that is within kFamilyAngleDeg of a right angle: a
  // screen's lines are perpendicular, and the photo's rotation turns both
  // families alike (perspective up to 25 degrees of tilt bends the angle
  // between them by at most 3.9 degrees, a phone's by 4.4). Apart, a family
  // whose grid lines are faint took the direction of a hair or a scratch.
  std::vector<double> energy[2];
  int first[2];
  for (int f = 0; f < 2; ++f) {
    first[f] = (family_lo[f] + kCoarse - 1) / kCoarse * kCoarse;
    for (int t = first[f]; t <= family_hi[f]; t += kCoarse) {
      energy[f].push_back(accumulator.Energy(t));
    }
  }
  int dominant[2] = {first[0], first[1]};
  double best_energy = -1.0;
  for (std::size_t i = 0; i < energy[0].size(); ++i) {
    for (std::size_t j = 0; j < energy[1].size(); ++j) {
      const int t0 = first[0] + kCoarse * static_cast<int>(i);
      const int t1 = first[1] + kCoarse * static_cast<int>(j);
      if (std::abs((t1 - t0) * kThetaStepDeg - 90.0) > kFamilyAngleDeg) continue;
      if (energy[0][i] + energy[1][j] > best_energy) {
        best_energy = energy[0][i] + energy[1][j], dominant[0] = t0, dominant[1] = t1;
      }
    }
  }
  const int spread = static_cast<int>(kFamilySpreadDeg / kThetaStepDeg);
  std::fill(fill.begin(), fill.end(), false);
  for (int f = 0; f < 2; ++f) {
    for (int t = std::max(0, dominant[f] - spread - kCoarse);
         t <= std::min(kThetaBins - 1, dominant[f] + spread + kCoarse); ++t) {
      fill[t] = true;
    }
  }
  accumulator.Hold(fill, 1);
  for (int f = 0; f < 2; ++f) {
    dominant[f] = accumulator.DominantBin(std::max(0, dominant[f] - kCoarse),
                                          std::min(kThetaBins - 1, dominant[f] + kCoarse));
  }
  const double size = std::max(ridge.cols, ridge.rows);
  const double scale = 0.5 * size;  // normalised coordinates: centred, divided by this
  std::vector<HoughLine> lines[2];
  std::optional<FamilyMatch> matches[2];
  Pencil pencils[2];
  const char* family_names[2] = {"vertical", "horizontal"};
  // The grid spans at least a fifth of the photo and at most all of it.
  auto min_spacing = [&](int f) { return 0.2 * size / divisions[f] * (f == 0 ? 1.0 : 0.75); };
  auto max_spacing = [&](int f) { return 1.1 * size / divisions[f]; };
  auto needed = [&](int f) { return std::max(3, (divisions[f] + 2) / 2); };
  auto enough = [&](const std::optional<FamilyMatch>& match, int f) {
    return match && static_cast<int>(match->lines.size()) >= needed(f);
  };
  // A grid too faint for its lines to be peaks one by one (the photo's
  // brightest lines set the floor) is looked for as a whole: the comb of
  // evenly spaced lines the family's direction holds most of, its lines
  // added to the family's candidates from comb_from[f] on (once).
  std::size_t comb_from[2] = {0, 0};
  auto add_comb = [&](int f, double lo_spacing, double hi_spacing) {
    if (comb_from[f] > 0) return;
    comb_from[f] = lines[f].size();
    const double theta = Accumulator::Theta(dominant[f]);
    for (const CombLine& line : FindComb(accumulator.CountProfile(dominant[f]), divisions[f] + 1,
                                         lo_spacing, hi_spacing)) {
      lines[f].push_back(
          {theta, line.rho - accumulator.rho_offset(), line.votes * accumulator.unit()});
    }
  };
  // The last look, where the peaks hold too few of a faint grid's lines in
  // step or two families that are not one view (randomised seed 2015's
  // calibration: a grid at 1.3 % of a trace's brightness, lines 0.4
  // px wide under glare; 3 of its 11 vertical lines among the peaks, every
  // one of them in its family's comb): each family is its comb alone, its
  // n + 1 evenly spaced lines parallel at the family's dominant direction,
  // none missing. The family whose comb is wider spaced is held (a comb at
  // half a faint grid's spacing catches each of its lines too) and the
  // other's is sought within the spacings a square division allows. The
  // lattice is good to a few pixels and a division: its lines' fit and the
  // checks after it decide, as for any other. False when either comb lacks
  // a line.
  auto combs_alone = [&]() {
    std::vector<double> profile[2];
    std::vector<CombLine> comb[2];
    for (int f = 0; f < 2; ++f) {
      profile[f] = accumulator.CountProfile(dominant[f]);
      comb[f] = FindComb(profile[f], divisions[f] + 1, min_spacing(f), max_spacing(f));
      if (static_cast<int>(comb[f].size()) != divisions[f] + 1) return false;
    }
    const auto spacing = [&](int f) {
      return (comb[f].back().rho - comb[f].front().rho) / divisions[f];
    };
    const int held = spacing(0) >= spacing(1) ? 0 : 1, other = 1 - held;
    const double held_spacing = spacing(held);
    if (!(spacing(other) >= kMinSpacingRatio * held_spacing &&
          spacing(other) <= kMaxSpacingRatio * held_spacing)) {
      comb[other] = FindComb(profile[other], divisions[other] + 1,
                             std::max(min_spacing(other), kMinSpacingRatio * held_spacing),
                             std::min(max_spacing(other), kMaxSpacingRatio * held_spacing));
      if (static_cast<int>(comb[other].size()) != divisions[other] + 1) return false;
    }
    for (int f = 0; f < 2; ++f) {
      const double theta = Accumulator::Theta(dominant[f]);
      lines[f].clear();
      FamilyMatch match;
      for (const CombLine& line : comb[f]) {
        match.lines.emplace_back(static_cast<int>(lines[f].size()),
                                 static_cast<int>(lines[f].size()));
        lines[f].push_back(
            {theta, line.rho - accumulator.rho_offset(), line.votes * accumulator.unit()});
      }
      match.window_certain = true;
      matches[f] = std::move(match);
    }
    return true;
  };
  bool from_combs = false;
  for (int f = 0; f < 2; ++f) {
    const int lo = std::max(0, dominant[f] - spread);
    const int hi = std::min(kThetaBins - 1, dominant[f] + spread);
    lines[f] = accumulator.Peaks(lo, hi, 0.15, 48);
    const int n_lines = divisions[f] + 1;
    const double theta = Accumulator::Theta(dominant[f]);
    matches[f] = MatchFamily(lines[f], theta, n_lines, min_spacing(f), max_spacing(f));
    if (!enough(matches[f], f)) {
      add_comb(f, min_spacing(f), max_spacing(f));
      matches[f] = MatchFamily(lines[f], theta, n_lines, min_spacing(f), max_spacing(f));
    }
    if (!matches[f] || static_cast<int>(matches[f]->lines.size()) < needed(f)) {
      if (combs_alone()) {
        from_combs = true;
        break;
      }
      *why = fmt::format("found {} of the {} {} grid lines in step",
                         matches[f] ? matches[f]->lines.size() : 0, n_lines, family_names[f]);
      return std::nullopt;
    }
  }
  // The two families must be one perspective view (kPerspectiveTolerance).
  // A family matched apart may be bent by perspective through lines that
  // are not the grid's (a print's frame, a trace's level, a wave's crests)
  // while the other's lines stay parallel: it is matched again with the
  // perspective the other family's turn gives, and the lattice is refused
  // when the two still disagree.
  auto theta_of = [&](int f) { return Accumulator::Theta(dominant[f]); };
  auto expected_c = [&](int f) {
    const double q = PerspectiveOf(lines[1 - f], *matches[1 - f], theta_of(1 - f)).q;
    return f == 1 ? q : -q;
  };
  auto agrees = [&](int f) {
    return std::abs(PerspectiveOf(lines[f], *matches[f], theta_of(f)).c - expected_c(f)) <=
           kPerspectiveTolerance;
  };
  const std::optional<FamilyMatch> apart[2] = {matches[0], matches[1]};
  const std::size_t apart_lines[2] = {lines[0].size(), lines[1].size()};
  for (int f = 0; f < 2; ++f) {
    if (from_combs || agrees(f)) continue;
    std::optional<FamilyMatch> again = MatchFamily(lines[f], theta_of(f), divisions[f] + 1,
                                                   min_spacing(f), max_spacing(f), expected_c(f));
    if (enough(again, f)) matches[f] = std::move(again);
  }
  // Still two views: often one family is the grid's and the other's peaks
  // hold too few of its faint lines, so that traces, a hair or a speck's
  // fan of lines were matched in step instead. Each family in turn is
  // matched again, the other's held, with its comb's lines as candidates
  // and anchors and the perspective the held family gives; the lattice is
  // taken when the two then agree (the one with more lines when both do).
  if (!from_combs && (!agrees(0) || !agrees(1))) {
    std::optional<FamilyMatch> rescued[2];
    for (int g = 0; g < 2; ++g) {
      // The held family as matched apart: matched again above with the
      // other's perspective, a right family is bent through junk.
      matches[1 - g] = apart[1 - g];
      // The comb is spaced as the held family, within the bounds a screen
      // of square divisions seen tilted (up to 25 degrees) and in
      // perspective allows: a comb at about half the grid's spacing (a
      // trace's crests, a speck's fan of lines) stood in for the grid's.
      const auto& held = matches[1 - g]->lines;
      const double held_spacing = std::abs(lines[1 - g][held.back().second].rho_px -
                                           lines[1 - g][held.front().second].rho_px) /
                                  (held.back().first - held.front().first);
      comb_from[g] = 0;
      lines[g].resize(std::min(lines[g].size(), apart_lines[g]));
      add_comb(g, std::max(min_spacing(g), kMinSpacingRatio * held_spacing),
               std::min(max_spacing(g), kMaxSpacingRatio * held_spacing));
      std::optional<FamilyMatch> again =
          MatchFamily(lines[g], theta_of(g), divisions[g] + 1, min_spacing(g), max_spacing(g),
                      expected_c(g), comb_from[g]);
      if (!enough(again, g)) continue;
      std::swap(matches[g], again);
      if (agrees(0) && agrees(1)) rescued[g] = matches[g];
      std::swap(matches[g], again);
    }
    auto total = [&](int g) { return rescued[g]->lines.size() + matches[1 - g]->lines.size(); };
    const int g = !rescued[0] ? 1 : !rescued[1] ? 0 : total(1) > total(0) ? 1 : 0;
    if (rescued[g]) matches[g] = std::move(rescued[g]), matches[1 - g] = apart[1 - g];
  }
  if (!from_combs && (!agrees(0) || !agrees(1))) from_combs = combs_alone();
  if (!from_combs && (!agrees(0) || !agrees(1))) {
    *why = "the two families of lines found are not one perspective view of a grid";
    return std::nullopt;
  }
  for (int f = 0; f < 2; ++f) pencils[f] = FitPencil(lines[f], *matches[f], scale);
  for (int f = 0; f < 2; ++f) {
    const FamilyMatch& other = *matches[1 - f];
    PlaceWindow(*matches[f], pencils[f], pencils[1 - f], other.lines.front().first,
                other.lines.back().first, divisions[f] + 1, ridge, scale);
  }

  // Crossings of the lattice's lines: screen x = n - start (vertical family),
  // screen y = ny / 2 - (m - start) (horizontal family, image y grows down).
  const cv::Point2d centre(0.5 * (ridge.cols - 1), 0.5 * (ridge.rows - 1));
  std::vector<cv::Point2d> screen, image;
  for (int i = 0; i <= divisions[0]; ++i) {
    const cv::Vec3d vertical = pencils[0](i + matches[0]->window_start);
    for (int j = 0; j <= divisions[1]; ++j) {
      const cv::Vec3d horizontal = pencils[1](j + matches[1]->window_start);
      const cv::Point2d p = Intersect(vertical, horizontal);
      if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
        *why = "the grid lines found do not cross";
        return std::nullopt;
      }
      screen.emplace_back(i, 0.5 * divisions[1] - j);
      image.push_back(centre + p * scale);
      // A grid seen in the photo lies in it, or a division or two beyond
      // where the window was placed past the lines seen. Far beyond, a wrong
      // progression's perspective has flung it out, and measuring it on the
      // full photo would take minutes: a division there spans thousands of
      // pixels, and so do the profiles across its lines.
      const cv::Point2d& q = image.back();
      if (!(std::abs(q.x - centre.x) < 1.5 * ridge.cols &&
            std::abs(q.y - centre.y) < 1.5 * ridge.rows)) {
        *why = "the lattice found runs far outside the photo";
        return std::nullopt;
      }
    }
  }
  Lattice lattice;
  lattice.working_from_screen = FitHomography(screen, image);
  lattice.lines_found = {static_cast<int>(matches[0]->lines.size()),
                         static_cast<int>(matches[1]->lines.size())};
  // The screen must land in the photo's frame the right way round.
  const cv::Matx33d& h = lattice.working_from_screen;
  auto map = [&](double x, double y) {
    const cv::Vec3d q = h * cv::Vec3d(x, y, 1.0);
    return cv::Point2d(q[0] / q[2], q[1] / q[2]);
  };
  const cv::Point2d corner00 = map(0, -0.5 * divisions[1]),
                    corner10 = map(divisions[0], -0.5 * divisions[1]);
  const cv::Point2d corner01 = map(0, 0.5 * divisions[1]);
  const double orientation = (corner10 - corner00).cross(corner01 - corner00);
  if (!(orientation < 0.0)) {  // x right and y up on the screen: clockwise in the image
    *why = "the lattice found is mirrored";
    return std::nullopt;
  }
  return lattice;
}

}  // namespace impactlab::digitize
