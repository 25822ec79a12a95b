#include "multibody/two_link_kinematics.h"

#include <algorithm>
#include <cmath>

namespace impactlab {

JointAngles RigidInverseKinematics(const TwoLinkParameters& p, const Eigen::Vector2d& target,
                                   double q4_hint_rad) {
  const double a1 = p.beam1.hub_radius_m + p.beam1.length_m;
  // Link 2, joint B to the tip, in its own frame.
  const Eigen::Vector2d link2(
      p.beam2.hub_radius_m + p.beam2.length_m + p.tool.centre_m + p.tool.tip_x_m, p.tool.tip_y_m);
  const double a2 = link2.norm();
  const double offset = std::atan2(link2.y(), link2.x());
  const double reach = target.norm();
  const double cosine =
      std::clamp((reach * reach - a1 * a1 - a2 * a2) / (2.0 * a1 * a2), -1.0, 1.0);
  const double bend = (q4_hint_rad + offset >= 0.0 ? 1.0 : -1.0) * std::acos(cosine);
  JointAngles out;
  out.q1_rad = std::atan2(target.y(), target.x()) -
               std::atan2(a2 * std::sin(bend), a1 + a2 * std::cos(bend));
  out.q4_rad = bend - offset;
  return out;
}

}  // namespace impactlab
