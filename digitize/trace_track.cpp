#include "digitize/trace_track.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "digitize/course_search.h"
#include "digitize/line_profile.h"
#include "digitize/screen_geometry.h"
#include "digitize/select.h"

namespace impactlab::digitize {

namespace {

// The strip reaches this far beyond the band: a trace may touch its band's
// edge, and its glow then spills over, divisions.
constexpr double kBandMarginDiv = 0.15;
// The CRT face shows this much beyond the graticule, divisions.
constexpr double kOverscanDiv = 0.3;
// Candidate peaks kept per column.
constexpr int kCandidatesPerColumn = 6;

// A course found without a suspected foreign run that passes this far from it
// went elsewhere: the run was not the trace's, divisions.
constexpr double kAwayDiv = 0.1;
// An excursion of a continuous trace's course reached and left by jumps
// its own slope does not explain, more than this each, divisions, is not
// the trace (StrayExcursions); the course is sought again without the
// candidates within kStrayClearDiv of it (a label's strokes stacked).
constexpr double kStrayJumpDiv = 1.0, kStrayClearDiv = 0.5;
// The same across a gap the course bridged on course (a mark taken out of
// the ridge image, a faint stretch): the dynamic programming lets a course
// jump there, and most cheaply where it begins, with no slope yet to keep.
// A stretch it lands on beside the trace (a hair, a ring's arc, a grid line,
// a thinner line of its own ink) is then reached or left without a restart
// and without the division-long jumps StrayExcursions looks for. A trace's
// own course is continuous: across a gap the slopes either side extrapolate
// it to within a few hundredths of a division, so a jump across one of more
// than kGapJumpDiv is not the trace's (see GapExcursions).
constexpr double kGapJumpDiv = 0.2;
// The stretches either side (each kGapSideDiv long, its slope fitted over
// up to that; beside an end piece four strip columns will do) bridge an
// excursion of up to kGapExcursionDiv; one at the course's first or last
// end of up to kGapEndDiv is judged against the rest of the course, at
// least kGapEndShare times longer, when the two run alongside each other:
// their slopes within kGapEndSlope, divisions per division.
constexpr double kGapSideDiv = 0.15, kGapExcursionDiv = 2.0, kGapEndDiv = 1.0;
constexpr double kGapEndShare = 3.0, kGapEndSlope = 0.5;
// An inner excursion is judged only where it meets its gaps less steeply
// than this, divisions per division.
constexpr double kGapSteep = 2.5;
// Only a course that sees the trace in this share of its columns at least is
// judged so: a continuous trace's, broken at grid lines and marks.
constexpr double kGapMinOccupied = 0.75;
// The course sought again without an excursion may differ from the first
// within this of it, divisions, and nowhere else.
constexpr double kGapNearDiv = 0.5;
// Only the candidates within kGapClearDiv of an excursion are withdrawn:
// the trace may run a few tenths of a division beside what was taken.
constexpr double kGapClearDiv = 0.1;
// A one-way trace (a calibration's: TraceRequest::one_way_until_s) turns back by no
// more than this, divisions (at least kOneWayBackMinRows strip rows): the
// reading's noise and a trace's wobble where it crosses a grid line, a few
// hundredths of a division. A pen ring's arc, an arrow or a stroke the
// course might follow instead turns back by tenths of a division or more.
constexpr double kOneWayBackDiv = 0.15, kOneWayBackMinRows = 1.5;
// A course is sought again at most this many times without what one check
// (lines beyond the face, strays) found on it: the course sought anew may
// take another such line or stray (a second scratch, a ring's other arc).
constexpr int kRounds = 3;
// A peak beside a point the user gave (TraceSettings::points_px) earns this
// much more: more than any detour to reach it costs (a restart costs
// 3, course_search.cpp), so the best path passes through every hinted point.
constexpr double kHintReward = 10.0;
// How near a hinted point a peak must lie to earn it, divisions (at least 2
// strip pixels): a click is good to a few photo pixels, and a steep flank
// moves fast across the columns beside it.
constexpr double kHintReachDiv = 0.05;

double QuantileOf(std::vector<float>& values, double q) {
  if (values.empty()) return 0.0;
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * (values.size() - 1));
  return SelectNth(values.begin(), at, values.end());
}

struct Strip {
  cv::Mat1f image;     // rows: screen y from y_top down; columns: the track grid
  double y_top = 0.0;  // screen y of row 0
  double px_per_div = 1.0;
  double YOf(double row) const { return y_top - row / px_per_div; }
  double RowOf(double y) const { return (y_top - y) * px_per_div; }
};

// The band's part of the ridge image, resampled on the screen's axes.
Strip CutStrip(const PreparedPhoto& photo, const GraticuleMapping& mapping,
               std::array<int, 2> divisions, const TraceSettings& settings, const TrackGrid& grid) {
  const double half_height = 0.5 * divisions[1] + kOverscanDiv;
  const double lo = std::min(settings.band_div[0], settings.band_div[1]);
  const double hi = std::max(settings.band_div[0], settings.band_div[1]);
  Strip strip;
  strip.px_per_div = grid.px_per_div;
  strip.y_top = std::min(hi + kBandMarginDiv, half_height);
  const double y_bottom = std::max(lo - kBandMarginDiv, -half_height);
  const int rows =
      std::max(3, static_cast<int>(std::ceil((strip.y_top - y_bottom) * grid.px_per_div)) + 1);
  cv::Mat1f map_x(rows, grid.columns), map_y(rows, grid.columns);
  // The mapping is smooth over a few strip pixels: exact every kEvery
  // columns, linear in between.
  constexpr int kEvery = 4;
  for (int row = 0; row < rows; ++row) {
    const double y = strip.YOf(row);
    float* mx = map_x.ptr<float>(row);
    float* my = map_y.ptr<float>(row);
    cv::Point2d previous;
    int previous_column = -1;
    for (int column = 0; column < grid.columns; column += kEvery) {
      const int c = std::min(column, grid.columns - 1);
      const cv::Point2d w = photo.WorkingFromPhoto(ImageFromScreen(mapping, {grid.XOf(c), y}));
      mx[c] = static_cast<float>(w.x), my[c] = static_cast<float>(w.y);
      if (previous_column >= 0) {
        for (int k = previous_column + 1; k < c; ++k) {
          const double f = static_cast<double>(k - previous_column) / (c - previous_column);
          mx[k] = static_cast<float>(previous.x + f * (w.x - previous.x));
          my[k] = static_cast<float>(previous.y + f * (w.y - previous.y));
        }
      }
      previous = w, previous_column = c;
      if (column + kEvery >= grid.columns && c != grid.columns - 1)
        column = grid.columns - 1 - kEvery;
    }
  }
  cv::remap(photo.ridge, strip.image, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0.0);
  return strip;
}

// Takes the grid lines out of the strip. Vertical lines and any vertical
// drift: each column's median. Horizontal lines: the lower quartile along
// their rows, but never more than twice the lines' usual height, so that a
// trace lying along a grid line survives. The usual height comes from the
// vertical lines (their columns' medians stand out of their neighbours'),
// which no trace can cover for more than a few rows. Returns it. On a
// raster's dotted graticule (`dotted`) the outermost horizontal lines are
// the display's solid frame, far above the dotted lines' height, and are
// taken out uncapped: capped, the frame stood in the strip, and a trace
// resting a tenth of a division above it was followed along the frame
// instead (the generator's digital thesis sessions: a contact step's rise
// read 75 us late, its time 23 % short).
double SuppressGrid(Strip& strip, std::array<int, 2> divisions, bool dotted) {
  cv::Mat1f& image = strip.image;
  // Each column's median, from a copy with the columns laid out as rows: read
  // down a column, every value would be a cache line of its own.
  cv::Mat1f columns = image.t();
  std::vector<float> medians(image.cols);
  for (int c = 0; c < image.cols; ++c) {
    float* p = columns.ptr<float>(c);
    medians[c] = SelectNth(p, p + image.rows / 2, p + image.rows);
  }
  for (int r = 0; r < image.rows; ++r) {
    float* p = image.ptr<float>(r);
    for (int c = 0; c < image.cols; ++c) p[c] -= medians[c];
  }
  std::vector<float> heights;
  const int reach = std::max(2, static_cast<int>(std::lround(0.1 * strip.px_per_div)));
  for (int i = 0; i <= divisions[0]; ++i) {
    const int c = static_cast<int>(std::lround(i * strip.px_per_div));
    if (c - reach < 0 || c + reach >= image.cols) continue;
    const float line = std::max({medians[c - 1], medians[c], medians[c + 1]});
    heights.push_back(line - 0.5f * (medians[c - reach] + medians[c + reach]));
  }
  const double line_height = std::max(0.0, MedianOf(heights));

  const double cap = 2.0 * line_height;
  std::vector<float> row_values(image.cols);
  const double half = 0.5 * divisions[1];
  for (int k = 0; k <= divisions[1]; ++k) {
    const bool frame = dotted && (k == 0 || k == divisions[1]);
    const double row_cap = frame ? std::numeric_limits<double>::infinity() : cap;
    const double centre = strip.RowOf(k - half);
    for (int r = static_cast<int>(std::floor(centre - 1.5));
         r <= static_cast<int>(std::ceil(centre + 1.5)); ++r) {
      if (r < 0 || r >= image.rows || std::abs(r - centre) > 1.5) continue;
      for (int c = 0; c < image.cols; ++c) row_values[c] = image(r, c);
      const float take = static_cast<float>(std::clamp(QuantileOf(row_values, 0.25), 0.0, row_cap));
      for (int c = 0; c < image.cols; ++c) image(r, c) -= take;
    }
  }
  return line_height;
}

// Where the graticule draws: its division lines (a strip pixel and a half
// either side, as SuppressGrid takes them out) and, along the centre axes,
// their tick marks' reach.
class GridNeighbourhood {
 public:
  GridNeighbourhood(std::array<int, 2> divisions, double px_per_div)
      : half_width_(0.5 * divisions[0]),
        half_height_(0.5 * divisions[1]),
        line_reach_(1.5 / px_per_div) {}

  // Screen x from the graticule's left edge, y from its centre (divisions).
  bool operator()(double x_div, double y_div) const {
    // Division lines lie at x = 0, 1, ... and y = -ny/2, -ny/2 + 1, ...;
    // the centre axes at x = nx/2 and y = 0 (lines of their own when odd).
    const auto near = [&](double from_line, double from_axis) {
      return std::abs(from_line - std::round(from_line)) <= line_reach_ ||
             std::abs(from_axis) <= kTickReachDiv;
    };
    return near(x_div, x_div - half_width_) || near(y_div + half_height_, y_div);
  }

 private:
  // Tick marks reach about a tenth of a division either side of an axis.
  static constexpr double kTickReachDiv = 0.15;
  double half_width_, half_height_;
  double line_reach_;
};

// The points a trace's settings say it passes through, in strip columns and
// rows: the reward a peak near one of them earns, and, between two points
// at most kFenceSpanDiv apart, the corridor the trace keeps to. Attraction
// alone does not hold a path that a brighter line beside the trace draws
// away between two points and back (a scratch along it); where points are
// that close, the user has said where the trace runs in between.
constexpr double kFenceSpanDiv = 0.5;
// The corridor's half-width about the curve through the points: at least
// this, divisions, and half the rise between the two points.
constexpr double kFenceHalfWidthDiv = 0.1;

class HintedPoints {
 public:
  HintedPoints(const TraceSettings& settings, const GraticuleMapping& mapping, const Strip& strip,
               const TrackGrid& grid)
      : reach_(std::max(2.0, kHintReachDiv * grid.px_per_div)), px_per_div_(grid.px_per_div) {
    for (const auto& [x, y] : settings.points_px) {
      const cv::Point2d screen = mapping.ScreenFromImage({x, y});
      points_.emplace_back(screen.x * grid.px_per_div, strip.RowOf(screen.y));
    }
    std::sort(points_.begin(), points_.end(),
              [](const cv::Point2d& a, const cv::Point2d& b) { return a.x < b.x; });
  }

  bool empty() const { return points_.empty(); }

  // kHintReward at a hinted point, half of it at the reach, 0 beyond.
  double Reward(int column, double row) const {
    double best = 0.0;
    for (const cv::Point2d& p : points_) {
      const double d = std::hypot(column - p.x, row - p.y);
      if (d <= reach_) best = std::max(best, kHintReward * (1.0 - 0.5 * d / reach_));
    }
    return best;
  }

  // Whether a peak lies outside the corridor between two close points: the
  // Catmull-Rom curve through them (its tangents from their neighbours),
  // widened by kFenceHalfWidthDiv or half their rise.
  bool Fenced(int column, double row) const {
    const auto next = std::upper_bound(points_.begin(), points_.end(), static_cast<double>(column),
                                       [](double c, const cv::Point2d& p) { return c < p.x; });
    if (next == points_.begin() || next == points_.end()) return false;
    const std::size_t i = static_cast<std::size_t>(next - points_.begin()) - 1;
    const cv::Point2d& a = points_[i];
    const cv::Point2d& b = points_[i + 1];
    const double span = b.x - a.x;
    if (!(span > 0.0) || span > kFenceSpanDiv * px_per_div_) return false;
    const auto slope = [&](std::size_t k) {  // rows per column at point k
      const cv::Point2d& lo = points_[k > 0 ? k - 1 : k];
      const cv::Point2d& hi = points_[k + 1 < points_.size() ? k + 1 : k];
      return hi.x > lo.x ? (hi.y - lo.y) / (hi.x - lo.x) : 0.0;
    };
    const double t = (column - a.x) / span, t2 = t * t, t3 = t2 * t;
    const double curve = (2 * t3 - 3 * t2 + 1) * a.y + (t3 - 2 * t2 + t) * span * slope(i) +
                         (-2 * t3 + 3 * t2) * b.y + (t3 - t2) * span * slope(i + 1);
    const double half_width =
        std::max({kFenceHalfWidthDiv * px_per_div_, 0.5 * std::abs(b.y - a.y), reach_});
    return std::abs(row - curve) > half_width;
  }

 private:
  double reach_;                     // strip pixels
  double px_per_div_;                // strip pixels per division
  std::vector<cv::Point2d> points_;  // (column, row), by column
};

// Thin lines that run on beyond the CRT's face: a scratch or a hair on the
// print, the film or the glass. The beam draws nowhere beyond the face (the
// phosphor reaches kOverscanDiv past the graticule), so a line that the
// course follows and that goes on, unbroken and nearly straight, well past
// the face into the bezel or the page round a printed figure, is not the
// trace, however well it pays column by column (a continuous line crossing
// a dotted trace out-earns the dots; a faint or bold trace loses to it).
//
// The line must be followed this far beyond the face, divisions: past the
// face's own edge and the bezel's lip (which a follower crossing it sees
// for a pixel or two), into the bezel or the page.
constexpr double kBeyondFaceDiv = 0.5;
// The course's stretches tried: this long, divisions, and straight to
// kStraightPx working pixels RMS (a trace's bend is not a scratch).
constexpr double kStraightWindowDiv = 0.25;
constexpr double kStraightPx = 0.6;
// A line is followed across gaps up to this long, divisions (where it
// crosses something darker, or its own ink thins), and while it turns no
// more than kMaxLineTurnDeg from where it started: a scratch curls
// gently, a trace's course turns away.
constexpr double kLineGapDiv = 0.08;
constexpr double kMaxLineTurnDeg = 30.0;
constexpr double kMaxLineBendDeg = 12.0, kBendChordDiv = 0.3;
// It is followed while it stands this share of the course's own peaks
// above the ground (and above the noise).
constexpr double kLineShare = 0.35;
// Candidates within this of a line found (divisions, at least 1.5 strip
// pixels) are withdrawn: the line's width and the follower's error.
constexpr double kLineClearDiv = 0.05;

// Working pixels a line follower has passed, in cells of a given size, with
// the line's direction there.
class FollowedCells {
 public:
  explicit FollowedCells(double cell_px) : cell_(cell_px) {}
  void Add(const std::vector<cv::Point2d>& points) {
    for (std::size_t k = 1; k < points.size(); ++k) {
      const cv::Point2d d = points[k] - points[k - 1];
      const double norm = std::hypot(d.x, d.y);
      if (norm > 0.0) cells_[Key(points[k], 0, 0)] = d * (1.0 / norm);
    }
  }
  // Whether `p` lies within about a cell of a point passed along a line in
  // `direction` (either way, within kSameLineDeg).
  bool Covers(cv::Point2d p, cv::Point2d direction) const {
    const double norm = std::hypot(direction.x, direction.y);
    if (!(norm > 0.0)) return false;
    const double min_cos = std::cos(kSameLineDeg * 3.14159265358979 / 180.0);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(Key(p, dx, dy));
        if (it != cells_.end() && std::abs(it->second.dot(direction)) >= min_cos * norm) {
          return true;
        }
      }
    }
    return false;
  }

 private:
  static constexpr double kSameLineDeg = 3.0;
  long long Key(cv::Point2d p, int dx, int dy) const {
    const long long x = static_cast<long long>(std::floor(p.x / cell_)) + dx;
    const long long y = static_cast<long long>(std::floor(p.y / cell_)) + dy;
    return (x << 32) ^ (y & 0xffffffffLL);
  }
  double cell_;
  std::unordered_map<long long, cv::Point2d> cells_;
};

class ThroughLines {
 public:
  ThroughLines(const PreparedPhoto& photo, const GraticuleFit& graticule, const Strip& strip,
               const TrackGrid& grid, double noise_floor)
      : photo_(photo),
        mapping_(graticule.mapping),
        screen_from_pixel_(graticule.mapping),
        strip_(strip),
        grid_(grid),
        half_width_(0.5 * graticule.divisions[0]),
        half_height_(0.5 * graticule.divisions[1]),
        noise_floor_(noise_floor) {}

  // Withdraws from `nodes` the candidates lying on the lines beyond the face
  // that `chosen` (a course through `nodes`) follows; returns how many lines.
  int Withdraw(const std::vector<Chosen>& chosen, std::vector<std::vector<Node>>& nodes) const {
    const int window =
        std::max(6, static_cast<int>(std::lround(kStraightWindowDiv * grid_.px_per_div)));
    std::vector<std::vector<cv::Point2d>> lines;
    FollowedCells followed(std::max(1.5, kLineClearDiv * grid_.px_per_div));
    std::size_t first = 0;
    for (std::size_t i = 1; i <= chosen.size(); ++i) {
      if (i < chosen.size() && chosen[i].link == CoarsePath::kOnCourse) continue;
      // chosen[first, i) is one stretch of the course, between restarts.
      for (std::size_t a = first; a < i; a += std::max<std::size_t>(1, window / 4)) {
        std::size_t b = a;
        while (b < i && chosen[b].column < chosen[a].column + window) ++b;
        if (b == i && chosen[b - 1].column - chosen[a].column < window - 2) break;
        // Nearly every column seen: a line, not a chopper's dots.
        if (4 * (b - a) < static_cast<std::size_t>(3 * window)) continue;
        std::vector<cv::Point2d> points;  // working pixels
        std::vector<float> values;
        for (std::size_t k = a; k < b; ++k) {
          const Node& n = nodes[chosen[k].column][chosen[k].index];
          points.push_back(WorkingOf(n.column, n.row));
          values.push_back(n.value);
        }
        if (OnLines(lines, points[points.size() / 2])) continue;
        // A stretch on a line already followed both ways and found on the
        // face alone (a long straight stretch of trace, a contact level) is
        // not followed again from each window along it.
        if (followed.Covers(points[points.size() / 2], points.back() - points.front())) continue;
        const double floor = std::max(noise_floor_, kLineShare * MedianOf(values));
        std::vector<cv::Point2d> line = Beyond(points, floor, followed);
        if (!line.empty()) lines.push_back(std::move(line));
      }
      first = i;
    }
    for (const std::vector<cv::Point2d>& line : lines) Clear(line, nodes);
    return static_cast<int>(lines.size());
  }

 private:
  cv::Point2d WorkingOf(int column, double row) const {
    return photo_.WorkingFromPhoto(ImageFromScreen(mapping_, {grid_.XOf(column), strip_.YOf(row)}));
  }

  // How far beyond the face a working pixel lies, divisions (<= 0: on it).
  double BeyondFace(cv::Point2d working) const {
    const cv::Point2d s = screen_from_pixel_(photo_.PhotoFromWorking(working));
    return std::max({-kOverscanDiv - s.x, s.x - 2.0 * half_width_ - kOverscanDiv,
                     std::abs(s.y) - half_height_ - kOverscanDiv});
  }

  float RidgeAt(cv::Point2d p) const {
    const cv::Mat1f& r = photo_.ridge;
    if (!(p.x >= 0.0 && p.y >= 0.0 && p.x < r.cols - 1 && p.y < r.rows - 1)) return 0.0f;
    const int x = static_cast<int>(p.x), y = static_cast<int>(p.y);
    const float fx = static_cast<float>(p.x - x), fy = static_cast<float>(p.y - y);
    return (r(y, x) * (1 - fx) + r(y, x + 1) * fx) * (1 - fy) +
           (r(y + 1, x) * (1 - fx) + r(y + 1, x + 1) * fx) * fy;
  }

  // Follows a thin bright line from `start` along `direction` (working
  // pixels), a pixel a step, re-centred on the brightest of five points
  // across it within a pixel; stops after a gap longer than kLineGapDiv,
  // a turn of more than kMaxLineTurnDeg or at the image's edge. Returns
  // where it saw the line.
  std::vector<cv::Point2d> Follow(cv::Point2d start, cv::Point2d direction, double floor) const {
    const int max_miss = std::max(2, static_cast<int>(std::lround(kLineGapDiv * grid_.px_per_div)));
    const double min_cos = std::cos(kMaxLineTurnDeg * 3.14159265358979 / 180.0);
    const cv::Point2d initial = direction;
    const std::size_t chord = std::max<std::size_t>(
        8, static_cast<std::size_t>(std::lround(kBendChordDiv * grid_.px_per_div)));
    const double max_bend_cos = std::cos(kMaxLineBendDeg * 3.14159265358979 / 180.0);
    const int max_steps = 2 * (photo_.ridge.cols + photo_.ridge.rows);
    std::vector<cv::Point2d> seen;
    cv::Point2d p = start, d = direction;
    for (int step = 0, miss = 0; step < max_steps && miss <= max_miss; ++step) {
      p += d;
      if (!(p.x >= 1.0 && p.y >= 1.0 && p.x < photo_.ridge.cols - 2 && p.y < photo_.ridge.rows - 2))
        break;
      const cv::Point2d n(-d.y, d.x);
      double best = -1.0, offset = 0.0;
      for (const double o : {0.0, -0.5, 0.5, -1.0, 1.0}) {
        const double v = RidgeAt(p + o * n);
        if (v > best) best = v, offset = o;
      }
      if (best < floor) {
        ++miss;
        continue;
      }
      miss = 0;
      p += 0.5 * offset * n;
      d += 0.05 * offset * n;
      d *= 1.0 / std::hypot(d.x, d.y);
      if (d.dot(initial) < min_cos) break;
      seen.push_back(p);
      // A line bending within a few tenths of a division (chords of
      // `chord` steps turning by more than kMaxLineBendDeg) is a trace's
      // swing, not a scratch: it stops where it began to bend.
      const std::size_t k = seen.size() - 1;
      if (k >= 2 * chord) {
        const cv::Point2d a = seen[k - chord] - seen[k - 2 * chord], b = seen[k] - seen[k - chord];
        if (a.dot(b) < max_bend_cos * std::hypot(a.x, a.y) * std::hypot(b.x, b.y)) {
          seen.resize(k - chord);
          break;
        }
      }
    }
    return seen;
  }

  // The line through `points` (a straight stretch of the course, working
  // pixels) followed both ways, when it runs on beyond the face; else empty.
  std::vector<cv::Point2d> Beyond(const std::vector<cv::Point2d>& points, double floor,
                                  FollowedCells& followed) const {
    cv::Point2d mean(0.0, 0.0);
    for (const cv::Point2d& p : points) mean += p;
    mean *= 1.0 / points.size();
    double sxx = 0.0, sxy = 0.0, syy = 0.0;
    for (const cv::Point2d& p : points) {
      const cv::Point2d d = p - mean;
      sxx += d.x * d.x, sxy += d.x * d.y, syy += d.y * d.y;
    }
    const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
    cv::Point2d u(std::cos(angle), std::sin(angle));
    if ((points.back() - points.front()).dot(u) < 0.0) u = -u;
    const cv::Point2d n(-u.y, u.x);
    double residual2 = 0.0;
    for (const cv::Point2d& p : points) residual2 += std::pow((p - mean).dot(n), 2);
    if (residual2 > kStraightPx * kStraightPx * points.size()) return {};
    const cv::Point2d head = mean + u * (points.back() - mean).dot(u);
    const cv::Point2d tail = mean + u * (points.front() - mean).dot(u);
    std::vector<cv::Point2d> forward = Follow(head, u, floor);
    std::vector<cv::Point2d> backward = Follow(tail, -u, floor);
    const auto beyond = [&](const std::vector<cv::Point2d>& seen) {
      return std::any_of(seen.begin(), seen.end(),
                         [&](const cv::Point2d& p) { return BeyondFace(p) >= kBeyondFaceDiv; });
    };
    if (!beyond(forward) && !beyond(backward)) {
      followed.Add(forward);
      followed.Add(backward);
      return {};
    }
    std::vector<cv::Point2d> line(backward.rbegin(), backward.rend());
    line.insert(line.end(), points.begin(), points.end());
    line.insert(line.end(), forward.begin(), forward.end());
    return line;
  }

  // Whether a course's point lies on a line already found.
  bool OnLines(const std::vector<std::vector<cv::Point2d>>& lines, cv::Point2d p) const {
    const double reach = std::max(1.5, kLineClearDiv * grid_.px_per_div);
    for (const auto& line : lines) {
      for (const cv::Point2d& q : line) {
        if (std::hypot(p.x - q.x, p.y - q.y) <= reach) return true;
      }
    }
    return false;
  }

  // Withdraws the candidates within kLineClearDiv of `line` (working pixels).
  void Clear(const std::vector<cv::Point2d>& line, std::vector<std::vector<Node>>& nodes) const {
    const double reach = std::max(1.5, kLineClearDiv * grid_.px_per_div);
    const int columns = static_cast<int>(nodes.size());
    std::vector<std::pair<double, double>> rows(columns, {1e300, -1e300});
    cv::Point2d previous;
    bool have_previous = false;
    for (const cv::Point2d& w : line) {
      const cv::Point2d s = screen_from_pixel_(photo_.PhotoFromWorking(w));
      const cv::Point2d q(s.x * grid_.px_per_div, strip_.RowOf(s.y));  // column, row
      const int steps =
          have_previous ? std::max(1, static_cast<int>(std::ceil(2.0 * std::abs(q.x - previous.x))))
                        : 1;
      for (int k = 1; k <= steps; ++k) {
        const cv::Point2d r = have_previous ? previous + (q - previous) * (1.0 * k / steps) : q;
        const int c = static_cast<int>(std::lround(r.x));
        if (c < 0 || c >= columns) continue;
        rows[c].first = std::min(rows[c].first, r.y);
        rows[c].second = std::max(rows[c].second, r.y);
      }
      previous = q, have_previous = true;
    }
    for (int c = 0; c < columns; ++c) {
      if (rows[c].first > rows[c].second) continue;
      std::erase_if(nodes[c], [&](const Node& n) {
        return n.row >= rows[c].first - reach && n.row <= rows[c].second + reach;
      });
    }
  }

  const PreparedPhoto& photo_;
  const GraticuleMapping& mapping_;
  ScreenFromPixel screen_from_pixel_;
  const Strip& strip_;
  const TrackGrid& grid_;
  double half_width_, half_height_;
  double noise_floor_;
};

// A course's pieces between gaps and restarts, [first, end) into `chosen`.
struct CoursePiece {
  std::size_t first = 0, end = 0;
};

// The candidates of excursions a continuous trace's course made across gaps
// it bridged: one to three pieces, reached or left by a jump that neither
// side's slope explains (more than `jump_rows`), that lie off the curve
// bridging the pieces either side (a cubic with their end slopes) by more
// than `jump_rows` at their median; or, at the course's first or last end,
// a short piece reached by such a jump from a course far longer than it.
// A trace's own pieces lie on that bridge and join across short gaps
// without jumps.
std::vector<Chosen> GapExcursions(const std::vector<Chosen>& chosen,
                                  const std::vector<std::vector<Node>>& nodes, double px_per_div,
                                  double jump_rows) {
  const auto row_of = [&](std::size_t i) { return nodes[chosen[i].column][chosen[i].index].row; };
  std::vector<CoursePiece> pieces;
  for (std::size_t i = 0; i < chosen.size(); ++i) {
    if (i == 0 || chosen[i].link == CoarsePath::kRestart ||
        chosen[i].column - chosen[i - 1].column > 1) {
      pieces.push_back({i, i});
    }
    pieces.back().end = i + 1;
  }
  const auto span = [&](const CoursePiece& p) {
    return chosen[p.end - 1].column - chosen[p.first].column;
  };
  const auto span_of = [&](std::size_t from, std::size_t to) {  // pieces [from, to)
    return chosen[pieces[to - 1].end - 1].column - chosen[pieces[from].first].column;
  };
  // The row and slope (rows per column) at one end of a piece, from a
  // straight line through its columns within kGapSideDiv of that end.
  const double side_columns = kGapSideDiv * px_per_div;
  struct End {
    int column = 0;
    double row = 0.0, slope = 0.0;
  };
  const auto end_of = [&](const CoursePiece& p, bool last) {
    const int at = chosen[last ? p.end - 1 : p.first].column;
    double n = 0.0, sc = 0.0, sr = 0.0, scc = 0.0, scr = 0.0;
    for (std::size_t i = p.first; i < p.end; ++i) {
      const double dc = chosen[i].column - at;
      if (std::abs(dc) > side_columns) continue;
      const double r = row_of(i);
      n += 1.0, sc += dc, sr += r, scc += dc * dc, scr += dc * r;
    }
    const double det = n * scc - sc * sc;
    End e;
    e.column = at;
    e.slope = det > 0.0 ? (n * scr - sc * sr) / det : 0.0;
    e.row = (sr - e.slope * sc) / n;
    return e;
  };
  // How far a piece's end lands from where the other pointed, whichever
  // side explains it better (rows).
  const auto jump = [&](const End& from, const End& to) {
    const int dc = to.column - from.column;
    return std::min(std::abs(to.row - (from.row + from.slope * dc)),
                    std::abs(from.row - (to.row - to.slope * dc)));
  };
  // A slope needs a few columns: kGapSideDiv either side of an inner
  // excursion, whose bridge it sets over up to kGapExcursionDiv; beside an
  // end piece, whose jump it extrapolates over a gap alone, four columns
  // where those are fewer.
  const auto long_enough = [&](const CoursePiece& p) { return span(p) >= side_columns; };
  const auto long_enough_at_end = [&](const CoursePiece& p) {
    return span(p) >= std::min(side_columns, 4.0);
  };
  std::vector<Chosen> stray;
  const auto take = [&](std::size_t from, std::size_t to) {
    stray.insert(stray.end(), chosen.begin() + static_cast<std::ptrdiff_t>(pieces[from].first),
                 chosen.begin() + static_cast<std::ptrdiff_t>(pieces[to - 1].end));
  };
  const std::size_t count = pieces.size();
  if (count < 2) return stray;
  // A chopped or sparse course is all gaps: its dashes join across the
  // chopper's blanking, where a swing moves the beam by more than a slope
  // from a dash's few columns extrapolates (ForeignRuns judges those).
  const double occupied =
      static_cast<double>(chosen.size()) / (chosen.back().column - chosen.front().column + 1);
  if (occupied < kGapMinOccupied) return stray;
  // The middle: pieces [i, j) between two long enough pieces.
  for (std::size_t i = 1; i + 1 < count; ++i) {
    if (!long_enough(pieces[i - 1])) continue;
    for (std::size_t j = i + 1; j <= std::min(i + 3, count - 1); ++j) {
      if (!long_enough(pieces[j])) continue;
      if (span_of(i, j) > kGapExcursionDiv * px_per_div) break;
      const End before = end_of(pieces[i - 1], true), after = end_of(pieces[j], false);
      const End first = end_of(pieces[i], false), last = end_of(pieces[j - 1], true);
      // A stretch that leaves or reaches a gap steeply is a fast swing whose
      // flank the beam drew too faintly to be seen (a rebound between two
      // impacts), whatever its slope fitted so near the gap extrapolates.
      if (std::max(std::abs(first.slope), std::abs(last.slope)) > kGapSteep) continue;
      const double in = jump(before, first);
      const double out = jump(last, after);
      if (std::max(in, out) <= jump_rows) continue;
      // The pieces either side must agree across it: where one of them is
      // the excursion (a hair leaving the trace where it crosses it), the
      // bridge is no measure of the trace.
      if (jump(before, after) > jump_rows) continue;
      // The bridge: a cubic from `before` to `after` with their slopes.
      const double width = after.column - before.column;
      std::vector<float> off;
      for (std::size_t k = pieces[i].first; k < pieces[j - 1].end; ++k) {
        const double t = (chosen[k].column - before.column) / width, t2 = t * t, t3 = t2 * t;
        const double bridge = (2 * t3 - 3 * t2 + 1) * before.row +
                              (t3 - 2 * t2 + t) * width * before.slope +
                              (-2 * t3 + 3 * t2) * after.row + (t3 - t2) * width * after.slope;
        off.push_back(static_cast<float>(std::abs(row_of(k) - bridge)));
      }
      if (MedianOf(off) <= jump_rows) continue;
      take(i, j);
      i = j;
      break;
    }
  }
  // An end piece is judged only when it runs beside the course it joins,
  // about as steep as it (kGapEndSlope): a line alongside the trace. Where
  // the slopes differ, the gap may be a fast flank the beam drew too faintly
  // (a run's release level and its first swing down), which no slope
  // extrapolates.
  const auto beside = [&](const End& from, const End& to) {
    return std::abs(from.slope - to.slope) <= kGapEndSlope && jump(from, to) > jump_rows;
  };
  // Where the course has none, its ends: the middle's excursions judged
  // first, since a true end piece is left by a jump where the course beyond
  // it strays (the rest is judged in the next round).
  if (!stray.empty()) return stray;
  // The ends: a short first (last) few pieces reached by an unexplained jump
  // from the rest of the course, far longer.
  const int total = span_of(0, count);
  std::size_t inner_from = 1;  // the pieces the first end took
  for (std::size_t j = 1; j <= std::min<std::size_t>(3, count - 1); ++j) {
    if (span_of(0, j) > kGapEndDiv * px_per_div) break;
    if (!long_enough_at_end(pieces[j])) continue;
    if (kGapEndShare * span_of(0, j) > total - span_of(0, j)) break;
    if (!beside(end_of(pieces[j - 1], true), end_of(pieces[j], false))) continue;
    take(0, j);
    inner_from = j + 1;
    break;
  }
  for (std::size_t j = 1; j <= std::min<std::size_t>(3, count - 1); ++j) {
    const std::size_t from = count - j;  // pieces [from, count)
    if (from < inner_from) break;
    if (span_of(from, count) > kGapEndDiv * px_per_div) break;
    if (!long_enough_at_end(pieces[from - 1])) continue;
    if (kGapEndShare * span_of(from, count) > total - span_of(from, count)) break;
    if (!beside(end_of(pieces[from - 1], true), end_of(pieces[from], false))) continue;
    take(from, count);
    break;
  }
  return stray;
}

// The candidates `nodes` without those within `reach` rows of the course's
// samples `taken`, in their columns: what a course is sought again on once
// `taken` was judged something beside the trace.
std::vector<std::vector<Node>> WithoutCandidatesNear(const std::vector<std::vector<Node>>& nodes,
                                                     const std::vector<Chosen>& taken,
                                                     double reach) {
  std::vector<std::vector<Node>> cleared = nodes;
  for (const Chosen& c : taken) {
    const double row = nodes[c.column][c.index].row;
    std::erase_if(cleared[c.column], [&](const Node& n) { return std::abs(n.row - row) <= reach; });
  }
  return cleared;
}

// Whether courses `a` (on the candidates `a_nodes`) and `b` (on `b_nodes`)
// take the same columns at the same rows everywhere farther than `near`
// columns from the candidates `around`.
bool SameAwayFrom(const std::vector<Chosen>& a, const std::vector<std::vector<Node>>& a_nodes,
                  const std::vector<Chosen>& b, const std::vector<std::vector<Node>>& b_nodes,
                  const std::vector<Chosen>& around, int near) {
  std::vector<bool> close(a_nodes.size(), false);
  for (const Chosen& c : around) {
    const int from = std::max(0, c.column - near);
    const int to = std::min(static_cast<int>(close.size()) - 1, c.column + near);
    for (int k = from; k <= to; ++k) close[static_cast<std::size_t>(k)] = true;
  }
  const auto away = [&](const std::vector<Chosen>& course,
                        const std::vector<std::vector<Node>>& nodes) {
    std::vector<std::pair<int, double>> out;
    for (const Chosen& c : course) {
      if (!close[static_cast<std::size_t>(c.column)]) {
        out.emplace_back(c.column, nodes[c.column][c.index].row);
      }
    }
    return out;
  };
  return away(a, a_nodes) == away(b, b_nodes);
}

// How many columns courses `a` (on the candidates `a_nodes`) and `b` (on
// `b_nodes`) take at rows within `near_rows` of each other.
std::size_t SharedColumns(const std::vector<Chosen>& a,
                          const std::vector<std::vector<Node>>& a_nodes,
                          const std::vector<Chosen>& b,
                          const std::vector<std::vector<Node>>& b_nodes, double near_rows) {
  std::size_t shared = 0, j = 0;
  for (const Chosen& c : a) {
    while (j < b.size() && b[j].column < c.column) ++j;
    if (j < b.size() && b[j].column == c.column &&
        std::abs(a_nodes[c.column][c.index].row - b_nodes[b[j].column][b[j].index].row) <=
            near_rows) {
      ++shared;
    }
  }
  return shared;
}

}  // namespace

TrackGrid MakeTrackGrid(const PreparedPhoto& photo, const GraticuleFit& graticule,
                        const TraceOptions& options) {
  TrackGrid grid;
  grid.px_per_div = options.track_px_per_div > 0.0
                        ? options.track_px_per_div
                        : std::clamp(std::round(graticule.px_per_div / photo.shrink), 12.0, 80.0);
  grid.columns = static_cast<int>(std::lround(graticule.divisions[0] * grid.px_per_div)) + 1;
  return grid;
}

bool Claims::Taken(int column, double y_div) const {
  for (const auto& [y, half_width] : taken[column]) {
    if (std::abs(y_div - y) <= half_width) return true;
  }
  return false;
}

CoarsePath TrackTrace(const PreparedPhoto& photo, const GraticuleFit& graticule,
                      const TraceSettings& settings, const TraceOptions& options,
                      const TrackGrid& grid, const Claims& claims, bool off_grid_rows, bool one_way,
                      std::optional<Chopper> beam_chopper) {
  Strip strip = CutStrip(photo, graticule.mapping, graticule.divisions, settings, grid);
  const double line_height = SuppressGrid(strip, graticule.divisions, graticule.dotted);
  const cv::Mat1f& image = strip.image;

  // The noise, from every third value (plenty, and a third of the work).
  std::vector<float> all;
  all.reserve(image.total() / 3 + 1);
  for (int r = 0; r < image.rows; ++r) {
    const float* p = image.ptr<float>(r);
    for (int c = r % 3; c < image.cols; c += 3) all.push_back(p[c]);
  }
  const double median = MedianOf(all);
  for (float& v : all) v = std::abs(v - static_cast<float>(median));
  const double sigma = 1.4826 * MedianOf(all);
  // A peak stands out of the noise. Where a grid line or a centre axis's tick
  // marks lie, what the suppression left of them may peak too, so a trace
  // there must outshine the lines; elsewhere nothing but the traces, dirt and
  // noise draws on the face, and a trace's faint stretches (a fast beam's
  // steep flanks, short dashes) count down to the noise floor.
  const double noise_floor = std::max(6.0 * sigma, 1e-3);
  const double grid_floor = std::max(noise_floor, 1.2 * line_height);
  const GridNeighbourhood near_grid(graticule.divisions, grid.px_per_div);
  // Beside a point the user gave, any peak is a candidate: the user has seen
  // the trace there, however faint, or wherever a grid line runs.
  const HintedPoints hints(settings, graticule.mapping, strip, grid);
  // A horizontal grid line's row: within a line's width of it (at least a
  // strip pixel and a half), where a grid line's own peaks lie.
  const double row_reach_div =
      std::max(1.5 / grid.px_per_div, graticule.line_width_px / graticule.px_per_div);
  const auto on_grid_row = [&](double y_div) {
    const double from_line = y_div + 0.5 * graticule.divisions[1];
    return std::abs(from_line - std::round(from_line)) <= row_reach_div;
  };

  // Each column's peaks, read down the columns laid out as rows.
  const cv::Mat1f across = image.t();
  std::vector<std::vector<Node>> columns(grid.columns);
  std::vector<float> column_maxima;
  for (int c = 0; c < image.cols; ++c) {
    std::vector<Node>& nodes = columns[c];
    const float* column = across.ptr<float>(c);
    for (int r = 1; r + 1 < image.rows; ++r) {
      const float v = column[r];
      if (!(v > 0.0f && v > column[r - 1] && v >= column[r + 1])) continue;
      const double a = column[r - 1], b = v, d = column[r + 1];
      const double curvature = a - 2.0 * b + d;
      const double row = r + (curvature < 0.0 ? 0.5 * (a - d) / curvature : 0.0);
      if (!hints.empty() && hints.Fenced(c, row)) continue;
      const double hint_reward = hints.empty() ? 0.0 : hints.Reward(c, row);
      if (hint_reward == 0.0) {
        if (v <= noise_floor) continue;
        if (v <= grid_floor && near_grid(grid.XOf(c), strip.YOf(row))) continue;
      }
      if (claims.Taken(c, strip.YOf(row))) continue;
      if (off_grid_rows && hint_reward == 0.0 && on_grid_row(strip.YOf(row))) continue;
      nodes.push_back({c, row, v, hint_reward});
    }
    // The brightest few, and every hinted one.
    std::sort(nodes.begin(), nodes.end(), [](const Node& x, const Node& y) {
      return std::pair(x.hint_reward > 0.0, x.value) > std::pair(y.hint_reward > 0.0, y.value);
    });
    const auto hinted = std::count_if(nodes.begin(), nodes.end(),
                                      [](const Node& n) { return n.hint_reward > 0.0; });
    const auto keep = static_cast<std::size_t>(kCandidatesPerColumn + hinted);
    if (nodes.size() > keep) nodes.resize(keep);
    float brightest = 0.0f;
    for (const Node& n : nodes) {
      if (n.hint_reward == 0.0) brightest = std::max(brightest, n.value);
    }
    if (brightest > 0.0f) column_maxima.push_back(brightest);
  }
  CoarsePath path;
  path.grid = grid;
  path.y_div.assign(grid.columns, CoarsePath::kNone);
  path.peak.assign(grid.columns, 0.0f);
  path.link.assign(grid.columns, CoarsePath::kOnCourse);
  if (column_maxima.empty()) return path;
  const double level = QuantileOf(column_maxima, 0.8);
  path.level = level;
  path.floor = std::max(noise_floor, 0.3 * level);
  for (std::vector<Node>& nodes : columns) {
    std::erase_if(nodes,
                  [&](const Node& n) { return n.value < path.floor && n.hint_reward == 0.0; });
  }

  // Dynamic programming over the columns; once more without what a chopped
  // trace's course took of a continuous line crossing it.
  const bool step_trace = settings.impact.has_value();
  const int max_gap =
      std::max(1, static_cast<int>(std::lround(options.max_gap_div * grid.px_per_div)));
  // The course, and the candidates it was last sought on when not all of
  // them, sought one way (OneWay) or any way.
  struct Search {
    std::vector<Chosen> chosen;
    std::vector<std::vector<Node>> kept;
  };
  const auto search = [&](const OneWay& way) {
    const auto best_course = [&](const std::vector<std::vector<Node>>& nodes) {
      return BestCourse(nodes, grid, level, step_trace, max_gap, way);
    };
    std::vector<Chosen> chosen = best_course(columns);
    // The candidates the course was last sought on, when not all of them.
    std::vector<std::vector<Node>> kept;
    if (!step_trace) {
      // Without the lines it took that run on beyond the face; again while the
      // course sought anew takes another.
      const ThroughLines through(photo, graticule, strip, grid, noise_floor);
      for (int round = 0; round < kRounds; ++round) {
        std::vector<std::vector<Node>> cleared = kept.empty() ? columns : kept;
        const int found = through.Withdraw(chosen, cleared);
        if (found == 0) break;
        chosen = best_course(cleared);
        kept = std::move(cleared);
      }
    }
    if (!step_trace) {
      const std::vector<std::vector<Node>>& before = kept.empty() ? columns : kept;
      const std::vector<Chosen> suspect = ForeignRuns(chosen, beam_chopper);
      if (!suspect.empty()) {
        std::vector<std::vector<Node>> without_runs = before;
        // One candidate per column at most: erasing it leaves the others valid.
        for (const Chosen& f : suspect) {
          without_runs[f.column].erase(without_runs[f.column].begin() + f.index);
        }
        std::vector<Chosen> without = best_course(without_runs);
        // Foreign only if the course found without the run runs elsewhere
        // there: where it passes the same way, the run was the trace's own.
        if (RunsElsewhere(without, without_runs, suspect, before, kAwayDiv * grid.px_per_div)) {
          chosen = std::move(without);
          kept = std::move(without_runs);
        }
      }
    }
    if (!step_trace) {
      // Once more without an excursion onto something beside the trace; and
      // again while the course sought anew takes another (a ring's other arc,
      // a second label), a few times at most.
      for (int round = 0; round < kRounds; ++round) {
        const std::vector<std::vector<Node>>& before = kept.empty() ? columns : kept;
        const std::vector<Chosen> stray =
            StrayExcursions(chosen, before, kStrayJumpDiv * grid.px_per_div);
        if (stray.empty()) break;
        std::vector<std::vector<Node>> cleared =
            WithoutCandidatesNear(before, stray, kStrayClearDiv * grid.px_per_div);
        chosen = best_course(cleared);
        kept = std::move(cleared);
      }
      // Then the excursions reached or left by jumps across gaps the course
      // bridged on course.
      for (int round = 0; round < kRounds; ++round) {
        const std::vector<std::vector<Node>>& before = kept.empty() ? columns : kept;
        const std::vector<Chosen> stray =
            GapExcursions(chosen, before, grid.px_per_div, kGapJumpDiv * grid.px_per_div);
        if (stray.empty()) break;
        std::vector<std::vector<Node>> cleared =
            WithoutCandidatesNear(before, stray, std::max(1.5, kGapClearDiv * grid.px_per_div));
        std::vector<Chosen> again = best_course(cleared);
        // The course sought again is taken only where it changed about the
        // excursions: a jump judged on a trace's own faint, broken stretch
        // can send the whole course elsewhere, and the course it had there
        // was its best.
        if (!SameAwayFrom(chosen, before, again, cleared, stray,
                          static_cast<int>(std::lround(kGapNearDiv * grid.px_per_div)))) {
          break;
        }
        chosen = std::move(again);
        kept = std::move(cleared);
      }
    }
    return Search{std::move(chosen), std::move(kept)};
  };
  Search found = search(OneWay{});
  // A one-way trace's course (a calibration's), where the digitizer asks for
  // one (TraceOptions::one_way_courses: its reading turned back), is sought
  // never turning back by more than a reading's noise, up the screen or
  // down it: the way that keeps more of the course sought any way (the way
  // that merely pays better may be a bright scratch's across a faint
  // trace).
  if (one_way && options.one_way_courses && !step_trace) {
    const auto nodes_of = [&](const Search& s) -> const std::vector<std::vector<Node>>& {
      return s.kept.empty() ? columns : s.kept;
    };
    OneWay way;
    way.back_rows = std::max(kOneWayBackMinRows, kOneWayBackDiv * grid.px_per_div);
    std::optional<Search> best_way;
    std::size_t most_kept = 0;
    for (const int d : {1, -1}) {
      way.direction = d;
      Search course = search(way);
      const std::size_t shared = SharedColumns(found.chosen, nodes_of(found), course.chosen,
                                               nodes_of(course), kOneWayBackMinRows);
      if (!best_way || shared > most_kept) most_kept = shared, best_way = std::move(course);
    }
    found = std::move(*best_way);
  }
  const std::vector<Chosen>& chosen = found.chosen;
  const std::vector<std::vector<Node>>& kept = found.kept;
  const std::vector<std::vector<Node>>& used = kept.empty() ? columns : kept;
  for (const Chosen& c : chosen) {
    const Node& node = used[c.column][c.index];
    path.y_div[c.column] = strip.YOf(node.row);
    path.peak[c.column] = node.value;
    path.link[c.column] = c.link;
    ++path.seen_columns;
  }
  return path;
}

std::optional<Chopper> ChopperOf(const CoarsePath& path) {
  std::vector<Chosen> course;
  for (int c = 0; c < path.grid.columns; ++c) {
    if (!std::isnan(path.y_div[static_cast<std::size_t>(c)])) {
      course.push_back({c, 0, path.link[static_cast<std::size_t>(c)]});
    }
  }
  return ChopperOf(course);
}

void Claim(const CoarsePath& path, double half_width_div, Claims& claims) {
  const int columns = static_cast<int>(path.y_div.size());
  int previous = -1;
  for (int c = 0; c < columns; ++c) {
    if (std::isnan(path.y_div[c])) continue;
    claims.taken[c].emplace_back(path.y_div[c], half_width_div);
    if (previous >= 0 && path.link[c] != CoarsePath::kRestart) {
      const double y0 = path.y_div[previous], y1 = path.y_div[c];
      const bool step = path.link[c] == CoarsePath::kStep;
      // A step's edge takes everything between its levels, from the last
      // column of one level to the first of the other.
      for (int k = step ? previous : previous + 1; k < c || (step && k == c); ++k) {
        if (step) {
          claims.taken[k].emplace_back(0.5 * (y0 + y1), 0.5 * std::abs(y1 - y0) + half_width_div);
        } else {
          const double f = static_cast<double>(k - previous) / (c - previous);
          claims.taken[k].emplace_back(y0 + f * (y1 - y0), half_width_div);
        }
      }
    }
    previous = c;
  }
}

}  // namespace impactlab::digitize
