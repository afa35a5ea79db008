// Renders a RobotModel as a human-readable table or as JSON. Shared by
// robotalk-describe (a local URDF) and the robotalk client CLI (a remote robot).
#pragma once

#include "robotalk/robot_model.h"

#include <ostream>
#include <string>
#include <vector>

namespace robotalk {

/// Tables of links, joints (dofs, limits, servo types), control frames and roots.
void PrintModelTable(const RobotModel& model, std::ostream& out);

/// One JSON object. Infinite limits are written as null ("no limit").
/// `warnings` (import warnings) go into a "warnings" array.
void PrintModelJson(const RobotModel& model, const std::vector<std::string>& warnings, std::ostream& out);

}  // namespace robotalk
