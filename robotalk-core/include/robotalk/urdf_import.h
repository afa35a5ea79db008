// Import of URDF robot descriptions through urdfdom, with the RoboTalk
// extension block (<robotalk>) for control frames, servo types and the base.
// The defect policy (what is repaired with a warning, what is refused) is in
// docs/specification.md, "URDF import".
#pragma once

#include "robotalk/robot_model.h"

#include <string>
#include <vector>

namespace robotalk {

struct UrdfImportOptions {
  /// Every warning becomes an error (UrdfError listing all of them).
  bool strict = false;
  /// Merge chains of joints joined by massless intermediate links that share
  /// the joint origin into one multi-dof joint (a pan-tilt unit becomes one
  /// 2-dof joint). The intermediate links disappear from the model.
  bool merge_massless_chains = false;
  /// Replaces the <robot name="..."> when not empty.
  std::string robot_name;
};

struct UrdfImportResult {
  RobotModel model;
  /// One line per repaired defect, each naming the element, e.g.
  /// "joint 'ptu_pan': lower limit 2.775 > upper -2.775; swapped".
  std::vector<std::string> warnings;
};

/// Reads and imports a URDF file. Throws UrdfError naming the file and what is
/// wrong (missing file, malformed XML, a joint naming an unknown link, a cycle,
/// negative mass, ...); in strict mode also for any warning.
UrdfImportResult LoadUrdfFile(const std::string& path, const UrdfImportOptions& options = {});

/// Same, from the XML text. `source_name` is used in messages.
UrdfImportResult ParseUrdf(const std::string& xml, const UrdfImportOptions& options = {},
                           const std::string& source_name = "<string>");

}  // namespace robotalk
