#include "digitize/hand_marks.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "digitize/grey_ink.h"
#include "digitize/select.h"

namespace impactlab::digitize {

namespace {

// A mark is at least this much wider than the beam's line (its full width
// at half height, glow included).
constexpr double kMarkWidthOverTrace = 1.25;
// Its ink stands at least this share of a trace's height above its
// surroundings (a yellow pencil on a grey print is dimmer than the trace).
constexpr double kMarkHeightOverTrace = 0.5;
// And it is at least this long: a written character, an arrow, a stroke.
// Smaller bright specks are dust, which the samples' outlier tests take.
constexpr double kMarkMinExtentDiv = 0.2;
// The opening's square is at least this many mask pixels wide.
constexpr int kMinSquarePx = 4;
// A first reading's samples are the beam's course where they run unbroken
// (gaps at most kCourseGapDiv) over at least kCourseMinDiv, divisions.
constexpr double kCourseGapDiv = 0.05, kCourseMinDiv = 0.5;
// How far beyond the graticule a mark is looked for, divisions.
constexpr double kScreenMarginDiv = 0.1;

// The mask pixel (shrunk by `f`, origin at `origin`) a photo point lies in:
// mask pixel (u, v) covers photo pixels [f u, f u + f) x [f v, f v + f).
cv::Point MaskPixel(cv::Point2d photo_px, int f, cv::Point origin = {}) {
  return {static_cast<int>(std::floor(photo_px.x / f)) - origin.x,
          static_cast<int>(std::floor(photo_px.y / f)) - origin.y};
}

// Mask pixels (origin at `origin`) of the screen segment `from`-`to`, divisions.
std::vector<cv::Point> MaskPoints(const GraticuleFit& graticule, int f, cv::Point origin,
                                  cv::Point2d from, cv::Point2d to) {
  constexpr int kSteps = 16;  // enough to follow a lens's bending of a division line
  std::vector<cv::Point> points;
  for (int i = 0; i <= kSteps; ++i) {
    points.push_back(MaskPixel(
        graticule.mapping.ImageFromScreen(from + (to - from) * (1.0 * i / kSteps)), f, origin));
  }
  return points;
}

// The graticule grown by `margin_div` on each side, as a closed outline.
std::vector<cv::Point> ScreenOutline(const GraticuleFit& graticule, int f, cv::Point origin,
                                     double margin_div) {
  const double x0 = -margin_div, x1 = graticule.divisions[0] + margin_div;
  const double y1 = 0.5 * graticule.divisions[1] + margin_div, y0 = -y1;
  const std::array<cv::Point2d, 5> corners = {
      cv::Point2d{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}, {x0, y0}};
  std::vector<cv::Point> outline;
  for (int k = 0; k < 4; ++k) {
    const std::vector<cv::Point> side =
        MaskPoints(graticule, f, origin, corners[k], corners[k + 1]);
    outline.insert(outline.end(), side.begin(), side.end() - 1);
  }
  return outline;
}

// Where a mark may lie (255): on the screen, a division's tenth round the
// graticule (a mark outside it touches no trace, and the print's border and
// the bezel's lip beyond are edges, not strokes), and off the graticule's
// lines: each division line a line's width and a pixel either side, the
// centre axes as far as their tick marks reach (0.12 division).
cv::Mat1b MarkGround(const GraticuleFit& graticule, int f, const cv::Rect& region) {
  cv::Mat1b ground(region.size(), uchar{0});
  const std::vector<std::vector<cv::Point>> screen = {
      ScreenOutline(graticule, f, region.tl(), kScreenMarginDiv)};
  cv::fillPoly(ground, screen, cv::Scalar(255));
  const int nx = graticule.divisions[0], ny = graticule.divisions[1];
  const double half = 0.5 * ny;
  const int line_px = std::max(1, static_cast<int>(std::ceil((graticule.line_width_px + 2.0) / f)));
  const int axis_px = std::max(1, static_cast<int>(std::ceil(0.24 * graticule.px_per_div / f)));
  const auto clear = [&](cv::Point2d from, cv::Point2d to, int width) {
    cv::polylines(ground, MaskPoints(graticule, f, region.tl(), from, to), false, cv::Scalar(0),
                  width);
  };
  for (int i = 0; i <= nx; ++i) {
    clear({1.0 * i, -half}, {1.0 * i, half}, 2 * i == nx ? axis_px : line_px);
  }
  for (int j = 0; j <= ny; ++j) {
    clear({0.0, j - half}, {1.0 * nx, j - half}, 2 * j == ny ? axis_px : line_px);
  }
  return ground;
}

// A reading's samples in runs with gaps of at most kCourseGapDiv.
struct SampleRun {
  std::size_t first = 0, end = 0;  // samples [first, end)
  double length_div = 0.0;
  double gap_before_div = 0.0;  // from the previous run's last sample
};

std::vector<SampleRun> UnbrokenRuns(const std::vector<cv::Point2d>& screen) {
  std::vector<SampleRun> runs;
  std::size_t first = 0;
  for (std::size_t i = 1; i <= screen.size(); ++i) {
    if (i < screen.size() && screen[i].x - screen[i - 1].x <= kCourseGapDiv) continue;
    runs.push_back({first, i, screen[i - 1].x - screen[first].x,
                    first > 0 ? screen[first].x - screen[first - 1].x : 0.0});
    first = i;
  }
  return runs;
}

std::vector<float> RunLengths(const std::vector<SampleRun>& runs) {
  std::vector<float> lengths;
  for (const SampleRun& r : runs) lengths.push_back(static_cast<float>(r.length_div));
  return lengths;
}

// Whether a reading shows a chopped beam: many runs, nearly all short and
// alike, with gaps alike between them (a chopper is periodic). A continuous
// trace seen in pieces (broken at grid lines, on faint flanks) has few runs
// or runs and gaps of every length.
bool DrawnInDashes(const std::vector<SampleRun>& runs) {
  constexpr std::size_t kMinRuns = 10;
  constexpr double kRegularShare = 0.8;
  if (runs.size() < kMinRuns) return false;
  std::vector<float> gaps;
  for (const SampleRun& r : runs) {
    if (&r != &runs.front()) gaps.push_back(static_cast<float>(r.gap_before_div));
  }
  const auto regular = [&](std::vector<float> values) {
    const double usual = MedianOf(values);
    const auto alike =
        std::count_if(values.begin(), values.end(), [&](float v) { return v <= 2.0 * usual; });
    return usual < kCourseMinDiv && alike >= kRegularShare * static_cast<double>(values.size());
  };
  return regular(RunLengths(runs)) && regular(gaps);
}

// Clears `allowed` (mask pixels, origin at `origin`) within half a trace's
// width (its own, or the beam's `width_px` if wider) of the samples a
// reading of the traces measured in long unbroken runs: the beam's course,
// however thick it is there. A first reading may stray onto a mark too, but
// there only briefly (a label's strokes, a stroke's crossing). A chopped
// trace's course is its dashes: the runs as long as its usual dash (up to
// kDashOverUsual times it) are cleared, however thick a dash is (at a
// peak, where the beam is slow, it glows wider than on the flanks:
// randomised seed 1018's run 0.713 lost a rebound's peak to that), and
// what its reading followed unbroken for longer (a ring's arc, a stroke
// along it) is not its own and stays.
constexpr double kDashOverUsual = 2.0;

void ClearCourses(const std::vector<DigitizedTrace>& traces, int f, cv::Point origin,
                  double width_px, cv::Mat1b& allowed) {
  for (const DigitizedTrace& trace : traces) {
    const std::vector<SampleRun> runs = UnbrokenRuns(trace.screen_div);
    // A contact trace is drawn by a beam of its own, never chopped, and is
    // read first, its levels and edges unmistakable: every run of it is its
    // course, the short ones too (its reading broken at every tick of a
    // centre axis it runs along is as regular as dashes: randomised seed
    // 1007's run 0.405, a bold printed contact trace, had its levels taken
    // for two marks and its pulse lost).
    const bool contact = trace.settings.impact.has_value();
    const bool dashed = !contact && DrawnInDashes(runs);
    const double shortest_course = contact ? 0.0 : kCourseMinDiv;
    double longest_dash = 0.0;
    if (dashed) {
      std::vector<float> lengths = RunLengths(runs);
      longest_dash = kDashOverUsual * MedianOf(lengths);
    }
    const double half_width_px = 0.5 * std::max(width_px, trace.width_px);
    for (const SampleRun& run : runs) {
      if (dashed ? run.length_div > longest_dash : run.length_div < shortest_course) continue;
      // A dash is cleared as far as its own half length reaches: its glow,
      // however wide, lies within it.
      const double reach_px =
          dashed
              ? std::max(half_width_px,
                         0.5 * cv::norm(trace.centre_px[run.end - 1] - trace.centre_px[run.first]))
              : half_width_px;
      const int radius = std::max(1, static_cast<int>(std::lround(reach_px / f)));
      for (std::size_t k = run.first; k < run.end; ++k) {
        cv::circle(allowed, MaskPixel(trace.centre_px[k], f, origin), radius, cv::Scalar(0),
                   cv::FILLED);
      }
    }
  }
}

}  // namespace

bool ReadInDashes(const DigitizedTrace& trace) {
  return DrawnInDashes(UnbrokenRuns(trace.screen_div));
}

bool HandMarkMap::Covers(cv::Point2d photo_px) const {
  if (mask.empty()) return false;
  const cv::Point p = MaskPixel(photo_px, shrink);
  return p.x >= 0 && p.y >= 0 && p.x < mask.cols && p.y < mask.rows && mask(p) != 0;
}

HandMarkMap FindHandMarks(const PreparedPhoto& photo, const GraticuleFit& graticule,
                          double trace_width_px, double trace_height,
                          const std::vector<DigitizedTrace>& first_reading) {
  HandMarkMap marks;
  const double square_px =
      kMarkWidthOverTrace * std::max({trace_width_px, graticule.line_width_px, 1.0}) + 1.0;
  // Shrunk so that the square is a few pixels wide: fine enough for a thin
  // pencil, and a quarter of the pixels or fewer on a sharp photo.
  const int f = std::max(1, static_cast<int>(std::floor(square_px / kMinSquarePx)));
  const int square = std::max(3, 2 * static_cast<int>(std::floor(0.5 * square_px / f)) + 1);
  marks.shrink = f;
  // The screen and, round it, room for the wider square (an opening is
  // wrong within its square's reach of the region's edge), in whole mask
  // pixels; only that much of the photo is shrunk.
  const int ground_square = 4 * square + 1;
  const cv::Size mask_size(photo.image.cols / f, photo.image.rows / f);
  const cv::Rect screen = cv::boundingRect(ScreenOutline(graticule, f, {0, 0}, kScreenMarginDiv));
  const cv::Rect area = (screen + cv::Size(2 * ground_square, 2 * ground_square) -
                         cv::Point(ground_square, ground_square)) &
                        cv::Rect({0, 0}, mask_size);
  if (area.width < 2 * ground_square || area.height < 2 * ground_square) return marks;
  const cv::Rect area_px(area.x * f, area.y * f, area.width * f, area.height * f);
  const cv::Mat1b region = ShrunkInk8(photo.image(area_px), f, photo.dark_traces);

  // What survives the square (ink at least that wide) over what survives a
  // square four times wider (the ground: glare, the face's light).
  cv::Mat1b wide, ground;
  cv::morphologyEx(region, wide, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(square, square)));
  cv::morphologyEx(region, ground, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, {ground_square, ground_square}));
  // In place, wide then ground: each fresh buffer costs its pages.
  cv::Mat1b& thick = wide;
  cv::subtract(wide, ground, thick);
  cv::Mat1b& candidate = ground;
  cv::compare(thick, 255.0 * kMarkHeightOverTrace * std::max(trace_height, 0.02), candidate,
              cv::CMP_GT);
  // A trace along a grid line, or along a centre axis and its tick marks,
  // is as wide as a stroke together with them, and a trace is thick where
  // it is slow or printed: what lies mostly where the graticule draws, on a
  // course the first reading measured, or off the screen, is not a mark. A
  // mark crossing the graticule's lines or a trace stays whole.
  cv::Mat1b allowed = MarkGround(graticule, f, area);
  ClearCourses(first_reading, f, area.tl(), trace_width_px, allowed);

  // Whole strokes, long enough to be written: a stroke the square wide and
  // the shortest mark long, half of it where a mark may lie, has at least
  // this many pixels there. On clean photos there are a handful at most,
  // and the labelling below, the search's dearest step, is skipped.
  const double min_extent = kMarkMinExtentDiv * graticule.px_per_div / f;
  cv::Mat1b& allowed_candidate = allowed;
  cv::bitwise_and(candidate, allowed, allowed_candidate);
  if (cv::countNonZero(allowed_candidate) < 0.5 * min_extent * square) return marks;
  cv::Mat1i labels, stats;
  cv::Mat centroids;
  const int count = cv::connectedComponentsWithStats(candidate, labels, stats, centroids, 8);
  std::vector<int> allowed_pixels(count, 0);
  for (int r = 0; r < labels.rows; ++r) {
    for (int c = 0; c < labels.cols; ++c) {
      if (allowed_candidate(r, c) != 0) ++allowed_pixels[labels(r, c)];
    }
  }
  std::vector<bool> keep(count, false);
  bool any = false;
  for (int i = 1; i < count; ++i) {
    const double extent = std::hypot(stats(i, cv::CC_STAT_WIDTH), stats(i, cv::CC_STAT_HEIGHT));
    keep[i] = extent >= min_extent && 2 * allowed_pixels[i] >= stats(i, cv::CC_STAT_AREA);
    any = any || keep[i];
  }
  if (!any) return marks;
  cv::Mat1b strokes(region.size(), uchar{0});
  for (int r = 0; r < labels.rows; ++r) {
    for (int c = 0; c < labels.cols; ++c) {
      if (keep[labels(r, c)]) strokes(r, c) = 255;
    }
  }
  // The stroke's glow, and the reach of a trace's profile beside it.
  const int grow = static_cast<int>(std::ceil((1.5 * trace_width_px + 2.0) / f));
  cv::dilate(strokes, strokes,
             cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * grow + 1, 2 * grow + 1}));
  marks.mask = cv::Mat1b(mask_size, uchar{0});
  strokes.copyTo(marks.mask(area));

  std::vector<std::vector<cv::Point>> outlines;
  cv::findContours(marks.mask, outlines, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
  for (std::vector<cv::Point>& outline : outlines) {
    for (cv::Point& p : outline) p = p * f + cv::Point(f / 2, f / 2);
  }
  marks.outlines_px = std::move(outlines);
  return marks;
}

PreparedPhoto WithoutMarks(const PreparedPhoto& photo, const HandMarkMap& marks) {
  PreparedPhoto out = photo;
  out.ridge = photo.ridge.clone();
  for (int r = 0; r < out.ridge.rows; ++r) {
    float* p = out.ridge.ptr<float>(r);
    for (int c = 0; c < out.ridge.cols; ++c) {
      if (marks.Covers(photo.PhotoFromWorking({static_cast<double>(c), static_cast<double>(r)}))) {
        p[c] = 0.0f;
      }
    }
  }
  return out;
}

namespace {

// Whether the straight course from `a` to `b` (photo pixels) crosses a mark:
// checked at every mask pixel's step along it.
bool CourseCrossesMark(const HandMarkMap& marks, cv::Point2d a, cv::Point2d b) {
  const int steps = std::max(1, static_cast<int>(std::ceil(cv::norm(b - a) / marks.shrink)));
  for (int k = 1; k < steps; ++k) {
    if (marks.Covers(a + (b - a) * (static_cast<double>(k) / steps))) return true;
  }
  return false;
}

}  // namespace

std::vector<std::array<double, 2>> DropSamplesOnMarks(const HandMarkMap& marks,
                                                      DigitizedTrace& trace) {
  std::vector<std::array<double, 2>> stretches;
  // Joins the last stretch when `from` lies before its end, or starts one.
  const auto take = [&](double from, double to) {
    if (!stretches.empty() && from <= stretches.back()[1]) {
      stretches.back()[0] = std::min(stretches.back()[0], from);
      stretches.back()[1] = std::max(stretches.back()[1], to);
    } else {
      stretches.push_back({from, to});
    }
  };
  const std::size_t n = trace.trace.time_s.size();
  std::size_t kept = 0;
  bool dropping = false;  // the previous sample was dropped
  for (std::size_t i = 0; i < n; ++i) {
    const double x = trace.screen_div[i].x;
    if (marks.Covers(trace.centre_px[i])) {
      if (dropping) {
        stretches.back()[1] = x;
      } else {
        take(x, x);
      }
      dropping = true;
      continue;
    }
    dropping = false;
    // Between the last sample kept and this one the course crossed a mark.
    if (kept > 0 && CourseCrossesMark(marks, trace.centre_px[kept - 1], trace.centre_px[i])) {
      take(trace.screen_div[kept - 1].x, x);
    }
    trace.trace.time_s[kept] = trace.trace.time_s[i];
    trace.trace.volts[kept] = trace.trace.volts[i];
    if (!trace.trace.sigma_volts.empty())
      trace.trace.sigma_volts[kept] = trace.trace.sigma_volts[i];
    trace.confidence[kept] = trace.confidence[i];
    trace.centre_px[kept] = trace.centre_px[i];
    trace.screen_div[kept] = trace.screen_div[i];
    ++kept;
  }
  trace.trace.time_s.resize(kept);
  trace.trace.volts.resize(kept);
  if (!trace.trace.sigma_volts.empty()) trace.trace.sigma_volts.resize(kept);
  trace.confidence.resize(kept);
  trace.centre_px.resize(kept);
  trace.screen_div.resize(kept);
  return stretches;
}

}  // namespace impactlab::digitize
