// The rigid arm's inverse kinematics, for the sanding law's joint commands.
#pragma once

#include <Eigen/Core>

#include "multibody/two_link_parameters.h"

namespace impactlab {

struct JointAngles {
  double q1_rad = 0.0, q4_rad = 0.0;
};

// The joint angles that put the undeflected arm's contact tip at `target`
// (base frame), on the elbow side of `q4_hint_rad`; an unreachable target is
// met as nearly as the arm reaches (stretched or folded towards it).
JointAngles RigidInverseKinematics(const TwoLinkParameters& parameters,
                                   const Eigen::Vector2d& target, double q4_hint_rad);

}  // namespace impactlab
