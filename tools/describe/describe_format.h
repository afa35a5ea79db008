// Renders a RobotModel as a human-readable table or as JSON. Shared by
// robotalk-describe (a local URDF) and the robotalk client CLI (a remote robot).
#pragma once

#include "robotalk/robot_model.h"

#include "json_text.h"

#include <ostream>
#include <string>
#include <vector>

namespace robotalk {

/// Tables of links, joints (dofs, limits, servo types), control frames and roots.
void PrintModelTable(const RobotModel& model, std::ostream& out);

/// The model as one JSON object, keys in a fixed order: name, total_mass,
/// num_dofs, links, joints, control_frames, roots, warnings (import warnings).
/// Infinite limits are null ("no limit").
nlohmann::ordered_json ModelJson(const RobotModel& model, const std::vector<std::string>& warnings);

/// ModelJson as one line of text and a newline.
void PrintModelJson(const RobotModel& model, const std::vector<std::string>& warnings, std::ostream& out);

}  // namespace robotalk
