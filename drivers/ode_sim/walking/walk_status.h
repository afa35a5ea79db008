// What the ode driver's walking controller reports (OdeDriver::walk_status()):
// for tests, the benchmark and the plots. Plain data.
#pragma once

#include "walking/gait.h"

#include <Eigen/Core>

namespace robotalk::walking {

struct WalkStatus {
  bool stepping = false;  ///< a step schedule is running (GOTO, SETSPEED or the steps of a STOP)
  bool fallen = false;    ///< the torso tilted past the bound; the driver halted the walk
  double tilt = 0;        ///< torso tilt from vertical now, rad
  int steps_taken = 0;    ///< footsteps started since the driver was built
  // In the world frame (the plan mapped with the pelvis pose measured when it was made):
  Eigen::Vector2d com_plan = Eigen::Vector2d::Zero();  ///< planned CoM, m
  Eigen::Vector2d zmp_ref = Eigen::Vector2d::Zero();   ///< reference ZMP, m
  Pose2 foot[2];                                       ///< planned feet (left, right)
  double foot_height[2] = {0, 0};                      ///< m
  // Measured.
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  ///< whole-body CoM from the physics, m
  Pose2 pelvis;                                   ///< the root's planar pose
};

}  // namespace robotalk::walking
