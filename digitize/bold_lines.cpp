#include "digitize/bold_lines.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace impactlab::digitize {

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
  cv::Mat1f opened;
  cv::morphologyEx(photo.working, opened, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
  bold.ridge = photo.working - opened;
  return bold;
}

}  // namespace impactlab::digitize
