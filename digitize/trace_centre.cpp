// ExtractTraces: each trace tracked coarsely along its band, then its centre
// line measured across it in the full photo, sample by sample, with the grid
// lines it passes allowed for, dash ends, specks, cusps and outliers dropped,
// and nothing reported where no line is seen.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "digitize/beam_spread.h"
#include "digitize/bold_lines.h"
#include "digitize/digitize.h"
#include "digitize/hand_marks.h"
#include "digitize/ink_sampler.h"
#include "digitize/line_profile.h"
#include "digitize/screen_geometry.h"
#include "digitize/select.h"
#include "digitize/trace_track.h"
#include "io/errors.h"

namespace impactlab {

namespace {

using digitize::CentreSettings;
using digitize::Claims;
using digitize::CoarsePath;
using digitize::CutToClearStretch;
using digitize::FindLineCentre;
using digitize::GridCrossings;
using digitize::ImageFromScreen;
using digitize::InkSampler;
using digitize::LevelHalfWidths;
using digitize::LineCentre;
using digitize::Median;
using digitize::Profile;
using digitize::ReadProfile;
using digitize::ScreenFromPixel;
using digitize::TrackGrid;

// The coarse course as a function of screen x: the seen columns either side,
// joined across gaps the tracking bridged (never across a step or a restart).
class Course {
 public:
  Course(const CoarsePath& path, int max_gap_columns) : path_(path), max_gap_(max_gap_columns) {
    const int n = static_cast<int>(path.y_div.size());
    previous_.assign(n, -1);
    next_.assign(n, -1);
    for (int c = 0, last = -1; c < n; ++c) {
      if (!std::isnan(path.y_div[c])) last = c;
      previous_[c] = last;
    }
    for (int c = n - 1, last = -1; c >= 0; --c) {
      if (!std::isnan(path.y_div[c])) last = c;
      next_[c] = last;
    }
    piece_.assign(n, 0);
    for (int c = 0, piece = 0; c < n; ++c) {
      if (!std::isnan(path.y_div[c]) && path.link[c] != CoarsePath::kOnCourse) ++piece;
      piece_[c] = piece;
    }
  }

  // y (div), slope (div/div) and which piece (between steps and restarts) at x.
  bool At(double x_div, double* y_div, double* slope, int* piece) const {
    const int n = static_cast<int>(path_.y_div.size());
    const double column = x_div * path_.grid.px_per_div;
    const int c0 = std::clamp(static_cast<int>(std::floor(column)), 0, n - 1);
    const int c1 = std::min(c0 + 1, n - 1);
    const int a = previous_[c0], b = next_[c1];
    const bool joined =
        a >= 0 && b >= 0 && b - a <= max_gap_ && path_.link[b] == CoarsePath::kOnCourse;
    // Only where the tracking saw the trace (within a column): in a gap it
    // bridged there is nothing to measure, and a grid line might pass for it.
    const bool seen = (a >= 0 && column - a <= 1.0) || (b >= 0 && b - column <= 1.0);
    if (!seen) return false;
    int at = -1;
    if (joined && b != a) {
      const double f = std::clamp((column - a) / (b - a), 0.0, 1.0);
      *y_div = path_.y_div[a] + f * (path_.y_div[b] - path_.y_div[a]);
      at = column - a < b - column ? a : b;
    } else if (a >= 0 && column - a <= 1.5) {
      *y_div = path_.y_div[a], at = a;
    } else if (b >= 0 && b - column <= 1.5) {
      *y_div = path_.y_div[b], at = b;
    } else {
      return false;
    }
    *slope = Slope(at);
    *piece = Piece(at);
    return true;
  }

 private:
  // The slope over a few seen columns either side within the same piece.
  double Slope(int c) const {
    constexpr int kReach = 4;
    const int n = static_cast<int>(path_.y_div.size());
    int lo = c, hi = c;
    for (int k = 0, p = c; k < kReach && p >= 0; ++k) {
      if (path_.link[p] != CoarsePath::kOnCourse) break;
      const int q = p > 0 ? previous_[p - 1] : -1;
      if (q < 0 || p - q > max_gap_) break;
      lo = q, p = q;
    }
    for (int k = 0, p = c; k < kReach && p < n - 1; ++k) {
      const int q = next_[p + 1];
      if (q < 0 || q - p > max_gap_ || path_.link[q] != CoarsePath::kOnCourse) break;
      hi = q, p = q;
    }
    if (hi == lo) return 0.0;
    return (path_.y_div[hi] - path_.y_div[lo]) / ((hi - lo) / path_.grid.px_per_div);
  }

  int Piece(int c) const { return piece_[c]; }

  const CoarsePath& path_;
  int max_gap_;
  std::vector<int> previous_, next_;
  std::vector<int> piece_;  // per column: pieces begun up to it
};

struct Sample {
  cv::Point2d centre_px;
  cv::Point2d screen_div;
  double height = 0.0;
  double fwhm_px = 0.0;
  double crossing_share = 0.0;
  LevelHalfWidths half_widths{};  // across the line at the spread's levels
  int piece = 0;
  bool keep = true;
  double confidence = 1.0;
};

struct MeasureSettings {
  double step_div = 0.01;  // between samples along the sweep
  double search_px = 3.0;  // the coarse course's uncertainty across the trace
  double half_length_px = 10.0;
  double profile_step_px = 0.5;
  CentreSettings centre;
  // The trace's typical height, for the half-widths at the spread's levels
  // (0: not read).
  double typical_height = 0.0;
};

// A short line of the graticule (a tick mark of a centre axis, 0.2 division
// apart) lighting a profile where the trace's core lies spoils it only when
// its light matters against the trace's. Its light is at most a grid line's
// height g, a plateau along the profile over the tick's length; where it
// covers one flank of a Gaussian line of height H and sigma s and not the
// other, the half-maximum centre moves by about 0.85 s g / H. A trace
// standing kShortLineOver grid lines high moves by under a tenth of s, a
// saturated core by less. At a small scale a tick's reach (1.5 line widths)
// covers every place between the ticks, so without this a trace lying
// along a centre axis (a contact level) was read only beside the division
// lines, where no tick is drawn.
constexpr double kShortLineOver = 5.0;

LineCentre AcrossFaintShortLine(const Profile& profile, const CentreSettings& settings) {
  if (!(settings.crossing_height > 0.0)) return {};
  const LineCentre centre = FindLineCentre(profile, settings);
  if (!centre.found || centre.height < kShortLineOver * settings.crossing_height) return {};
  return centre;
}

// Measures across the trace at x = x0, x0 + step, ... wherever the course is known.
std::vector<Sample> MeasureAlong(const InkSampler& ink, const GraticuleFit& graticule,
                                 const Course& course, const GridCrossings& grid,
                                 const MeasureSettings& settings, double step_div) {
  const GraticuleMapping& mapping = graticule.mapping;
  const ScreenFromPixel screen_from_pixel(mapping);
  const double nx = graticule.divisions[0];
  std::vector<Sample> samples;
  constexpr double kTangentDiv = 0.02;
  const int count = static_cast<int>(std::floor(nx / step_div + 1e-9));
  // Beside a tick's end a profile is cut short of its light, if it still
  // reaches this far either side, well past the trace's edges: a trace
  // crossing a centre axis at a shallow angle has its profiles run along the
  // axis's ticks, and would lose a division or two of its course there.
  const double min_reach_px =
      settings.search_px + 0.6 * (settings.half_length_px - settings.search_px);
  for (int i = 0; i <= count; ++i) {
    const double x = std::min(nx, i * step_div);
    double y = 0.0, slope = 0.0;
    int piece = 0;
    if (!course.At(x, &y, &slope, &piece)) continue;
    const cv::Point2d origin = ImageFromScreen(mapping, {x, y});
    const cv::Point2d tangent =
        ImageFromScreen(mapping, {x + kTangentDiv, y + slope * kTangentDiv}) -
        ImageFromScreen(mapping, {x - kTangentDiv, y - slope * kTangentDiv});
    const double length = std::hypot(tangent.x, tangent.y);
    if (!(length > 0.0)) continue;
    const cv::Point2d normal(-tangent.y / length, tangent.x / length);
    Profile profile =
        ReadProfile(ink, origin, normal, settings.half_length_px, settings.profile_step_px);
    const int n = static_cast<int>(profile.values.size());
    grid.AddTo(profile, screen_from_pixel(profile.PointAt(profile.OffsetAt(0))),
               screen_from_pixel(profile.PointAt(profile.OffsetAt(n - 1))));
    // Cut short of a short line's light, or, where that light reaches the
    // trace's core, read whole if the line is faint against the trace.
    const LineCentre centre = CutToClearStretch(profile, min_reach_px)
                                  ? FindLineCentre(profile, settings.centre)
                                  : AcrossFaintShortLine(profile, settings.centre);
    if (!centre.found) continue;
    Sample sample;
    sample.centre_px = profile.PointAt(centre.offset_px);
    sample.screen_div = screen_from_pixel(sample.centre_px);
    sample.height = centre.height;
    sample.fwhm_px = centre.fwhm_px;
    sample.crossing_share = centre.crossing_share;
    if (settings.typical_height > 0.0) {
      sample.half_widths =
          digitize::MeasureLevelHalfWidths(profile, centre, settings.typical_height);
    }
    sample.piece = piece;
    samples.push_back(sample);
  }
  return samples;
}

// A parabola y = c0 + c1 x + c2 x^2 (screen divisions, x and y from sample
// i) through sample i's nearest `neighbours` either side on the same piece
// within `reach_div`, not itself; a straight line with fewer than five,
// nothing with fewer than three.
std::optional<cv::Vec3d> LocalParabola(const std::vector<Sample>& samples, int i, double reach_div,
                                       int neighbours = 10) {
  const int n = static_cast<int>(samples.size());
  const cv::Point2d centre = samples[i].screen_div;
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d rhs(0.0, 0.0, 0.0);
  int count = 0;
  for (int j = std::max(0, i - neighbours); j <= std::min(n - 1, i + neighbours); ++j) {
    const double x = samples[j].screen_div.x - centre.x, y = samples[j].screen_div.y - centre.y;
    if (j == i || samples[j].piece != samples[i].piece || std::abs(x) > reach_div) continue;
    const cv::Vec3d basis(1.0, x, x * x);
    normal += basis * basis.t();
    rhs += y * basis;
    ++count;
  }
  if (count < 3) return std::nullopt;
  if (count < 5) normal(2, 2) += 1e6 * (normal(1, 1) + 1e-12);  // a straight line
  // Cramer's rule: cv::solve's setup costs more than the 3 x 3 solve itself.
  const double det = cv::determinant(normal);
  if (!(std::abs(det) > 1e-300)) return std::nullopt;
  cv::Vec3d fit;
  for (int k = 0; k < 3; ++k) {
    cv::Matx33d replaced = normal;
    for (int r = 0; r < 3; ++r) replaced(r, k) = rhs[r];
    fit[k] = cv::determinant(replaced) / det;
  }
  return fit;
}

double OutlierReach(double step_div) { return std::max(0.1, 6.5 * step_div); }

// Sample i's miss across the trace (pixels) from the LocalParabola through
// its neighbours within `reach_div` (at most `neighbours` either side);
// infinite with fewer than three.
double MissAcross(const std::vector<Sample>& samples, int i, double reach_div, double px_per_div,
                  int neighbours = 10) {
  const std::optional<cv::Vec3d> fit = LocalParabola(samples, i, reach_div, neighbours);
  if (!fit) return std::numeric_limits<double>::infinity();
  // The vertical miss shrunk by the slope.
  return -(*fit)[0] * px_per_div / std::sqrt(1.0 + (*fit)[1] * (*fit)[1]);
}

// A trace is read in dots when more than this share of its samples have too
// few neighbours within the outlier reach: a continuous trace's lone samples
// (a stretch otherwise dropped) are a few percent of them.
constexpr double kDottedShare = 1.0 / 3.0;

// Drops samples further than `sigmas` robust sigmas from a smooth curve
// through their neighbours on the same piece (LocalParabola over the nearest
// tenth of a division or so); returns that robust sigma across the trace, the
// centre's scatter (pixels). A sample with fewer than three neighbours (its
// stretch otherwise dropped) is not trusted, unless the trace is read in
// dots (kDottedShare): a finely chopped beam draws dots shorter than the
// reach a chopper period apart (randomised seed 1014's run 0.713: dots 2.5 px
// long every 7.9 px, 0.14 division), and they are the beam's one course. So
// there such a sample is judged against its neighbouring dots, the reach
// doubled until three are found (up to 0.4 division, as LocalShapes), by the
// limit the trace's other samples set.
double RejectOutliers(std::vector<Sample>& samples, double step_div, double px_per_div,
                      double sigmas, int* dropped) {
  const int n = static_cast<int>(samples.size());
  std::vector<double> residuals(n, 0.0);
  for (int i = 0; i < n; ++i) {
    residuals[i] = MissAcross(samples, i, OutlierReach(step_div), px_per_div);
  }
  std::vector<double> magnitudes;
  for (const double r : residuals) {
    if (std::isfinite(r)) magnitudes.push_back(std::abs(r));
  }
  const double sigma = 1.4826 * Median(magnitudes);
  if (static_cast<double>(n - magnitudes.size()) > kDottedShare * n) {
    std::vector<double> xs(n);
    for (int i = 0; i < n; ++i) xs[i] = samples[i].screen_div.x;  // increasing
    for (int i = 0; i < n; ++i) {
      for (double reach = 2.0 * OutlierReach(step_div); reach < 0.5 && !std::isfinite(residuals[i]);
           reach *= 2.0) {
        const auto from = std::lower_bound(xs.begin(), xs.end(), xs[i] - reach) - xs.begin();
        const auto to = std::upper_bound(xs.begin(), xs.end(), xs[i] + reach) - xs.begin();
        const auto neighbours = std::max<std::ptrdiff_t>(i - from, to - i);
        residuals[i] = MissAcross(samples, i, reach, px_per_div, static_cast<int>(neighbours));
      }
    }
  }
  const double limit = sigmas * std::max(sigma, 0.1);
  *dropped = 0;
  for (int i = 0; i < n; ++i) {
    if (std::abs(residuals[i]) > limit) {
      samples[i].keep = false;
      ++*dropped;
    } else {
      // Confidence falls as a sample strays towards the limit.
      samples[i].confidence *= 1.0 - 0.5 * std::abs(residuals[i]) / limit;
    }
  }
  return sigma;
}

// Where a dash ends (or dust hides the trace), the profile sees the line's
// end from the side and its centre slides off the course; those samples are
// dimmer than the line a little way inside. Drops samples dimmer than
// `level` times the brightest within kReachDiv on the same unbroken run.
void TrimDashEnds(std::vector<Sample>& samples, double step_div, double level) {
  const double reach_div = std::max(0.06, 6.5 * step_div);
  const int n = static_cast<int>(samples.size());
  std::vector<int> run(n, 0);
  for (int i = 1; i < n; ++i) {
    const bool joined = samples[i].screen_div.x - samples[i - 1].screen_div.x <= 1.6 * step_div;
    run[i] = run[i - 1] + (joined ? 0 : 1);
  }
  std::vector<double> brightest(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double best = samples[i].height;
    for (int j = i - 1; j >= 0 && run[j] == run[i] &&
                        samples[i].screen_div.x - samples[j].screen_div.x <= reach_div;
         --j) {
      best = std::max(best, samples[j].height);
    }
    for (int j = i + 1; j < n && run[j] == run[i] &&
                        samples[j].screen_div.x - samples[i].screen_div.x <= reach_div;
         ++j) {
      best = std::max(best, samples[j].height);
    }
    brightest[i] = best;
  }
  for (int i = 0; i < n; ++i) {
    if (samples[i].height < level * brightest[i]) samples[i].keep = false;
  }
}

// Where the trace turns sharply (a rebound's cusp, a step's corner) within
// about its own width, glow and blur round the corner off and the measured
// centre cuts inside it; the line's centre is not defined there. Drops
// samples where the course turns by more than kMaxTurnDeg between points
// `reach_px` before and after them.
void DropCorners(std::vector<Sample>& samples, double reach_px, double step_div) {
  constexpr double kMaxTurnDeg = 40.0;
  const double max_turn_cos = std::cos(kMaxTurnDeg * 3.14159265358979 / 180.0);
  const int n = static_cast<int>(samples.size());
  auto joined = [&](int a, int b) {  // an unbroken stretch between samples a < b
    for (int k = a; k < b; ++k) {
      if (samples[k + 1].screen_div.x - samples[k].screen_div.x > 3.0 * step_div ||
          samples[k + 1].piece != samples[k].piece) {
        return false;
      }
    }
    return true;
  };
  std::vector<bool> corner(n, false);
  for (int i = 0; i < n; ++i) {
    int before = i, after = i;
    while (before > 0 && cv::norm(samples[before].centre_px - samples[i].centre_px) < reach_px)
      --before;
    while (after + 1 < n && cv::norm(samples[after].centre_px - samples[i].centre_px) < reach_px)
      ++after;
    if (before == i || after == i || !joined(before, after)) continue;
    const cv::Point2d in = samples[i].centre_px - samples[before].centre_px;
    const cv::Point2d out = samples[after].centre_px - samples[i].centre_px;
    const double turn_cos = in.dot(out) / (cv::norm(in) * cv::norm(out));
    if (turn_cos < max_turn_cos) corner[i] = true;
  }
  for (int i = 0; i < n; ++i) {
    if (corner[i]) samples[i].keep = false;
  }
}

// A speck of dust or a blob of glare the tracking strayed onto gives a run
// of samples no longer than itself is wide; a dashed trace's stretches are
// longer. Runs break where the centre jumps by more than a few trace widths
// between neighbouring samples. A run shorter than `min_length_px` is dropped
// when the trace's runs are typically several times longer (a finely chopped
// trace, all dots, keeps its dots).
void DropShortRuns(std::vector<Sample>& samples, double step_div, double width_px,
                   double min_length_px) {
  const int n = static_cast<int>(samples.size());
  std::vector<std::pair<int, int>> runs;  // [start, end)
  int start = 0;
  for (int i = 1; i <= n; ++i) {
    const bool breaks = i == n ||
                        samples[i].screen_div.x - samples[i - 1].screen_div.x > 3.0 * step_div ||
                        cv::norm(samples[i].centre_px - samples[i - 1].centre_px) > 3.0 * width_px;
    if (breaks) runs.emplace_back(start, i), start = i;
  }
  auto length = [&](const std::pair<int, int>& run) {
    return cv::norm(samples[run.second - 1].centre_px - samples[run.first].centre_px);
  };
  std::vector<double> lengths;
  for (const auto& run : runs) lengths.push_back(length(run));
  const double typical = Median(lengths);
  for (const auto& run : runs) {
    if (length(run) < std::min(min_length_px, 0.3 * typical)) {
      for (int k = run.first; k < run.second; ++k) samples[k].keep = false;
    }
  }
}

// Whether the trace somewhere writes kMinSpeedRatio times faster than its
// sweep (a tenth of its steps at least): only then can it measure its spread.
// A fast sweep or a contact pulse's levels cannot, and curve too little to
// matter.
bool WritesFastSomewhere(const std::vector<Sample>& samples, double step_div) {
  std::vector<double> slopes;
  for (std::size_t i = 0; i + 1 < samples.size(); ++i) {
    const cv::Point2d d = samples[i + 1].screen_div - samples[i].screen_div;
    if (samples[i + 1].piece == samples[i].piece && d.x > 0.0 && d.x <= 3.0 * step_div) {
      slopes.push_back(std::abs(d.y / d.x));
    }
  }
  if (slopes.size() < 30) return false;
  const auto p90 = slopes.begin() + static_cast<std::ptrdiff_t>(0.9 * (slopes.size() - 1));
  std::nth_element(slopes.begin(), p90, slopes.end());
  return std::hypot(1.0, *p90) >= digitize::kMinSpeedRatio;
}

// Each sample's local parabola (LocalParabola, at least six neighbours):
// near a slow sweep's peaks a chopper's gaps and the dropped corners leave
// few samples, so it reaches further there (up to 0.4 division) for a curve
// rather than a chord.
std::vector<std::optional<cv::Vec3d>> LocalShapes(const std::vector<Sample>& samples,
                                                  double step_div) {
  const int n = static_cast<int>(samples.size());
  std::vector<double> xs(n);
  for (int i = 0; i < n; ++i) xs[i] = samples[i].screen_div.x;  // increasing
  std::vector<std::optional<cv::Vec3d>> shape(n);
  for (int i = 0; i < n; ++i) {
    for (double reach = OutlierReach(step_div); reach < 0.5 && !shape[i]; reach *= 2.0) {
      const int from =
          static_cast<int>(std::lower_bound(xs.begin(), xs.end(), xs[i] - reach) - xs.begin());
      const int to =
          static_cast<int>(std::upper_bound(xs.begin(), xs.end(), xs[i] + reach) - xs.begin());
      int count = 0;
      for (int j = from; j < to; ++j) count += j != i && samples[j].piece == samples[i].piece;
      if (count >= 6) shape[i] = LocalParabola(samples, i, reach, std::max(i - from, to - i));
    }
  }
  return shape;
}

// Moves each sample out of its curve by the spread's pull, s^2 kappa / 2
// along the normal (beam_spread.h), with s^2 measured on the trace itself;
// returns the spread used (not found: nothing moved). In screen terms the
// pull moves y by s^2 y'' / (2 p^2 (1 + y'^2)), p pixels per division.
digitize::SpreadEstimate UndoCurvaturePull(std::vector<Sample>& samples, double step_div,
                                           double px_per_div, double width_px) {
  if (!WritesFastSomewhere(samples, step_div)) return {};
  const std::vector<std::optional<cv::Vec3d>> shape = LocalShapes(samples, step_div);
  std::vector<digitize::SpreadPoint> points;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!shape[i] || samples[i].crossing_share > 0.0) continue;
    points.push_back({std::hypot(1.0, (*shape[i])[1]), samples[i].half_widths});
  }
  const digitize::SpreadEstimate spread = digitize::EstimateSpread(points);
  // A concave tone curve only widens a line: its spread is at most what its
  // width would give with none.
  const double widest = std::pow(width_px / 2.354820045, 2);
  if (!spread.found || spread.variance_px2 > widest) return {};
  const double pull = spread.variance_px2 / (2.0 * px_per_div * px_per_div);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!shape[i]) continue;
    const double slope = (*shape[i])[1], second = 2.0 * (*shape[i])[2];
    samples[i].screen_div.y -= pull * second / (1.0 + slope * slope);
  }
  return spread;
}

DigitizedTrace MeasureTrace(const PreparedPhoto& photo, const GraticuleFit& graticule,
                            const TraceRequest& request, const CoarsePath& path,
                            const TraceOptions& options) {
  const InkSampler ink(photo.image, photo.dark_traces);
  const int max_gap_columns =
      std::max(1, static_cast<int>(std::lround(options.max_gap_div * path.grid.px_per_div)));
  const Course course(path, max_gap_columns);
  const double px_per_div = graticule.px_per_div;
  const GridCrossings grid(graticule.divisions, graticule.line_width_px / px_per_div,
                           options.grid_reach_widths);

  MeasureSettings settings;
  // The tracking places the trace to about a working pixel.
  settings.search_px = 1.5 * photo.shrink + 1.5;
  settings.centre.method = options.method;
  settings.centre.centroid_level = options.centroid_level;
  settings.centre.search_px = settings.search_px;
  settings.centre.crossing_height = graticule.line_contrast;
  settings.centre.crossing_fwhm_px = graticule.line_width_px;
  settings.centre.symmetric_near_crossings = options.grid_model;

  // A first look at every tenth position gives the trace's width, and tells
  // whether it writes fast enough anywhere to measure its spread (a fast
  // sweep's calibration trace does not: its half-widths are not read).
  settings.half_length_px = settings.search_px + std::max(6.0, 0.08 * px_per_div);
  settings.profile_step_px = 0.5;
  const double step_div = 1.0 / (px_per_div * options.samples_per_px);
  const std::vector<Sample> first_look =
      MeasureAlong(ink, graticule, course, grid, settings, 10.0 * step_div);
  std::vector<double> widths, first_heights;
  for (const Sample& s : first_look) {
    widths.push_back(s.fwhm_px);
    first_heights.push_back(s.height);
  }
  double width_px = std::max(1.0, Median(widths));
  // A bold trace (a line printed in a report's figure) fills a profile
  // reaching only a few pixels past the search: its background is then read
  // on its own flanks and its width comes out about the profile's, and most
  // of its samples are later dropped as wider than that. Where the trace was
  // tracked on a ridge image of bold lines (a reading of thin lines failed)
  // and its width measured reaches that far, the first look is taken again
  // on a profile that reaches well past the width (at most half a division:
  // a grid line and the next trace lie beyond), while it keeps growing. A
  // reading of thin lines is measured as before.
  const bool bold_reading = photo.ridge_opening_px > digitize::kRidgeOpeningPx;
  for (int round = 0; bold_reading && round < 3; ++round) {
    const double reach_px = settings.half_length_px - settings.search_px;
    if (width_px < 0.8 * reach_px) break;
    const double wider = std::min(1.5 * width_px, 0.5 * px_per_div);
    if (wider <= reach_px) break;
    settings.half_length_px = settings.search_px + wider;
    widths.clear();
    first_heights.clear();
    const std::vector<Sample> look =
        MeasureAlong(ink, graticule, course, grid, settings, 10.0 * step_div);
    for (const Sample& s : look) {
      widths.push_back(s.fwhm_px);
      first_heights.push_back(s.height);
    }
    // A profile that reaches past a bold line reads it wider; one that
    // reads it no wider (or not at all) says the first width stood.
    const double measured = Median(widths);
    if (!(measured > width_px)) break;
    width_px = measured;
  }
  if (WritesFastSomewhere(first_look, 10.0 * step_div)) {
    settings.typical_height = Median(first_heights);
  }

  settings.half_length_px = settings.search_px + options.profile_half_widths * width_px;
  settings.profile_step_px = std::clamp(width_px / 6.0, 0.25, 1.0);
  std::vector<Sample> samples = MeasureAlong(ink, graticule, course, grid, settings, step_div);

  DigitizedTrace result;
  result.name = request.name;
  result.settings = request.settings;
  result.width_px = width_px;
  std::vector<double> heights;
  for (const Sample& s : samples) heights.push_back(s.height);
  result.height = Median(heights);
  const double band_lo = std::min(request.settings.band_div[0], request.settings.band_div[1]);
  const double band_hi = std::max(request.settings.band_div[0], request.settings.band_div[1]);
  constexpr double kBandSlackDiv = 0.15;
  for (Sample& s : samples) {
    s.keep = s.height >= options.min_relative_height * result.height &&
             s.screen_div.y >= band_lo - kBandSlackDiv &&
             s.screen_div.y <= band_hi + kBandSlackDiv && s.screen_div.x >= 0.0 &&
             s.screen_div.x <= graticule.divisions[0];
    s.confidence = std::min(1.0, s.height / result.height) * (1.0 - 0.5 * s.crossing_share);
  }
  std::erase_if(samples, [](const Sample& s) { return !s.keep; });
  TrimDashEnds(samples, step_div, options.min_local_height);
  std::erase_if(samples, [](const Sample& s) { return !s.keep; });
  // The trace's height where its line is seen whole: a chopped trace's dash
  // ends (a quarter of its samples when the dashes are a few widths long) are
  // dimmer, and would make a sparse dashed trace look no brighter than a
  // grid line.
  if (!samples.empty()) {
    std::vector<double> whole;
    for (const Sample& s : samples) whole.push_back(s.height);
    result.height = Median(whole);
  }
  DropShortRuns(samples, step_div, width_px, 1.25 * width_px);
  std::erase_if(samples, [](const Sample& s) { return !s.keep; });
  result.noise_px =
      RejectOutliers(samples, step_div, px_per_div, options.outlier_sigmas, &result.outliers);
  std::erase_if(samples, [](const Sample& s) { return !s.keep; });
  DropCorners(samples, std::max(2.0, width_px), step_div);
  // Where two stretches of the trace merge (a cusp, a crossing) the line
  // looks wider than the trace and its centre is not defined.
  for (Sample& s : samples) {
    if (s.fwhm_px > options.max_relative_width * width_px) s.keep = false;
  }
  std::erase_if(samples, [](const Sample& s) { return !s.keep; });

  std::erase_if(samples, [&](const Sample& s) { return s.confidence < options.min_confidence; });
  const digitize::SpreadEstimate spread =
      UndoCurvaturePull(samples, step_div, px_per_div, width_px);
  if (spread.found) {
    result.spread_px2 = spread.variance_px2;
    result.spread_sigma_px2 = spread.sigma_px2;
  }

  // Time must increase: where the trace runs back (it cannot, but a steep
  // stretch's samples may), the later sample goes.
  const TraceSettings& ts = request.settings;
  const double sigma_px = std::hypot(result.noise_px, 0.5 * graticule.residual_px);
  double last_time = -std::numeric_limits<double>::infinity();
  for (const Sample& s : samples) {
    const double time = (s.screen_div.x - ts.t0_div) * ts.time_per_div;
    if (!(time > last_time)) continue;
    last_time = time;
    result.trace.time_s.push_back(time);
    result.trace.volts.push_back((s.screen_div.y - ts.zero_div) * ts.volts_per_div);
    result.trace.sigma_volts.push_back(sigma_px / std::sqrt(std::max(s.confidence, 0.05)) /
                                       px_per_div * std::abs(ts.volts_per_div));
    result.confidence.push_back(s.confidence);
    result.centre_px.push_back(s.centre_px);
    result.screen_div.push_back(s.screen_div);
  }
  result.coverage = result.trace.time_s.size() * step_div / graticule.divisions[0];
  return result;
}

// The share of a trace's samples lying on a horizontal grid line (a division
// line or the centre axis), within the line's and the trace's widths: a grid
// line tracked for a trace lies on one all along, a trace only where it
// runs along one.
double ShareOnGridLines(const DigitizedTrace& trace, const GraticuleFit& graticule) {
  if (trace.screen_div.empty() || !(graticule.px_per_div > 0.0)) return 0.0;
  // Within the line's and the trace's half widths of each other, both ways,
  // the two overlap. A grid line followed by mistake is measured as wide as a
  // line, so the trace's width counts only up to a line's: a bold trace (a
  // third of a division, printed) would otherwise lie "on" a line over most
  // of the screen.
  const double reach_div =
      std::max(graticule.line_width_px + std::min(trace.width_px, graticule.line_width_px), 2.0) /
      graticule.px_per_div;
  const double half_height = 0.5 * graticule.divisions[1];
  std::size_t on = 0;
  for (const cv::Point2d& p : trace.screen_div) {
    const double from_line = p.y + half_height;
    if (std::abs(from_line - std::round(from_line)) <= reach_div || std::abs(p.y) <= reach_div) {
      ++on;
    }
  }
  return static_cast<double>(on) / trace.screen_div.size();
}

// A trace saturated like the grid's lines (a bold line printed in a
// report's figure, in the grid's own ink) stands no higher than they do, and
// where it runs along one for much of the sweep (a contact level, a
// calibration's flat ends) it lies on the lines as a grid line followed by
// mistake does. A person tells it from them by its width: a grid line
// followed is measured as wide as the grid's lines (0.8-1.2 times on the
// ridge image of thin lines; up to 1.6 on the images of bold and wide lines,
// where a halftone's rows of dots and the lines' crossings widen it), while
// a bold trace measures twice to three times their width.
constexpr double kWiderThanGridLine = 1.75;

// A trace followed off the grid's rows is judged as any reading is, and more
// strictly: it must lie off the grid's lines in more than half its samples
// (below kOffRowsMaxOnLines), be seen off them along options' min_coverage of
// the sweep, and stand at least kOffRowsMinHeight as high as a grid line.
// Printed in the grid's ink, it stands as high as the lines; a hair or a
// scratch a course takes beside a faint trace stands far lower (randomised
// seed 1014's run 0.713: 0.43, a fifth of its samples half a division off).
// A reading whose samples still lie mostly on the lines was drawn back onto
// them, or onto strokes beside them: randomised seed 2022's calibration
// L-0.405, 78 % on the lines, its last samples on a pen stroke 0.7 division
// off the trace, misread its run's largest rebound by 28 % of X0.
constexpr double kOffRowsMinHeight = 0.8, kOffRowsMaxOnLines = 0.5;

struct OffRowsReading {
  CoarsePath path;
  DigitizedTrace trace;
};

// A trace whose course followed the grid's lines (refused: it lies on them
// and stands no higher) may be beside them: a trace printed in the grid's
// own ink, as dark as its lines and no narrower at the working scale, which
// the course leaves for a row that pays as well and runs straight. Once the
// lattice is known, its rows are known: the course is sought again with no
// candidate on a horizontal line's row, and it then takes the trace, bridging
// its crossings of the rows. Empty where the reading is not taken.
std::optional<OffRowsReading> ReadOffGridRows(
    const PreparedPhoto& photo, const GraticuleFit& graticule, const TraceRequest& request,
    const TraceOptions& options, const digitize::TrackGrid& grid, const digitize::Claims& claims,
    std::optional<digitize::Chopper> beam_chopper) {
  CoarsePath path =
      digitize::TrackTrace(photo, graticule, request.settings, options, grid, claims,
                           /*off_grid_rows=*/true, request.one_way_until_s > 0.0, beam_chopper);
  if (path.seen_columns == 0) return std::nullopt;
  DigitizedTrace trace = MeasureTrace(photo, graticule, request, path, options);
  const double on_lines = ShareOnGridLines(trace, graticule);
  if (trace.trace.time_s.empty() || on_lines >= kOffRowsMaxOnLines ||
      trace.coverage * (1.0 - on_lines) < options.min_coverage ||
      trace.height < kOffRowsMinHeight * graticule.line_contrast) {
    return std::nullopt;
  }
  return OffRowsReading{std::move(path), std::move(trace)};
}

bool WiderThanGridLines(const DigitizedTrace& trace, const GraticuleFit& graticule) {
  return graticule.line_width_px > 0.0 &&
         trace.width_px >= kWiderThanGridLine * graticule.line_width_px;
}

// A hinted point may lie this far outside its trace's band (the tracking's
// strip reaches as far), divisions.
constexpr double kHintBandMarginDiv = 0.15;

std::string BandText(const TraceSettings& settings) {
  return fmt::format("[{:g}, {:g}] div", settings.band_div[0], settings.band_div[1]);
}

// A trace not found names the hint that would help, or, when it was given,
// what to check in it.
std::string PointsAdvice(const TraceRequest& request) {
  return request.settings.points_px.empty()
             ? "; if the trace is there, give a few pixels it passes through: points = [[x, y], "
               "...] in its trace table (docs/manifest.md)"
             : " (tracked through the points given: do they lie on the trace?)";
}

// A hinted point must lie on the screen, in the trace's band: a point
// elsewhere is a slip (another trace's, or the wrong photo's pixels).
void CheckPoints(const PreparedPhoto& photo, const GraticuleFit& graticule,
                 const TraceRequest& request) {
  const TraceSettings& s = request.settings;
  const double lo = std::min(s.band_div[0], s.band_div[1]) - kHintBandMarginDiv;
  const double hi = std::max(s.band_div[0], s.band_div[1]) + kHintBandMarginDiv;
  const cv::Size size = photo.image.size();
  for (std::size_t i = 0; i < s.points_px.size(); ++i) {
    const cv::Point2d p(s.points_px[i][0], s.points_px[i][1]);
    const std::string key = fmt::format("traces.{}.points[{}]", request.name, i);
    if (!(p.x >= -0.5 && p.y >= -0.5 && p.x <= size.width - 0.5 && p.y <= size.height - 0.5)) {
      throw InputError(
          {photo.source, key, std::nullopt},
          fmt::format("the point [{:g}, {:g}] lies outside the photo of {} x {} pixels", p.x, p.y,
                      size.width, size.height));
    }
    const cv::Point2d screen = graticule.mapping.ScreenFromImage(p);
    const bool on_screen =
        screen.x >= -kHintBandMarginDiv && screen.x <= graticule.divisions[0] + kHintBandMarginDiv;
    if (!on_screen || !(screen.y >= lo && screen.y <= hi)) {
      throw InputError(
          {photo.source, key, std::nullopt},
          fmt::format("the point [{:g}, {:g}] of trace '{}' lies at screen ({:.2f}, {:.2f}) div, "
                      "outside its band {} (x from 0 to {})",
                      p.x, p.y, request.name, screen.x, screen.y, BandText(s),
                      graticule.divisions[0]));
    }
  }
}

// The traces read in turn, and their courses.
struct Reading {
  std::vector<DigitizedTrace> traces;
  std::vector<CoarsePath> paths;
};

// Every trace of `requests` read in turn, each displacement trace's course
// sought with `beam_chopper` (their shared chopper, when known).
Reading ReadEachTrace(const PreparedPhoto& photo, const GraticuleFit& graticule,
                      const std::vector<TraceRequest>& requests, const TraceOptions& options,
                      const digitize::TrackGrid& grid,
                      std::optional<digitize::Chopper> beam_chopper) {
  // Contact (step) traces first: their levels and edges are unmistakable,
  // and what they take is not offered to the traces whose bands they share.
  std::vector<std::size_t> order(requests.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_partition(order.begin(), order.end(),
                        [&](std::size_t i) { return requests[i].settings.impact.has_value(); });
  Claims claims(grid.columns);
  Reading reading{std::vector<DigitizedTrace>(requests.size()),
                  std::vector<CoarsePath>(requests.size())};
  std::vector<DigitizedTrace>& results = reading.traces;
  for (const std::size_t i : order) {
    const TraceRequest& request = requests[i];
    CheckPoints(photo, graticule, request);
    // A contact trace is drawn by a beam of its own, unchopped.
    const std::optional<digitize::Chopper> chopper =
        request.settings.impact ? std::nullopt : beam_chopper;
    CoarsePath path =
        digitize::TrackTrace(photo, graticule, request.settings, options, grid, claims,
                             /*off_grid_rows=*/false, request.one_way_until_s > 0.0, chopper);
    DigitizedTrace trace;
    if (path.seen_columns > 0) trace = MeasureTrace(photo, graticule, request, path, options);
    // What lies on the grid's lines and stands out only as much as they do
    // is a grid line, unless it is far wider than they are (WiderThanGridLines,
    // on a last reading). Off them no line of the graticule can pass for a trace, however faint
    // the trace (a print's bright graticule, a fast beam).
    const auto bright_enough_of = [&](const DigitizedTrace& t) {
      return t.height >= options.min_height_over_grid * graticule.line_contrast ||
             ShareOnGridLines(t, graticule) < 0.5 ||
             (options.tell_bold_by_width && WiderThanGridLines(t, graticule));
    };
    bool bright_enough = bright_enough_of(trace);
    // Refused as a grid line, a continuous trace is sought again off the
    // grid's rows (ReadOffGridRows); a contact trace's levels lie on them by
    // design, and are never sought so.
    if (options.off_grid_rows && !bright_enough && !request.settings.impact) {
      if (std::optional<OffRowsReading> again =
              ReadOffGridRows(photo, graticule, request, options, grid, claims, chopper)) {
        trace = std::move(again->trace);
        path = std::move(again->path);
        bright_enough = true;
      }
    }
    const bool seen = !trace.trace.time_s.empty() && trace.coverage >= options.min_coverage;
    if (seen && !bright_enough) {
      // Say what was seen: a line along the sweep, but no brighter than the
      // grid (nor wider, where the grid's line width is measured).
      const std::string how_wide =
          graticule.line_width_px > 0.0
              ? fmt::format(" and {:.2f} times as wide", trace.width_px / graticule.line_width_px)
              : std::string();
      const std::string wide_needed = graticule.line_width_px > 0.0
                                          ? fmt::format(" or {:.2f} as wide", kWiderThanGridLine)
                                          : std::string();
      throw InputError(
          {photo.source, "traces." + request.name, std::nullopt},
          fmt::format("trace '{}' not found in its band {}: a line is seen along {:.0f} % of the "
                      "sweep, but it stands only {:.2f} times as high as a grid line{}, at least "
                      "{:.2f} as high{} needed to tell it from one{}",
                      request.name, BandText(request.settings), 100.0 * trace.coverage,
                      trace.height / graticule.line_contrast, how_wide,
                      options.min_height_over_grid, wide_needed, PointsAdvice(request)));
    }
    if (!seen) {
      throw InputError(
          {photo.source, "traces." + request.name, std::nullopt},
          fmt::format("trace '{}' not found in its band {}: a line is seen along {:.0f} % "
                      "of the sweep, at least {:.0f} % needed{}",
                      request.name, BandText(request.settings), 100.0 * trace.coverage,
                      100.0 * options.min_coverage, PointsAdvice(request)));
    }
    // Claim the course and the trace's glow, a few widths either side.
    digitize::Claim(path, 3.0 * trace.width_px / graticule.px_per_div + 0.5 / grid.px_per_div,
                    claims);
    trace.from_points_hint = !request.settings.points_px.empty();
    results[i] = std::move(trace);
    reading.paths[i] = std::move(path);
  }
  return reading;
}

}  // namespace

std::vector<DigitizedTrace> ExtractTraces(const PreparedPhoto& photo, const GraticuleFit& graticule,
                                          const std::vector<TraceRequest>& requests,
                                          const TraceOptions& options) {
  if (std::string error; !options.Check(&error)) {
    throw std::invalid_argument("trace options: " + error);
  }
  for (const TraceRequest& request : requests) {
    const TraceSettings& s = request.settings;
    if (!(s.time_per_div > 0.0) || s.volts_per_div == 0.0 || !std::isfinite(s.volts_per_div) ||
        !std::isfinite(s.zero_div) || !std::isfinite(s.t0_div) || !std::isfinite(s.band_div[0]) ||
        !std::isfinite(s.band_div[1]) || s.band_div[0] == s.band_div[1]) {
      throw std::invalid_argument(fmt::format(
          "trace '{}': time_per_div must be positive, volts_per_div non-zero, the band not empty "
          "and all settings finite",
          request.name));
    }
  }
  const TrackGrid grid = digitize::MakeTrackGrid(photo, graticule, options);
  Reading first = ReadEachTrace(photo, graticule, requests, options, grid, std::nullopt);
  // The displacement traces of a photo are one beam's signals, chopped or
  // alternated (a dual-trace scope's modes): chopped, every one of them is
  // drawn in dashes. Where one reads in dashes and another does not, the
  // other's course may have taken a continuous line (a hair, a stroke along
  // the band) that outshone its dashes all along, and shows no chopper of
  // its own to judge it by: the traces are read again with the chopper the
  // dashed one shows. The second reading stands unless it loses a trace.
  std::optional<digitize::Chopper> beam_chopper;
  bool unbroken = false;
  for (std::size_t i = 0; i < requests.size(); ++i) {
    if (requests[i].settings.impact) continue;
    if (!digitize::ReadInDashes(first.traces[i])) {
      unbroken = true;
    } else if (!beam_chopper) {
      beam_chopper = digitize::ChopperOf(first.paths[i]);
    }
  }
  if (beam_chopper && unbroken) {
    try {
      return ReadEachTrace(photo, graticule, requests, options, grid, beam_chopper).traces;
    } catch (const InputError&) {
      // Read so, a trace is lost: the first reading stands.
    }
  }
  return std::move(first.traces);
}

}  // namespace impactlab
