#include "digitize/bold_lines.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "digitize/hand_marks.h"

namespace impactlab::digitize {

namespace {

cv::Mat1f OpenedBy(const cv::Mat1f& image, int side) {
  cv::Mat1f opened;
  cv::morphologyEx(image, opened, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
  return opened;
}

}  // namespace

int BoldOpeningPx(const PreparedPhoto& photo, const GraticuleFit& graticule) {
  // Half a division keeps a printed trace a third of a division bold (the
  // widest seen) while a cell of the grid, a division wide, is still ground.
  const double half_division_px = 0.5 * graticule.px_per_div / photo.shrink;
  const int side = 2 * static_cast<int>(std::floor(0.5 * half_division_px)) + 1;
  return std::max(side, kRidgeOpeningPx);
}

PreparedPhoto WithBoldLines(const PreparedPhoto& photo, const GraticuleFit& graticule) {
  const int side = BoldOpeningPx(photo, graticule);
  PreparedPhoto bold = photo;
  bold.ridge = photo.working - OpenedBy(photo.working, side);
  bold.ridge_opening_px = side;
  return bold;
}

int WideOpeningPx(const PreparedPhoto& photo, const GraticuleFit& graticule) {
  // An opening by a square clips a line to the level at which it is as wide
  // as the square: at twice its full width at half maximum a grid line's
  // profile (a Gaussian's, or a saturated core's with its flanks) is down
  // to its foot, while a trace three or more times as wide keeps most of
  // its height.
  const double line_px = graticule.line_width_px / photo.shrink;
  const int side = 2 * static_cast<int>(std::ceil(line_px)) + 1;
  const int wide = std::max(side, kRidgeOpeningPx);
  return wide < BoldOpeningPx(photo, graticule) ? wide : 0;
}

PreparedPhoto WithWideLines(const PreparedPhoto& photo, const GraticuleFit& graticule) {
  const int side = WideOpeningPx(photo, graticule);
  const int bold_side = BoldOpeningPx(photo, graticule);
  PreparedPhoto wide = photo;
  wide.ridge_opening_px = bold_side;
  wide.ridge = OpenedBy(photo.working, side) - OpenedBy(photo.working, bold_side);
  return wide;
}

double LongGapShare(const DigitizedTrace& trace, double sweep_div) {
  if (trace.screen_div.empty() || !(sweep_div > 0.0)) return 1.0;
  double missed = 0.0, last = 0.0;
  const auto gap = [&missed](double from, double to) {
    if (to - from >= kLongGapDiv) missed += to - from;
  };
  for (const cv::Point2d& p : trace.screen_div) {
    gap(last, p.x);
    last = p.x;
  }
  gap(last, sweep_div);
  return missed / sweep_div;
}

bool AsksForBoldReading(const DigitizedTrace& trace, const PreparedPhoto& photo, double sweep_div) {
  if (trace.coverage >= kWeakCoverage || ReadInDashes(trace)) return false;
  // The width is measured in the photo; the thin image's square is in
  // working pixels.
  const bool broad = trace.width_px / photo.shrink >= kBroadShare * photo.ridge_opening_px;
  return broad || LongGapShare(trace, sweep_div) > kLongGapShare;
}

}  // namespace impactlab::digitize
