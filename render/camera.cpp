#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace impactlab {

namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

cv::Point2d Apply(const cv::Matx33d& h, cv::Point2d p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

// Rotation by `angle` about the unit vector `axis` (Rodrigues' formula).
cv::Matx33d AxisAngleRotation(const cv::Vec3d& axis, double angle) {
  const cv::Matx33d cross(0.0, -axis[2], axis[1],  //
                          axis[2], 0.0, -axis[0],  //
                          -axis[1], axis[0], 0.0);
  return cv::Matx33d::eye() * std::cos(angle) + cross * std::sin(angle) +
         (axis * axis.t()) * (1.0 - std::cos(angle));
}

}  // namespace

cv::Point2d CameraMapping::ImageFromScreen(cv::Point2d screen_div) const {
  const cv::Point2d q = Apply(homography, screen_div);
  const cv::Point2d d = q - distortion_centre_px;
  const double r2 = (d.x * d.x + d.y * d.y) / (distortion_radius_px * distortion_radius_px);
  return distortion_centre_px + d * (1.0 + radial_k1 * r2);
}

cv::Point2d CameraMapping::ScreenFromImage(cv::Point2d image_px) const {
  const cv::Point2d d = image_px - distortion_centre_px;
  const double distorted_radius = std::hypot(d.x, d.y);
  cv::Point2d q = image_px;
  if (radial_k1 != 0.0 && distorted_radius > 0.0) {
    // Solve r + k1 r^3 / R^2 = r_d for the undistorted radius r.
    const double k = radial_k1 / (distortion_radius_px * distortion_radius_px);
    double r = distorted_radius;
    for (int iteration = 0; iteration < 20; ++iteration) {
      const double step = (r + k * r * r * r - distorted_radius) / (1.0 + 3.0 * k * r * r);
      r -= step;
      if (std::abs(step) < 1e-12 * (1.0 + r)) break;
    }
    q = distortion_centre_px + d * (r / distorted_radius);
  }
  return Apply(homography.inv(), q);
}

namespace render {

CameraMapping FrameCamera(const CameraPose& pose, const std::vector<cv::Point2d>& outline_div,
                          cv::Point2d centre_div, cv::Size image_size) {
  // The screen plane seen by a unit-focal pinhole camera: a screen point (u, v)
  // from the centre (v up) sits at R (u, -v, 0) + (0, 0, D) in camera space.
  const double tilt = pose.tilt_deg * kDegree;
  const double azimuth = pose.tilt_azimuth_deg * kDegree;
  const cv::Matx33d rotation =
      AxisAngleRotation(cv::Vec3d(std::cos(azimuth), std::sin(azimuth), 0.0), tilt);
  const cv::Matx33d plane_to_camera(rotation(0, 0), rotation(0, 1), 0.0,  //
                                    rotation(1, 0), rotation(1, 1), 0.0,  //
                                    rotation(2, 0), rotation(2, 1), pose.camera_distance_div);
  const cv::Matx33d screen_to_plane(1.0, 0.0, -centre_div.x,  //
                                    0.0, -1.0, centre_div.y,  //
                                    0.0, 0.0, 1.0);
  // Roll in the image plane; image y points down, so counter-clockwise as seen
  // is a negative mathematical angle.
  const double roll = pose.rotation_deg * kDegree;
  const cv::Matx33d roll_matrix(std::cos(roll), std::sin(roll), 0.0,   //
                                -std::sin(roll), std::cos(roll), 0.0,  //
                                0.0, 0.0, 1.0);
  const cv::Matx33d unscaled = roll_matrix * plane_to_camera * screen_to_plane;

  double x_min = std::numeric_limits<double>::max(), y_min = x_min;
  double x_max = std::numeric_limits<double>::lowest(), y_max = x_max;
  for (const cv::Point2d& p : outline_div) {
    const cv::Point2d q = Apply(unscaled, p);
    x_min = std::min(x_min, q.x), x_max = std::max(x_max, q.x);
    y_min = std::min(y_min, q.y), y_max = std::max(y_max, q.y);
  }
  const double width = image_size.width, height = image_size.height;
  const double scale = pose.fill * std::min(width / (x_max - x_min), height / (y_max - y_min));
  const cv::Point2d image_centre((width - 1.0) / 2.0, (height - 1.0) / 2.0);
  const cv::Point2d spare((width - scale * (x_max - x_min)) / 2.0,
                          (height - scale * (y_max - y_min)) / 2.0);
  const cv::Point2d outline_centre((x_min + x_max) / 2.0, (y_min + y_max) / 2.0);
  const cv::Point2d shift = image_centre +
                            cv::Point2d(spare.x * pose.offset.x, spare.y * pose.offset.y) -
                            outline_centre * scale;
  const cv::Matx33d place(scale, 0.0, shift.x,  //
                          0.0, scale, shift.y,  //
                          0.0, 0.0, 1.0);

  CameraMapping mapping;
  mapping.homography = place * unscaled;
  mapping.homography *= 1.0 / mapping.homography(2, 2);
  mapping.radial_k1 = pose.barrel_k1;
  mapping.distortion_centre_px = image_centre;
  mapping.distortion_radius_px = 0.5 * std::hypot(width, height);
  return mapping;
}

ScreenFromPixel::ScreenFromPixel(const CameraMapping& mapping)
    : screen_from_undistorted_(mapping.homography.inv()),
      centre_px_(mapping.distortion_centre_px),
      k_per_px2_(mapping.radial_k1 /
                 (mapping.distortion_radius_px * mapping.distortion_radius_px)) {}

double PixelsPerDivisionAt(const CameraMapping& mapping, cv::Point2d p) {
  constexpr double kStepDiv = 1e-3;
  const cv::Point2d centre = mapping.ImageFromScreen(p);
  const cv::Point2d along_x = mapping.ImageFromScreen(p + cv::Point2d(kStepDiv, 0.0)) - centre;
  const cv::Point2d along_y = mapping.ImageFromScreen(p + cv::Point2d(0.0, kStepDiv)) - centre;
  return std::sqrt(std::abs(along_x.cross(along_y))) / kStepDiv;
}

double MaxPixelsPerDivision(const CameraMapping& mapping, const cv::Rect2d& region_div) {
  constexpr int kSteps = 8;
  constexpr double kStepDiv = 1e-3;
  double largest = 0.0;
  for (int i = 0; i <= kSteps; ++i) {
    for (int j = 0; j <= kSteps; ++j) {
      const cv::Point2d p(region_div.x + region_div.width * i / kSteps,
                          region_div.y + region_div.height * j / kSteps);
      const cv::Point2d centre = mapping.ImageFromScreen(p);
      const cv::Point2d along_x =
          (mapping.ImageFromScreen(p + cv::Point2d(kStepDiv, 0)) - centre) / kStepDiv;
      const cv::Point2d along_y =
          (mapping.ImageFromScreen(p + cv::Point2d(0, kStepDiv)) - centre) / kStepDiv;
      // Largest singular value of the Jacobian [along_x along_y].
      const double a = along_x.dot(along_x), b = along_x.dot(along_y), d = along_y.dot(along_y);
      const double largest_eigenvalue = 0.5 * (a + d) + std::sqrt(0.25 * (a - d) * (a - d) + b * b);
      largest = std::max(largest, std::sqrt(largest_eigenvalue));
    }
  }
  return largest;
}

}  // namespace render
}  // namespace impactlab
