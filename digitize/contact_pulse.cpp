// MeasurePulse: the contact trace's levels from its samples, its edges from
// the photo. A contact circuit switches in about a microsecond, far faster
// than the sweep, so the beam writes each edge as a faint vertical stroke
// between the levels; its centre at half height is the edge's time.
//
// The stroke is often within a line's width of a vertical grid line (a
// delayed sweep starts on one), and it is several times fainter than the
// line. A centre from the profile's half maximum or its symmetry then takes
// part of the line's light for the stroke's, and a line whose height is left
// free swallows a stroke lying on it. So the profile across the stroke is
// fitted as a model (contact_stroke.h): a straight background, the grid
// line's own profile as read where the stroke is not (rows beyond the
// levels), scaled by how much brighter the neighbouring grid lines are at
// the stroke's height than there, and the stroke.
//
// The levels' ends time each edge too (level_jump.h): the bright level the
// beam leaves ends where the one it reaches begins, and a grid line both
// rows cross cancels in their difference. The two measures are weighed by
// their variances.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>

#include "digitize/contact_stroke.h"
#include "digitize/digitize.h"
#include "digitize/ink_sampler.h"
#include "digitize/interpolate.h"
#include "digitize/level_jump.h"
#include "digitize/line_profile.h"
#include "digitize/screen_geometry.h"
#include "digitize/select.h"

namespace impactlab {

namespace {

using digitize::CatmullRom;
using digitize::FitStroke;
using digitize::GridCrossings;
using digitize::ImageFromScreen;
using digitize::InkSampler;
using digitize::Median;
using digitize::Profile;
using digitize::ReadProfile;
using digitize::ScreenFromPixel;
using digitize::StrokeFit;
using digitize::StrokeNeighbour;
using digitize::StrokeSearch;

// An edge as measured: its time (screen divisions while measured, seconds
// once finished) and sigma, and where it lies in the photo.
struct PulseEdge {
  double time_s = 0.0;      // where the beam crosses half way between the levels
  double sigma_s = 0.0;     // one standard deviation
  cv::Point2d centre_px;    // the crossing in the photo
  bool from_image = false;  // measured in the photo (the stroke, the levels' ends), else put
                            // between the last samples of each level
};

double QuantileOfCopy(std::vector<double> values, double q) {
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * (values.size() - 1));
  return digitize::SelectNth(values.begin(), at, values.end());
}

// Splits the heights into two groups with the largest between-group variance
// (Otsu); returns the two groups' medians, low first.
std::optional<std::pair<double, double>> TwoLevels(std::vector<double> y) {
  const std::size_t n = y.size();
  if (n < 10) return std::nullopt;
  std::sort(y.begin(), y.end());
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + y[i];
  double best = -1.0;
  std::size_t split = 0;
  const std::size_t least = std::max<std::size_t>(3, n / 20);
  for (std::size_t k = least; k + least <= n; ++k) {
    const double m0 = prefix[k] / k, m1 = (prefix[n] - prefix[k]) / (n - k);
    const double between = static_cast<double>(k) * (n - k) * (m1 - m0) * (m1 - m0);
    if (between > best) best = between, split = k;
  }
  if (split == 0) return std::nullopt;
  return std::make_pair(y[(split - 1) / 2], y[split + (n - split) / 2]);
}

// A profile's noise: the robust scatter of differences two pixels apart (four
// samples; nearer ones share pixels) in its outer fifths, which a slope of
// the background does not inflate.
double ProfileNoise(const std::vector<double>& values) {
  constexpr std::size_t kLag = 4;
  const std::size_t n = values.size(), fifth = std::max<std::size_t>(kLag + 2, n / 5);
  std::vector<double> differences;
  for (std::size_t i = 0; i + kLag < fifth && i + kLag < n; ++i) {
    differences.push_back(std::abs(values[i + kLag] - values[i]));
    differences.push_back(std::abs(values[n - 1 - i] - values[n - 1 - i - kLag]));
  }
  if (differences.empty()) return 1e-6;
  return 1.4826 * Median(differences) / std::sqrt(2.0) + 1e-6;
}

// Profiles along the sweep (the screen's x) centred on screen x `x_div`, one
// per photo row between screen heights y0 and y1, all with the same offsets
// (so a vertical line sits at the same offset in every one). Rows along a
// horizontal grid line or a minor tick are left out: their light is not the
// screen's, and where lines cross the graticule is no sum of its lines.
struct Rows {
  std::vector<double> offsets;
  std::vector<std::vector<double>> values;
  std::vector<double> y_div;

  int size() const { return static_cast<int>(values.size()); }

  // The mean of rows [from, to) and their mean height.
  std::vector<double> Mean(int from, int to, double* y) const {
    std::vector<double> mean(offsets.size(), 0.0);
    *y = 0.0;
    for (int r = from; r < to; ++r) {
      for (std::size_t i = 0; i < mean.size(); ++i) mean[i] += values[r][i];
      *y += y_div[r];
    }
    for (double& v : mean) v /= (to - from);
    *y /= (to - from);
    return mean;
  }
};

class RowReader {
 public:
  RowReader(const InkSampler& ink, const GraticuleFit& graticule, const GridCrossings& grid)
      : ink_(ink), graticule_(graticule), grid_(grid), screen_from_pixel_(graticule.mapping) {}

  Rows Read(double x_div, double y0, double y1, int count, double half_length_px) const {
    const GraticuleMapping& mapping = graticule_.mapping;
    const double half_ny = 0.5 * graticule_.divisions[1];
    // A horizontal line's light reaches 1.5 of its widths either side.
    const double line_clear_div = 1.5 * graticule_.line_width_px / graticule_.px_per_div;
    Rows rows;
    if (!(y1 > y0) || count < 1) return rows;
    for (int j = 0; j < count; ++j) {
      const double y = y0 + (y1 - y0) * (j + 0.5) / count;
      if (std::abs((y + half_ny) - std::round(y + half_ny)) < line_clear_div) continue;
      Profile p = ReadProfile(ink_, ImageFromScreen(mapping, {x_div, y}), Along(x_div, y),
                              half_length_px, 0.5);
      const int n = static_cast<int>(p.values.size());
      grid_.AddTo(p, screen_from_pixel_(p.PointAt(p.OffsetAt(0))),
                  screen_from_pixel_(p.PointAt(p.OffsetAt(n - 1))));
      if (p.BesideShortLine()) continue;
      if (rows.offsets.empty()) {
        for (int i = 0; i < n; ++i) rows.offsets.push_back(p.OffsetAt(i));
      }
      rows.values.emplace_back(p.values.begin(), p.values.end());
      rows.y_div.push_back(y);
    }
    return rows;
  }

  // The unit vector along the screen's x at a screen point, in the photo.
  cv::Point2d Along(double x_div, double y_div) const {
    constexpr double kDeltaDiv = 0.01;
    const cv::Point2d d = ImageFromScreen(graticule_.mapping, {x_div + kDeltaDiv, y_div}) -
                          ImageFromScreen(graticule_.mapping, {x_div - kDeltaDiv, y_div});
    return d / cv::norm(d);
  }

  // The profile at screen (x_div, y_div) with the grid lines that cross it.
  Profile Crossed(double x_div, double y_div, const std::vector<double>& offsets) const {
    Profile p;
    p.origin_px = graticule_.mapping.ImageFromScreen({x_div, y_div});
    p.direction = Along(x_div, y_div);
    p.start_px = offsets.front();
    p.step_px = offsets[1] - offsets[0];
    p.values.assign(offsets.size(), 0.0f);
    grid_.AddTo(p, screen_from_pixel_(p.PointAt(offsets.front())),
                screen_from_pixel_(p.PointAt(offsets.back())));
    return p;
  }

  double ScreenX(const Profile& p, double offset_px) const {
    return screen_from_pixel_(p.PointAt(offset_px)).x;
  }

 private:
  const InkSampler& ink_;
  const GraticuleFit& graticule_;
  const GridCrossings& grid_;
  ScreenFromPixel screen_from_pixel_;
};

// The straight background of a profile through the medians of its outer
// fifths, at each sample.
std::vector<double> LinearBackground(const std::vector<double>& v) {
  const int n = static_cast<int>(v.size()), fifth = std::max(1, n / 5);
  const double left = Median(std::vector<double>(v.begin(), v.begin() + fifth));
  const double right = Median(std::vector<double>(v.end() - fifth, v.end()));
  const double i_left = 0.5 * (fifth - 1), i_right = n - 1 - 0.5 * (fifth - 1);
  std::vector<double> b(n);
  for (int i = 0; i < n; ++i) b[i] = left + (right - left) * (i - i_left) / (i_right - i_left);
  return b;
}

// A grid line's own light along a profile (ink above the screen), from rows
// where nothing else is: each row less its straight background, the rows a
// trace runs through (their background well above the others') left out, and
// the median of the rest taken sample by sample. The part about the line is
// then taken less a straight baseline just beyond its reach (the rows'
// backgrounds are not quite straight), made symmetric about the centre it
// shows (a grid line is symmetric: this halves the noise and keeps the
// noise's asymmetry from passing for the stroke's), and nothing is kept
// beyond its reach. Empty when too few rows are clear.
std::vector<double> LineTemplate(const std::vector<Rows>& sources, const Profile::Crossing& line,
                                 double tolerance) {
  constexpr int kLeastRows = 8;
  std::vector<double> backgrounds;
  std::vector<std::pair<const std::vector<double>*, std::vector<double>>> candidates;
  if (sources.empty()) return {};
  for (const Rows& rows : sources) {
    for (const std::vector<double>& v : rows.values) {
      std::vector<double> b = LinearBackground(v);
      backgrounds.push_back(0.5 * (b.front() + b.back()));
      candidates.emplace_back(&v, std::move(b));
    }
  }
  if (static_cast<int>(candidates.size()) < kLeastRows) return {};
  const double limit = QuantileOfCopy(backgrounds, 0.25) + tolerance;
  std::vector<const std::pair<const std::vector<double>*, std::vector<double>>*> clear;
  for (std::size_t r = 0; r < candidates.size(); ++r) {
    if (backgrounds[r] <= limit) clear.push_back(&candidates[r]);
  }
  if (static_cast<int>(clear.size()) < kLeastRows) return {};
  const std::vector<double>& offsets = sources.front().offsets;
  const int n = static_cast<int>(offsets.size());
  const double r1 = 1.5 * line.fwhm_px + 1.0, r2 = r1 + 4.0;
  // The median where the template is read: within r2 (and the symmetry's
  // search) of the line.
  std::vector<double> median(n, 0.0), column(clear.size());
  for (int i = 0; i < n; ++i) {
    if (std::abs(offsets[i] - line.offset_px) > r2 + 2.0) continue;
    for (std::size_t r = 0; r < clear.size(); ++r) {
      column[r] = (*clear[r]->first)[i] - clear[r]->second[i];
    }
    median[i] = Median(column);
  }
  double s1 = 0, su = 0, sv = 0, suu = 0, suv = 0;
  for (int i = 0; i < n; ++i) {
    const double u = offsets[i] - line.offset_px;
    if (std::abs(u) < r1 || std::abs(u) > r2) continue;
    s1 += 1, su += u, sv += median[i], suu += u * u, suv += u * median[i];
  }
  double a = 0.0, b = 0.0;
  if (s1 >= 2) {
    const double det = s1 * suu - su * su;
    if (std::abs(det) > 1e-12) b = (s1 * suv - su * sv) / det;
    a = (sv - b * su) / s1;
  }
  std::vector<double> part(n, 0.0);
  for (int i = 0; i < n; ++i) {
    const double u = offsets[i] - line.offset_px;
    if (std::abs(u) <= r2) part[i] = median[i] - (a + b * u);
  }
  const double step = offsets[1] - offsets[0];
  auto at = [&](double u) { return CatmullRom(part, (u - offsets.front()) / step); };
  auto asymmetry = [&](double m) {
    double sum = 0.0;
    for (double d = step; d <= r1; d += step) {
      const double diff = at(m + d) - at(m - d);
      sum += diff * diff;
    }
    return sum;
  };
  // The centre it shows: the least asymmetry within 1.5 px of where the
  // mapping puts it, then a parabola.
  constexpr double kStep = 0.05;
  double m = line.offset_px, best = asymmetry(m);
  for (int k = -30; k <= 30; ++k) {
    const double f = asymmetry(line.offset_px + k * kStep);
    if (f < best) best = f, m = line.offset_px + k * kStep;
  }
  const double fa = asymmetry(m - kStep), fb = asymmetry(m + kStep);
  const double curvature = fa - 2.0 * best + fb;
  if (curvature > 0.0) m += 0.5 * kStep * std::clamp((fa - fb) / curvature, -1.0, 1.0);
  std::vector<double> shape(n, 0.0);
  for (int i = 0; i < n; ++i) {
    const double u = offsets[i] - m;
    if (std::abs(u) > r1) continue;
    // A short taper, so that the template has no step at its ends.
    const double taper = std::clamp((r1 - std::abs(u)) / 1.5, 0.0, 1.0);
    shape[i] = taper * 0.5 * (at(offsets[i]) + at(2.0 * m - offsets[i]));
  }
  return shape;
}

// Least squares of `values` = a + b u + scale * shape: the scale.
double ShapeScale(const std::vector<double>& offsets, const std::vector<double>& values,
                  const std::vector<double>& shape) {
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0.0, 0.0, 0.0);
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    const cv::Vec3d basis(1.0, offsets[i], shape[i]);
    normal += basis * basis.t();
    rhs += values[i] * basis;
  }
  cv::Vec3d a;
  if (!cv::solve(normal, rhs, a, cv::DECOMP_CHOLESKY)) return std::nan("");
  return a[2];
}

// Where the stroke rows lie (screen heights, rows read) and how the
// reference rows beyond the levels are read.
struct RowPlan {
  double y0 = 0.0, y1 = 0.0;  // the stroke's rows
  int count = 0;
  double bottom = 0.0, top = 0.0;  // the levels
  double clear = 0.0;              // reference rows start this far beyond them
  double reach = 0.0;              // and run this far
  int reference_count = 0;
  double tolerance = 0.0;  // a reference row's background this far above the lower quartile
                           // has a trace in it
};

// The reference rows above and below the levels at screen x `x_div`
// (profiles `length` either side), those there are.
std::vector<Rows> ReferenceRows(const RowReader& reader, const GraticuleFit& graticule,
                                const RowPlan& plan, double x_div, double length) {
  const double half_ny = 0.5 * graticule.divisions[1];
  std::vector<Rows> sides;
  sides.push_back(reader.Read(x_div, plan.top + plan.clear,
                              std::min(plan.top + plan.clear + plan.reach, half_ny),
                              plan.reference_count, length));
  sides.push_back(reader.Read(x_div, std::max(plan.bottom - plan.clear - plan.reach, -half_ny),
                              plan.bottom - plan.clear, plan.reference_count, length));
  sides.erase(
      std::remove_if(sides.begin(), sides.end(), [](const Rows& r) { return r.size() == 0; }),
      sides.end());
  return sides;
}

// How the grid lines the stroke's profile crosses enter its fit. Each is its
// own profile read in the reference rows, where the stroke is not. Lighting
// (vignetting, glare) and the photo's tone curve make a line brighter or
// fainter from one height to another, and a stroke lying on a line is told
// from it only by how much brighter the line looks than it should: so the
// nearest line's scale is drawn towards the one the grid lines a division
// either side (which the stroke does not touch) show between the stroke's
// rows and the reference rows. A line without clear reference rows is a
// Gaussian where the mapping puts it, of free height.
std::vector<StrokeNeighbour> LineNeighbours(const RowReader& reader, const GraticuleFit& graticule,
                                            const RowPlan& plan, const Profile& whole, double x_div,
                                            double half_length) {
  std::vector<double> offsets(whole.values.size());
  for (std::size_t i = 0; i < offsets.size(); ++i) offsets[i] = whole.OffsetAt(static_cast<int>(i));
  std::vector<StrokeNeighbour> neighbours;
  const Profile::Crossing* nearest = nullptr;
  for (const Profile::Crossing& c : whole.crossings) {
    if (nearest == nullptr || std::abs(c.offset_px) < std::abs(nearest->offset_px)) nearest = &c;
  }
  const std::vector<Rows> reference =
      whole.crossings.empty() ? std::vector<Rows>{}
                              : ReferenceRows(reader, graticule, plan, x_div, half_length);
  for (const Profile::Crossing& c : whole.crossings) {
    StrokeNeighbour line;
    line.shape = LineTemplate(reference, c, plan.tolerance);
    if (line.shape.empty()) {
      line.shape = digitize::GaussianShape(offsets, c.offset_px, c.fwhm_px);
      neighbours.push_back(std::move(line));
      continue;
    }
    if (&c == nearest) {
      std::vector<double> scales;
      const int nx = graticule.divisions[0];
      const double length = 3.0 * graticule.line_width_px + 8.0;
      const double x_line = std::round(reader.ScreenX(whole, c.offset_px));
      for (const double x : {x_line - 1.0, x_line + 1.0}) {
        if (x < 0.0 || x > nx) continue;
        const Rows rows = reader.Read(x, plan.y0, plan.y1, plan.count, length);
        if (rows.size() < 2) continue;
        double y = 0.0;
        const std::vector<double> mean = rows.Mean(0, rows.size(), &y);
        const Profile p = reader.Crossed(x, y, rows.offsets);
        const Profile::Crossing* own = nullptr;
        for (const Profile::Crossing& k : p.crossings) {
          if (std::abs(k.offset_px) < 0.5 * length) own = &k;
        }
        if (own == nullptr) continue;
        const std::vector<double> shape =
            LineTemplate(ReferenceRows(reader, graticule, plan, x, length), *own, plan.tolerance);
        if (shape.empty()) continue;
        const double scale = ShapeScale(rows.offsets, mean, shape);
        if (std::isfinite(scale) && scale > 0.0) scales.push_back(scale);
      }
      // Without them, about as bright as in the reference rows.
      line.prior = 1.0;
      line.prior_sigma = 0.1;
      if (!scales.empty()) {
        const double mean = std::accumulate(scales.begin(), scales.end(), 0.0) / scales.size();
        double spread = 0.0;
        for (double s : scales) spread = std::max(spread, std::abs(s - mean));
        // Two lines a division apart agree to a few percent at best.
        line.prior = mean;
        line.prior_sigma = std::max(0.03, spread);
      }
    }
    neighbours.push_back(std::move(line));
  }
  // The nearest line first: its scale is the one the caller checks.
  if (nearest != nullptr) {
    std::swap(neighbours.front(), neighbours[nearest - whole.crossings.data()]);
  }
  return neighbours;
}

struct StrokeEdge {
  PulseEdge edge;  // time_s and sigma_s in screen divisions
  double fwhm_px = 0.0, height = 0.0;
  double separation = HUGE_VAL;              // to the nearest grid line, in the two's mean widths
  bool line_as_expected = true;              // the nearest line's scale within its prior's reach
  bool line_measured = true;                 // the nearest line's profile read, not assumed
  double lean = 0.0, lean_sigma = HUGE_VAL;  // dx/dy across the bands, screen divisions
  // The bands lean far more than a contact edge can: a line crossing the
  // levels (a hair, a hand-drawn ring's arc), not the beam's stroke.
  bool crossing_line = false;
};

// What the pulse's other edge showed: the same beam at the same speed draws
// a stroke of about the same width and height.
struct StrokeHint {
  double fwhm_px = 0.0, height = 0.0;
};

// What an edge's fit needs of the photo, read once (a second fit with the
// other edge's hint reads nothing again).
struct StrokeData {
  double guess_div = 0.0, mid_div = 0.0;
  double px_per_div = 0.0, reach_px = 0.0, width_px = 0.0;
  double half_length_px = 0.0;  // of every profile read
  double step_widths = 0.0;     // the levels' distance in trace widths
  Rows rows;                    // the stroke's rows
  std::vector<double> total;    // their mean
  double total_y = 0.0;         // and its height
  Profile whole;                // the mean as a profile, with the lines it crosses
  std::vector<StrokeNeighbour> neighbours;
};

// Every photo row in the middle half between the levels, read along the
// sweep about screen x `guess_div` (the search `reach_div` either side and
// room beyond), and the grid lines the rows cross. Nullopt without rows.
std::optional<StrokeData> ReadStroke(const RowReader& reader, const GraticuleFit& graticule,
                                     double guess_div, double reach_div, double low_div,
                                     double high_div, double width_px) {
  StrokeData d;
  d.guess_div = guess_div;
  d.mid_div = 0.5 * (low_div + high_div);
  d.width_px = width_px;
  const cv::Point2d step = graticule.mapping.ImageFromScreen({guess_div + 0.01, d.mid_div}) -
                           graticule.mapping.ImageFromScreen({guess_div - 0.01, d.mid_div});
  d.px_per_div = cv::norm(step) / 0.02;
  d.reach_px = reach_div * d.px_per_div;
  // Room beyond the search for the stroke's flanks and a grid line beside it.
  const double half_length = d.reach_px + std::max(4.0 * width_px, 12.0);
  d.half_length_px = half_length;
  const double span = std::abs(high_div - low_div);
  d.step_widths = span * d.px_per_div / std::max(width_px, 1.0);
  RowPlan plan;
  plan.bottom = std::min(low_div, high_div);
  plan.top = std::max(low_div, high_div);
  // The middle half between the levels: clear of the corners' glow.
  plan.y0 = plan.bottom + 0.25 * span;
  plan.y1 = plan.top - 0.25 * span;
  plan.count = std::clamp(static_cast<int>(0.5 * span * d.px_per_div), 12, 400);
  // Beyond the levels, clear of their glow; a row every two pixels is plenty
  // for a median, but no fewer than 40.
  plan.clear = 0.15 + 3.0 * width_px / d.px_per_div;
  plan.reach = 0.6;
  plan.reference_count = std::max(static_cast<int>(0.5 * plan.reach * d.px_per_div),
                                  std::min(static_cast<int>(plan.reach * d.px_per_div), 40));
  plan.tolerance = std::max(0.25 * graticule.line_contrast, 0.02);
  d.rows = reader.Read(guess_div, plan.y0, plan.y1, plan.count, half_length);
  if (d.rows.size() < 2) return std::nullopt;
  d.total = d.rows.Mean(0, d.rows.size(), &d.total_y);
  d.whole = reader.Crossed(guess_div, d.total_y, d.rows.offsets);
  d.whole.values.assign(d.total.begin(), d.total.end());
  d.neighbours = LineNeighbours(reader, graticule, plan, d.whole, guess_div, half_length);
  return d;
}

// Where the stroke crosses half height: fitted with the grid lines beside it
// on the mean of all rows, then band by band with that width, for the
// stroke's lean (which moves the centre read at half height when the rows'
// mean height is not there) and the scatter.
std::optional<StrokeEdge> FitEdge(const RowReader& reader, const GraticuleFit& graticule,
                                  const StrokeData& d, const StrokeHint* hint) {
  constexpr int kMaxBands = 6;
  const Rows& rows = d.rows;
  const int used = rows.size();
  const std::vector<double>& offsets = rows.offsets;
  const std::vector<double>& total = d.total;
  const std::vector<StrokeNeighbour>& neighbours = d.neighbours;
  const Profile& whole = d.whole;
  const double px_per_div = d.px_per_div, reach_px = d.reach_px, width_px = d.width_px;
  const double guess_div = d.guess_div, mid_div = d.mid_div, total_y = d.total_y;
  StrokeSearch search;
  search.centre_lo_px = -reach_px;
  search.centre_hi_px = reach_px;
  // No wider than the trace (the same beam, brighter), no narrower than a
  // sharp photo's stroke could be.
  search.fwhm_lo_px = std::max(1.2, 0.3 * width_px);
  search.fwhm_hi_px = std::max(3.0, width_px);
  if (hint != nullptr) {
    search.fwhm_lo_px = std::max(search.fwhm_lo_px, hint->fwhm_px / 1.25);
    search.fwhm_hi_px =
        std::max(search.fwhm_lo_px, std::min(search.fwhm_hi_px, 1.25 * hint->fwhm_px));
    search.height_lo = 0.4 * hint->height;
  }
  search.noise = ProfileNoise(total);
  StrokeFit stroke = FitStroke(offsets, total, neighbours, search);
  // The profile's own noise misses what is not white (JPEG blocks, grain,
  // the background's shape): what the fit leaves is the noise that weighs
  // the line's prior.
  if (stroke.height > 0.0 && !neighbours.empty() &&
      std::abs(stroke.residual_rms - search.noise) > 0.3 * search.noise) {
    search.noise = stroke.residual_rms;
    stroke = FitStroke(offsets, total, neighbours, search);
  }
  // A stroke must stand out of what the model leaves unexplained.
  if (!stroke.found || stroke.height < 4.0 * stroke.residual_rms) return std::nullopt;
  const double total_x = reader.ScreenX(whole, stroke.centre_px);

  StrokeEdge out;
  out.fwhm_px = stroke.fwhm_px;
  out.height = stroke.height;
  for (const Profile::Crossing& c : whole.crossings) {
    out.separation = std::min(out.separation, std::abs(c.offset_px - stroke.centre_px) /
                                                  (0.5 * (stroke.fwhm_px + c.fwhm_px)));
  }
  // A line without a profile of its own (no clear rows beyond the levels)
  // has a free height: a stroke on it is not told from it.
  out.line_measured = neighbours.empty() || neighbours[0].prior_sigma > 0.0;
  if (!neighbours.empty() && neighbours[0].prior_sigma > 0.0 && !stroke.neighbour_scales.empty()) {
    out.line_as_expected = std::abs(stroke.neighbour_scales[0] - neighbours[0].prior) <=
                           3.0 * neighbours[0].prior_sigma;
  }

  // The fit's own noise, the residuals' correlation allowed for.
  double sigma_px = stroke.residual_rms * stroke.centre_per_noise_px * stroke.correlation;
  // Band by band with the stroke's width.
  std::vector<double> xs, ys;
  const int bands = std::min(kMaxBands, used / 2);
  StrokeSearch band_search = search;
  band_search.fwhm_lo_px = band_search.fwhm_hi_px = stroke.fwhm_px;
  band_search.centre_lo_px = std::max(search.centre_lo_px, stroke.centre_px - stroke.fwhm_px);
  band_search.centre_hi_px = std::min(search.centre_hi_px, stroke.centre_px + stroke.fwhm_px);
  band_search.noise = search.noise * std::sqrt(static_cast<double>(bands));
  band_search.height_lo = 0.0;
  for (int b = 0; b < bands && bands >= 4; ++b) {
    double y = 0.0;
    const std::vector<double> values = rows.Mean(b * used / bands, (b + 1) * used / bands, &y);
    const StrokeFit band = FitStroke(offsets, values, neighbours, band_search);
    if (!band.found || band.height < 0.3 * stroke.height) continue;
    Profile p = whole;
    p.origin_px = graticule.mapping.ImageFromScreen({guess_div, y});
    xs.push_back(reader.ScreenX(p, band.centre_px));
    ys.push_back(y);
  }
  out.edge.from_image = true;
  out.edge.time_s = total_x;  // screen x for now
  if (xs.size() >= 4) {
    const double my = std::accumulate(ys.begin(), ys.end(), 0.0) / ys.size();
    const double mx = std::accumulate(xs.begin(), xs.end(), 0.0) / xs.size();
    double syy = 0.0, sxy = 0.0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
      syy += (ys[i] - my) * (ys[i] - my);
      sxy += (xs[i] - mx) * (ys[i] - my);
    }
    const double lean = sxy / syy;  // dx/dy
    out.lean = lean;
    double rss = 0.0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
      const double r = xs[i] - (mx + lean * (ys[i] - my));
      rss += r * r;
    }
    const double scatter = std::sqrt(rss / (xs.size() - 2));
    // A contact edge leans little (a microsecond's switching is a few
    // hundredths of a division across the pulse's height): a lean the bands'
    // scatter does not pin down is shrunk towards none.
    constexpr double kLeanPrior = 0.05;  // dx/dy
    const double lean_variance = scatter * scatter / syy;
    out.lean_sigma = std::sqrt(lean_variance);
    // A contact edge leans by a few hundredths (an RC edge's settling by
    // about a tenth); a hair or a drawn ring's arc crossing the levels at a
    // slant leans by tenths (randomised seeds 1034's run 0.405 and 4023's run
    // 0.713: -0.58 and 0.59, to +-0.03).
    // The bands' rows lie a quarter of the step from each level; within 0.7
    // trace width of one they see its corner's glow, the leaving level's
    // on one side and the reaching level's on the other, which leans them
    // too (a 2.2-width step's stroke on a clean photo leans so): a lean is
    // only read where the rows are clear of that, a step of 2.8 widths.
    constexpr double kLeastCrossingLean = 0.25, kLeanSigmas = 3.0, kCornerClearSteps = 2.8;
    out.crossing_line = d.step_widths >= kCornerClearSteps &&
                        std::abs(lean) - kLeanSigmas * out.lean_sigma > kLeastCrossingLean;
    const double shrink = kLeanPrior * kLeanPrior / (kLeanPrior * kLeanPrior + lean_variance);
    const double lever = mid_div - total_y;
    out.edge.time_s = total_x + shrink * lean * lever;
    const double band_sigma_div =
        std::sqrt(scatter * scatter / xs.size() + lever * lever * shrink * lean_variance);
    sigma_px = std::max(sigma_px, band_sigma_div * px_per_div);
  }
  // Where the stroke overlaps a line the model is not exact (the tone curve,
  // the template's own noise): a share of the stroke's width, as large as
  // what the fit leaves unexplained is against the stroke's height. The
  // factor 3 keeps nine in ten edges 0-3 px from a line within 1.6 of their
  // sigmas in every photo style (measured against the renderer's truth).
  if (std::isfinite(out.separation)) {
    constexpr double kOverlapShare = 3.0;
    const double overlap = std::exp(-0.5 * out.separation * out.separation);
    sigma_px = std::hypot(
        sigma_px, kOverlapShare * stroke.residual_rms / stroke.height * stroke.fwhm_px * overlap);
  }
  out.edge.sigma_s = sigma_px / px_per_div;
  out.edge.centre_px = graticule.mapping.ImageFromScreen({out.edge.time_s, mid_div});
  return out;
}

// What the levels' ends say of an edge (level_jump.h).
struct JumpMeasure {
  // The antisymmetry's centre, when the levels step across it. It is the
  // edge's half-height crossing only where the reaching level begins where
  // the leaving one ends; an edge that settles slowly puts it later (below).
  std::optional<PulseEdge> mirror;
  // Where the reaching level begins less where the leaving one ends, photo
  // pixels (NaN where a row shows no step), and the first half of that
  // interval when it is positive (its middle, its length over sqrt 12).
  double gap_px = std::nan("");
  std::optional<PulseEdge> bound;
  // Where the leaving level ends and the reaching one begins, screen
  // divisions (NaN where a row shows no step): the beam is on a level
  // outside them.
  double leaving_end_div = std::nan(""), reaching_start_div = std::nan("");
};

// The edge where the beam leaves the level at `leaving_div` and reaches the
// one at `reaching_div` (level_jump.h): each level's mean profile across its
// trace's core, on the stroke rows' offsets. Nothing when a level has no
// clear rows (a horizontal grid line or minor ticks along it).
//
// The two rows are mirror images only when the reaching level begins where
// the leaving one ends. An edge that settles slowly (an RC exponential of a
// microsecond or two, a few hundredths of a division on a fast sweep)
// leaves its level at once but approaches the other one, which then begins
// 3-4 time constants later: the antisymmetry then lies between the two,
// later than the half-height crossing (on the external photos by 0.2-0.7 of
// the gap). The half-height crossing lies between the leaving level's end
// and the reaching level's beginning, and in its first half, since the
// trace leaves at once and settles slowly (an exponential crosses half
// height ln 2 / ln(step / half width), about a fifth, of the way; a linear
// ramp half way): that is `bound`. On switched edges (our renderer's
// standard scenes) the reaching row's half crossing lies 0.3-1 trace width
// before the leaving row's (each row sees the other's corner); on RC edges
// 1.3-2.6 widths after it (tests/digitize/contact_rc_test.cpp), 1-7 on the
// external photos.
JumpMeasure FitJump(const RowReader& reader, const GraticuleFit& graticule, const StrokeData& d,
                    double leaving_div, double reaching_div) {
  JumpMeasure out;
  const double half_width_div = 0.5 * d.width_px / d.px_per_div;
  const int count = std::max(1, static_cast<int>(std::lround(2.0 * d.width_px)));
  std::vector<double> profiles[2];
  int k = 0;
  for (const double level : {leaving_div, reaching_div}) {
    const Rows rows = reader.Read(d.guess_div, level - half_width_div, level + half_width_div,
                                  count, d.half_length_px);
    if (rows.size() == 0 || rows.offsets != d.rows.offsets) return out;
    double y = 0.0;
    profiles[k++] = rows.Mean(0, rows.size(), &y);
  }
  digitize::LevelJumpSearch search;
  search.centre_lo_px = -d.reach_px;
  search.centre_hi_px = d.reach_px;
  search.half_window_px = 2.0 * d.width_px + 2.0;
  for (const StrokeNeighbour& line : d.neighbours) search.lines.push_back(line.shape);
  const digitize::LevelJump jump =
      digitize::FitLevelJump(d.rows.offsets, profiles[0], profiles[1], search);
  auto edge_at = [&](double offset_px, double sigma_px) {
    PulseEdge edge;
    edge.from_image = true;
    edge.time_s = reader.ScreenX(d.whole, offset_px);  // screen x for now
    edge.sigma_s = sigma_px / d.px_per_div;
    edge.centre_px = graticule.mapping.ImageFromScreen({edge.time_s, d.mid_div});
    return edge;
  };
  out.gap_px = jump.reaching_start_px - jump.leaving_end_px;
  if (std::isfinite(out.gap_px)) {
    out.leaving_end_div = reader.ScreenX(d.whole, jump.leaving_end_px);
    out.reaching_start_div = reader.ScreenX(d.whole, jump.reaching_start_px);
  }
  if (std::isfinite(out.gap_px) && out.gap_px > 0.0) {
    const double centre = jump.leaving_end_px + 0.25 * out.gap_px;
    if (std::abs(centre) <= d.reach_px) {
      out.bound = edge_at(centre, 0.5 * out.gap_px / std::sqrt(12.0));
    }
  }
  if (!jump.found) return out;
  // What the antisymmetry leaves misses the noise's correlation across rows
  // (JPEG blocks, grain) and what of the lines does not cancel: three times
  // its sigma keeps nine in ten edges within 1.5 sigmas of the truth in
  // every photo style (measured against the renderer's, 5 styles x 4 seeds).
  constexpr double kUnexplained = 3.0;
  out.mirror = edge_at(jump.centre_px, kUnexplained * jump.sigma_px);
  return out;
}

// Whether sample i lies on the level at `level_div` (within `off_level_div`
// of it) where the trace runs level: the samples from it away from the edge
// (`side` -1: before it, +1: after it), over two trace widths (and 10
// samples at least) along the sweep, lie at the level (nine in ten of them)
// and rise or fall by at most a third of a division per division. A line
// crossing the level's height at a slant passes within a trace width of it
// over several samples, and a drawn ring's top runs flat beside it, but
// neither runs along it.
bool RunsLevel(const std::vector<cv::Point2d>& screen, int i, int side, double level_div,
               double off_level_div, double width_div) {
  if (std::abs(screen[i].y - level_div) > off_level_div) return false;
  constexpr double kFlatSlope = 0.35;
  constexpr int kLeastSamples = 10;
  const double reach = 2.0 * width_div;
  double s1 = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, off = 0;
  const int n = static_cast<int>(screen.size());
  for (int j = i, k = 0; j >= 0 && j < n; j += side, ++k) {
    const double dx = screen[j].x - screen[i].x, dy = screen[j].y - screen[i].y;
    if (k >= kLeastSamples && std::abs(dx) > reach) break;
    s1 += 1, sx += dx, sy += dy, sxx += dx * dx, sxy += dx * dy;
    if (std::abs(screen[j].y - level_div) > off_level_div) off += 1;
  }
  if (off > 0.1 * s1) return false;
  const double det = s1 * sxx - sx * sx;
  if (s1 < 3 || !(det > 0.0)) return true;
  return std::abs((s1 * sxy - sx * sy) / det) <= kFlatSlope;
}

}  // namespace

std::optional<ContactPulseFit> MeasurePulse(const PreparedPhoto& photo,
                                            const GraticuleFit& graticule,
                                            const DigitizedTrace& trace) {
  const std::vector<cv::Point2d>& screen = trace.screen_div;
  std::vector<double> y;
  for (const cv::Point2d& p : screen) y.push_back(p.y);
  const auto levels = TwoLevels(y);
  if (!levels) return std::nullopt;
  auto [low, high] = *levels;
  const TraceSettings& s = trace.settings;
  // The pulse is the higher voltage (a contact circuit is high while the bars touch).
  const bool inverted = s.volts_per_div < 0.0;
  const double pulse_level = inverted ? low : high, rest_level = inverted ? high : low;
  const double px_per_div = graticule.px_per_div;
  // The levels must be told apart in the photo: each level's rows (a trace
  // width about it, where its end is read) clear of the other's, with the
  // stroke's rows between them. A smaller step is left to the sampled
  // trace's measure. (Four widths were asked before: pulses stepping two to
  // four widths were timed from the samples' spacing, up to 10 % off; they
  // made 7 of the 18 worst contact times over four randomised sets of 204
  // photos. Seed 1001's run 0.713, a 3-width step, 0.76 % off, is 0.003 %.)
  constexpr double kLeastStepWidths = 2.0;
  if (std::abs(high - low) * px_per_div < kLeastStepWidths * std::max(trace.width_px, 1.0)) {
    return std::nullopt;
  }

  // Runs of samples at each level, in order: every rest -> pulse -> rest.
  const double middle = 0.5 * (low + high);
  auto at_pulse = [&](double v) { return (v > middle) == (pulse_level > middle); };
  constexpr int kRun = 3;  // samples in a row that make a level
  const int n = static_cast<int>(screen.size());
  auto run_at = [&](int from, bool pulse) {
    if (from < 0 || from + kRun > n) return false;
    for (int k = from; k < from + kRun; ++k) {
      if (at_pulse(screen[k].y) != pulse) return false;
    }
    return true;
  };
  struct Pulse {
    int rise_before = -1, rise_after = -1, fall_before = -1, fall_after = -1;
    std::ptrdiff_t at_level = 0;  // its samples at the pulse's level
  };
  std::vector<Pulse> pulses;
  for (int i = kRun - 1; i + 1 < n; ++i) {
    Pulse* open = !pulses.empty() && pulses.back().fall_after < 0 ? &pulses.back() : nullptr;
    if (!open) {
      if (!at_pulse(screen[i].y) && run_at(i + 1, true) && run_at(i - kRun + 1, false)) {
        pulses.push_back({i, i + 1, -1, -1, 0});
      }
    } else if (!at_pulse(screen[i + 1].y) && at_pulse(screen[i].y) && run_at(i + 1, false)) {
      open->fall_before = i, open->fall_after = i + 1;
    }
  }
  if (!pulses.empty() && pulses.back().fall_after < 0) pulses.pop_back();
  if (pulses.empty()) return std::nullopt;
  // The bars touch once in a sweep: the pulse is the one holding most of
  // the samples at the pulse's level. A label written across the trace's
  // rest level reads as a short pulse of its own, before the contact's or
  // after it (randomised seed 1022's run 0.405, "x0 = .405" written along
  // the rest level up to the rise): it is passed over. Where no pulse holds
  // most of them, its edges would be timed on whatever drew them; the
  // sampled trace's measure then says why (rebounds/contact_pulse.cpp).
  for (Pulse& p : pulses) {
    p.at_level = std::count_if(screen.begin() + p.rise_after, screen.begin() + p.fall_after,
                               [&](const cv::Point2d& q) { return at_pulse(q.y); });
  }
  const Pulse& pulse =
      *std::max_element(pulses.begin(), pulses.end(),
                        [](const Pulse& a, const Pulse& b) { return a.at_level < b.at_level; });
  const auto at_pulse_count = std::count_if(screen.begin(), screen.end(),
                                            [&](const cv::Point2d& p) { return at_pulse(p.y); });
  if (2 * pulse.at_level < at_pulse_count) return std::nullopt;
  int rise_before = pulse.rise_before, rise_after = pulse.rise_after;
  int fall_before = pulse.fall_before, fall_after = pulse.fall_after;
  // The edge lies between the last sample at the level the beam leaves and
  // the first at the level it reaches. A sample on the right side of the
  // middle but far off its level is no sample of the level: a hand mark or
  // a scratch the tracking followed beside the edge (an arrow drawn at a
  // pulse's fall, its samples 0.5 division above the pulse's level, made
  // the fall's window 0.16 division beyond the true fall, which was then
  // searched for nowhere near it). Such samples are passed over, so that
  // the window reaches the level's own samples.
  const double off_level = std::min(0.25 * std::abs(high - low), trace.width_px / px_per_div);
  auto at_level = [&](int i, double level) { return std::abs(screen[i].y - level) <= off_level; };
  {
    while (rise_before > 0 && !at_level(rise_before, rest_level)) --rise_before;
    while (rise_after + 1 < fall_before && !at_level(rise_after, pulse_level)) ++rise_after;
    while (fall_before - 1 > rise_after && !at_level(fall_before, pulse_level)) --fall_before;
    while (fall_after + 1 < n && !at_level(fall_after, rest_level)) ++fall_after;
  }

  const InkSampler ink(photo.image, photo.dark_traces);
  // A faint stroke beside a grid line needs the line's light modelled.
  constexpr double kGridReachWidths = 1.5;
  const GridCrossings grid(graticule.divisions, graticule.line_width_px / px_per_div,
                           kGridReachWidths);
  const double low_div = rest_level, high_div = pulse_level;
  const RowReader reader(ink, graticule, grid);
  // The edge lies between the last sample of one level and the first of the
  // other (each level is followed right into its corner).
  const double width_div = trace.width_px / px_per_div;
  auto read_at = [&](int before, int after) {
    const double x0 = screen[before].x, x1 = screen[after].x;
    return ReadStroke(reader, graticule, 0.5 * (x0 + x1), 0.5 * (x1 - x0) + width_div, low_div,
                      high_div, trace.width_px);
  };
  const std::optional<StrokeData> rise_data = read_at(rise_before, rise_after);
  const std::optional<StrokeData> fall_data = read_at(fall_before, fall_after);
  // An edge where a line crosses the levels at a slant (crossing_line): the
  // levels' rows are crossed by it too, each at its own place, so their
  // mirror image is the line's, not the edge's.
  bool rise_crossed = false, fall_crossed = false;
  auto stroke_at = [&](int before, int after, const StrokeHint* hint) {
    const std::optional<StrokeData>& data = before == rise_before ? rise_data : fall_data;
    std::optional<StrokeEdge> edge;
    if (data) edge = FitEdge(reader, graticule, *data, hint);
    if (edge && edge->crossing_line) {
      (before == rise_before ? rise_crossed : fall_crossed) = true;
      edge.reset();
    }
    const double x0 = screen[before].x, x1 = screen[after].x;
    const double x = edge ? edge->edge.time_s : 0.0;
    if (edge && (x < x0 - 0.5 * width_div || x > x1 + 0.5 * width_div)) {
      edge.reset();  // something else: a speck, a scratch
    }
    // The ends of the centre axis's minor ticks (0.1 division either side of
    // it) look like short strokes too.
    const double axis = 0.5 * graticule.divisions[0];
    if (edge &&
        std::min(std::abs(x - (axis - 0.1)), std::abs(x - (axis + 0.1))) < 0.5 * width_div) {
      edge.reset();
    }
    return edge;
  };
  // Each edge on its own, then one beside a grid line again with what the
  // other, clear of the lines, showed of the stroke.
  constexpr double kClear = 1.5;  // separation from a grid line, in widths
  std::optional<StrokeEdge> rise = stroke_at(rise_before, rise_after, nullptr);
  std::optional<StrokeEdge> fall = stroke_at(fall_before, fall_after, nullptr);
  // A stroke far fainter than the other edge's is no stroke of that beam
  // either: a bump of the background taken for it while the stroke lies on
  // the line.
  constexpr double kFainter = 2.5;
  if (rise && fall) {
    const bool rise_guides =
        rise->line_as_expected && ((rise->separation >= kClear && fall->separation < kClear) ||
                                   rise->height > kFainter * fall->height);
    const bool fall_guides =
        fall->line_as_expected && ((fall->separation >= kClear && rise->separation < kClear) ||
                                   fall->height > kFainter * rise->height);
    if (rise_guides && !fall_guides) {
      const StrokeHint hint{rise->fwhm_px, rise->height};
      if (auto again = stroke_at(fall_before, fall_after, &hint)) fall = again;
    } else if (fall_guides && !rise_guides) {
      const StrokeHint hint{fall->fwhm_px, fall->height};
      if (auto again = stroke_at(rise_before, rise_after, &hint)) rise = again;
    }
  } else if (rise || fall) {
    // One edge not seen: perhaps a stroke on a grid line the other can find.
    const StrokeEdge& seen = rise ? *rise : *fall;
    if (seen.separation >= kClear && seen.line_as_expected) {
      const StrokeHint hint{seen.fwhm_px, seen.height};
      if (!rise) rise = stroke_at(rise_before, rise_after, &hint);
      if (!fall) fall = stroke_at(fall_before, fall_after, &hint);
    }
  }
  // The levels' ends measure each edge too (FitJump), from the bright
  // levels rather than the faint stroke.
  const JumpMeasure rise_jump =
      rise_data ? FitJump(reader, graticule, *rise_data, low_div, high_div) : JumpMeasure{};
  const JumpMeasure fall_jump =
      fall_data ? FitJump(reader, graticule, *fall_data, high_div, low_div) : JumpMeasure{};

  // Both edges are one circuit's: they settle alike (one time constant, one
  // step, one beam), so the gap between the levels' ends is the circuit's,
  // measured twice. Where it is under two trace widths the antisymmetry is
  // taken as a measure of each edge, but one that lies a lag `delta` after
  // the half-height crossing, the same lag on both edges: none on a switched
  // edge, 0.2-0.7 of the gap on the external photos' RC edges. The lag is a
  // parameter of the edges' joint fit, known a priori only as 0.4 +- 0.15
  // of the (positive) gap; it cancels from the width when both edges are
  // timed by their levels' ends, and the strokes, which cross half height
  // with no lag, pin it where an edge shows both. Beyond two widths the
  // levels' ends only bound the edge.
  //
  // The lag's prior sigma is the spread of what it was measured to be: over
  // the external photos' 32 edges timed by their levels' ends, lag / gap
  // was 0.42 on average with a standard deviation of 0.15 (0.14-0.68, one
  // 1.0), so 0.15 of the gap. It was 0.25, half the range 0.2-0.7 taken
  // for a sigma: on an edge timed by its levels' ends alone, its lag pinned
  // by no stroke, that stated up to 1.7 times the uncertainty there was.
  //
  // Where the two edges' gaps differ by more than two clean edges' do,
  // something else (a grid line, a JPEG block, a mark) moved a row's step,
  // and the antisymmetry with it. Each row's half crossing sits where the
  // other level's corner lets it: 0.3-1 trace width before the other's on
  // a switched edge, so two clean edges' gaps differ by up to that range,
  // 0.7 width, and that much of a difference is no sign of a disturbed row.
  // A difference D beyond it is one edge's: the disturbed row's step moved
  // by D, the antisymmetry half as far (on our randomised photos the
  // disturbed edge's levels' ends were 0.3-0.5 of the gaps' difference off,
  // the other edge's not at all). Which edge is not known, so each is given half of that
  // variance, (D / 2)^2 / 2, and the width, fall - rise, the whole of it.
  // (The difference was charged in full before, a quarter of it to each
  // edge: over 146 pulses on our randomised photos whose gaps differ by
  // under 0.7 width, it made the width's sigma 1.1 times what the edges'
  // own noise gives at the median, 1.9 times at the 90th percentile, 5.8 at
  // most.)
  constexpr double kMirrorWidths = 2.0;
  constexpr double kLagShare = 0.4, kLagSpread = 0.15;
  constexpr double kCornerWidths = 0.7;
  std::vector<double> gaps;
  for (const JumpMeasure* j : {&rise_jump, &fall_jump}) {
    const bool crossed = j == &rise_jump ? rise_crossed : fall_crossed;
    if (j->mirror && std::isfinite(j->gap_px) && !crossed) gaps.push_back(j->gap_px);
  }
  const double circuit_gap_px =
      gaps.empty() ? 0.0 : std::accumulate(gaps.begin(), gaps.end(), 0.0) / gaps.size();
  const bool mirrored = circuit_gap_px <= kMirrorWidths * trace.width_px;
  const double lag_gap_div = std::max(circuit_gap_px, 0.0) / px_per_div;
  const double lag_div = kLagShare * lag_gap_div;
  // No lag at all on a switched edge: held at none (a tiny sigma).
  const double lag_sigma_div = std::max(kLagSpread * lag_gap_div, 1e-7);
  auto jump_of = [&](const JumpMeasure& j, bool crossed) -> std::optional<PulseEdge> {
    if (!mirrored || !j.mirror || crossed) return std::nullopt;
    PulseEdge edge = *j.mirror;
    if (gaps.size() == 2) {
      const double beyond_corners_px =
          std::max(std::abs(gaps[0] - gaps[1]) - kCornerWidths * trace.width_px, 0.0);
      edge.sigma_s =
          std::hypot(edge.sigma_s, beyond_corners_px / (2.0 * std::sqrt(2.0)) / px_per_div);
    }
    return edge;
  };

  // Each edge's measures, screen divisions: the stroke (as the crossing),
  // the levels' ends (the crossing plus the lag), or, with neither, one
  // measure of the crossing alone.
  struct EdgeMeasures {
    std::optional<PulseEdge> stroke, jump, alone;
  };
  auto measures = [&](int before, int after, const std::optional<StrokeEdge>& stroke,
                      const std::optional<StrokeEdge>& other_stroke,
                      const std::optional<PulseEdge>& jump, const JumpMeasure& levels,
                      bool crossed) {
    if (crossed && !stroke) {
      // The tracking may have followed the crossing line from one level to
      // the other, and its samples there, passing through a level's height,
      // be taken for the level's: the edge lies between the last sample of
      // the level the beam leaves and the first of the one it reaches where
      // each runs level.
      const double leaving = before == rise_before ? rest_level : pulse_level;
      const double reaching = before == rise_before ? pulse_level : rest_level;
      while (before > 0 && !RunsLevel(screen, before, -1, leaving, off_level, width_div)) --before;
      while (after + 1 < n && !RunsLevel(screen, after, +1, reaching, off_level, width_div))
        ++after;
    }
    const double x0 = screen[before].x, x1 = screen[after].x;
    const double spacing_sigma = (x1 - x0) / std::sqrt(12.0);
    EdgeMeasures m;
    if (stroke) m.stroke = stroke->edge;
    // A line of free height beside the stroke, or one far brighter or
    // fainter than its neighbours say (a stroke taken for part of it, or a
    // JPEG block's step taken for the stroke): the fit cannot tell all of
    // their light apart, and the levels' ends bound the uncertainty too.
    // A line further than kLineReach of the two's widths from the stroke
    // (each one's light reaches 1.5 of its widths) moves it by nothing,
    // whatever its brightness. (The fit's sigma does not hold what a line of
    // free height can take: on a 400 px photo a fall 0.7 px beside the line
    // x = 5 merges with it into one blob, which the fit explains to under a
    // hundredth of the stroke's height as a stroke 0.66 px off, with a sigma
    // of 0.06 px.)
    constexpr double kLineReach = 3.0;
    if (stroke && ((!stroke->line_measured && stroke->separation < kClear) ||
                   (!stroke->line_as_expected && stroke->separation < kLineReach))) {
      m.stroke->sigma_s = std::hypot(m.stroke->sigma_s, spacing_sigma);
    }
    m.jump = jump;
    // The stroke's and the levels' ends' measures further apart than
    // kDisagree of their joint sigmas (the lag allowed for) are not
    // measuring the same thing. A stroke on a grid line is then the line's
    // own light taken for it (a printed figure's line, its brightness
    // beating with the halftone screen along it, stands out of its
    // reference rows where the faint stroke is lost in the dots): the
    // levels' ends, where the line cancels, time the edge alone. Clear of
    // lines, neither is known to be the wrong one, and both sigmas are
    // scaled by how far apart they are (the Particle Data Group's scale
    // factor), so that the error stated covers both.
    constexpr double kDisagree = 4.0;
    // A stroke more than kFainter times as high as the other edge's is not
    // the same beam's at the same speed: one of the two is something else.
    // The fainter is taken for a bump of the background above (the brighter
    // guides its fit again); but a brighter one that also lies more than
    // kDisagreeBright joint sigmas from its own levels' ends is the
    // something else, a scratch or a hair across the levels (randomised seed
    // 4022's run 0.405: a scratch 11 px beside the line x = 2, 4.5 times as
    // high as the fall's stroke and 3.7 joint sigmas from the rise's levels'
    // ends, was taken for the rise, the contact time 0.47 % long at 26 of
    // its sigmas). Two independent signs, each improbable for the beam's
    // stroke, at 3 sigmas together.
    constexpr double kDisagreeBright = 3.0;
    const bool brighter_than_beam =
        stroke && other_stroke && stroke->height > kFainter * other_stroke->height;
    if (m.stroke && m.jump) {
      const double apart = std::abs(m.stroke->time_s - (m.jump->time_s - lag_div));
      const double joint =
          std::sqrt(m.stroke->sigma_s * m.stroke->sigma_s + m.jump->sigma_s * m.jump->sigma_s +
                    lag_sigma_div * lag_sigma_div);
      // A stroke where the levels' ends show the beam still on a level (more
      // than a trace width before the leaving level ends or after the
      // reaching one begins) is ink across the levels, not the edge: a hand
      // mark (a ring drawn about randomised seed 2009's run 0.713's fall
      // crossed both levels 0.31 division before it; its stroke was taken,
      // the sampled trace having followed the ring, and the contact time
      // stated 4.5 % short at 28 of its sigmas).
      const double first = std::min(levels.leaving_end_div, levels.reaching_start_div);
      const double last = std::max(levels.leaving_end_div, levels.reaching_start_div);
      const bool on_a_level = std::isfinite(first) && (m.stroke->time_s < first - width_div ||
                                                       m.stroke->time_s > last + width_div);
      if (brighter_than_beam && apart > kDisagreeBright * joint) {
        m.stroke.reset();
      } else if (apart > kDisagree * joint) {
        if (stroke->separation < kClear || on_a_level) {
          m.stroke.reset();
        } else {
          m.stroke->sigma_s *= apart / joint;
          m.jump->sigma_s *= apart / joint;
        }
      }
    }
    if (m.stroke || m.jump) return m;
    // No stroke and no mirrored levels' ends: where the levels' ends bound
    // the edge (a slowly settling edge), when that is narrower than the
    // samples' spacing; else between the levels' ends, as a sampled trace
    // would.
    if (levels.bound && levels.bound->sigma_s < spacing_sigma && !crossed) {
      m.alone = levels.bound;
    } else {
      const double guess = 0.5 * (x0 + x1);
      m.alone = PulseEdge{};
      m.alone->time_s = guess;
      m.alone->sigma_s = spacing_sigma;
    }
    return m;
  };
  const EdgeMeasures rise_m = measures(rise_before, rise_after, rise, fall,
                                       jump_of(rise_jump, rise_crossed), rise_jump, rise_crossed);
  const EdgeMeasures fall_m = measures(fall_before, fall_after, fall, rise,
                                       jump_of(fall_jump, fall_crossed), fall_jump, fall_crossed);

  // The joint least squares of (rise, fall, lag) with the lag's prior.
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0.0, 0.0, 0.0);
  auto add = [&](const cv::Vec3d& row, double value, double sigma) {
    const double w = 1.0 / (sigma * sigma);
    normal += w * (row * row.t());
    rhs += w * value * row;
  };
  for (int e = 0; e < 2; ++e) {
    const EdgeMeasures& m = e == 0 ? rise_m : fall_m;
    const cv::Vec3d crossing(e == 0 ? 1.0 : 0.0, e == 0 ? 0.0 : 1.0, 0.0);
    if (m.stroke) add(crossing, m.stroke->time_s, m.stroke->sigma_s);
    if (m.alone) add(crossing, m.alone->time_s, m.alone->sigma_s);
    if (m.jump) add(crossing + cv::Vec3d(0.0, 0.0, 1.0), m.jump->time_s, m.jump->sigma_s);
  }
  add(cv::Vec3d(0.0, 0.0, 1.0), lag_div, lag_sigma_div);
  const cv::Matx33d covariance = normal.inv(cv::DECOMP_CHOLESKY);
  const cv::Vec3d solution = covariance * rhs;
  // The mapping's own uncertainty along the sweep, each edge's: the fitted
  // mapping's, not one line sample's scatter (the graticule's residual),
  // which hundreds of samples average: the residual times the square root
  // of the parameters (a homography's 8 and the radial term) over the
  // samples. (Half the residual was stated before; the true edge pixels
  // taken through the fitted mapping give the true width to 0.003 %.)
  const double mapping_share =
      graticule.samples_used > 0
          ? std::min(0.5, std::sqrt((8.0 + (graticule.radial_fitted ? 1.0 : 0.0)) /
                                    graticule.samples_used))
          : 0.5;
  const double mapping_sigma_div = mapping_share * graticule.residual_px / px_per_div;
  const double mapping_variance = mapping_sigma_div * mapping_sigma_div;
  // A printed figure places an edge no finer than its screen's dots where
  // the edge's dots merge with a grid line's: the ink of the two does not
  // add as light does, so neither the stroke's fit nor the levels' ends can
  // part them, and both are drawn towards the line alike. The two merge
  // where their bars of ink (each its width at half height, the edge's its
  // stroke's or, with none, the trace's) come within half a dot of each
  // other, the dots at a printed bar's border reaching that far beyond it.
  // There the edge is known to a dot: its position uniform over the
  // screen's period, a sigma of period / sqrt(12), added once to the edge
  // however it was measured. (On our randomised prints, falls 9 px from a
  // line, both about 10 px wide, were read 1-6 px towards it with sigmas of
  // 0.3-1.5 px: randomised seed 4034's run 0.713's contact time at -10 of
  // its sigmas, 2021's 0.713 at -4.7. Edges clear of that reach were read
  // as their sigmas say: the external halftone-e900's, 11-16 px from lines
  // 7-8 px wide, within 0.1 us.)
  auto print_variance = [&](double x_div, const std::optional<StrokeEdge>& stroke) {
    if (!(photo.halftone_period_px > 0.0)) return 0.0;
    const double from_line_px = std::abs(x_div - std::round(x_div)) * px_per_div;
    const double edge_width_px = stroke ? stroke->fwhm_px : trace.width_px;
    const double merge_px =
        0.5 * (graticule.line_width_px + edge_width_px) + 0.5 * photo.halftone_period_px;
    if (from_line_px >= merge_px) return 0.0;
    const double sigma_div = photo.halftone_period_px / std::sqrt(12.0) / px_per_div;
    return sigma_div * sigma_div;
  };
  // A raster display (a dotted graticule: a digital scope's screen) draws a
  // step as a column of its pixels, wherever within that column the signal
  // crossed: the edge is known to a column, its position uniform over the
  // column's width (a graticule line's, one pixel wide), a sigma of
  // width / sqrt(12), added once to the edge. (The generator's digital
  // photos: contact times off by up to 0.55 us, a column 0.8-1.3 us wide,
  // at sigmas of 0.02-0.16 us, pull RMS 10.)
  const double raster_sigma_div =
      graticule.dotted ? graticule.line_width_px / std::sqrt(12.0) / px_per_div : 0.0;
  const double raster_variance = raster_sigma_div * raster_sigma_div;
  // What places each edge no finer than a dot or a column, whatever measured it.
  const double placement_variances[2] = {print_variance(solution[0], rise) + raster_variance,
                                         print_variance(solution[1], fall) + raster_variance};
  auto finish = [&](int e, const EdgeMeasures& m) {
    PulseEdge edge;
    edge.from_image = m.stroke || m.jump || (m.alone && m.alone->from_image);
    const double x = solution[e];
    edge.centre_px = graticule.mapping.ImageFromScreen({x, 0.5 * (low_div + high_div)});
    // Screen x to seconds.
    edge.time_s = (x - s.t0_div) * s.time_per_div;
    edge.sigma_s =
        std::sqrt(covariance(e, e) + mapping_variance + placement_variances[e]) * s.time_per_div;
    return edge;
  };
  const PulseEdge rise_edge = finish(0, rise_m);
  const PulseEdge fall_edge = finish(1, fall_m);
  const double width_variance = covariance(0, 0) + covariance(1, 1) - 2.0 * covariance(0, 1) +
                                2.0 * mapping_variance + placement_variances[0] +
                                placement_variances[1];
  ContactPulseFit fit;
  fit.pulse.rise_s = {rise_edge.time_s, rise_edge.sigma_s};
  fit.pulse.fall_s = {fall_edge.time_s, fall_edge.sigma_s};
  fit.pulse.width_s = {fall_edge.time_s - rise_edge.time_s,
                       std::sqrt(std::max(width_variance, 0.0)) * s.time_per_div};
  fit.pulse.low_volts = (std::min(low, high) - s.zero_div) * s.volts_per_div;
  fit.pulse.high_volts = (std::max(low, high) - s.zero_div) * s.volts_per_div;
  if (fit.pulse.low_volts > fit.pulse.high_volts) {
    std::swap(fit.pulse.low_volts, fit.pulse.high_volts);
  }
  fit.rise = {rise_edge.centre_px, rise_edge.from_image};
  fit.fall = {fall_edge.centre_px, fall_edge.from_image};
  return fit;
}

}  // namespace impactlab
