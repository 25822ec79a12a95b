// GraticuleMapping: the homography and the radial term, both ways.
#include <cmath>

#include "digitize/digitize.h"
#include "digitize/screen_geometry.h"

namespace impactlab {

cv::Point2d GraticuleMapping::ImageFromScreen(cv::Point2d screen_div) const {
  return digitize::ImageFromScreen(*this, screen_div);
}

cv::Point2d GraticuleMapping::ScreenFromImage(cv::Point2d image_px) const {
  cv::Point2d q = image_px;
  if (radial_k1 != 0.0) {
    // Solve r + k r^3 = r_d for the undistorted radius r (k = k1 / R^2).
    const cv::Point2d d = image_px - distortion_centre_px;
    const double distorted = std::hypot(d.x, d.y);
    if (distorted > 0.0) {
      const double k = radial_k1 / (distortion_radius_px * distortion_radius_px);
      double r = distorted;
      for (int iteration = 0; iteration < 20; ++iteration) {
        const double step = (r + k * r * r * r - distorted) / (1.0 + 3.0 * k * r * r);
        r -= step;
        if (std::abs(step) < 1e-12 * (1.0 + r)) break;
      }
      q = distortion_centre_px + d * (r / distorted);
    }
  }
  const cv::Vec3d s = homography.inv() * cv::Vec3d(q.x, q.y, 1.0);
  return {s[0] / s[2], s[1] / s[2]};
}

double GraticuleMapping::PixelsPerDivisionAt(cv::Point2d screen_div) const {
  constexpr double kStepDiv = 1e-3;
  const cv::Point2d centre = ImageFromScreen(screen_div);
  const cv::Point2d along_x = ImageFromScreen(screen_div + cv::Point2d(kStepDiv, 0.0)) - centre;
  const cv::Point2d along_y = ImageFromScreen(screen_div + cv::Point2d(0.0, kStepDiv)) - centre;
  return std::sqrt(std::abs(along_x.cross(along_y))) / kStepDiv;
}

}  // namespace impactlab
