// Import of URDF robot descriptions through urdfdom, with the RoboTalk
// extension block (<robotalk>) for control frames, servo types and the base.
// docs/urdf_import.md has the frame conventions, the extension block reference
// and the defect policy (what is repaired with a warning, what is refused).
//
// Thread safety: the functions may be called from several threads; the
// urdfdom call inside is serialised, because urdfdom reports through
// console_bridge's process-wide output handler, which the import captures
// (urdfdom never writes to stderr during an import).
#pragma once

#include "robotalk/robot_model.h"

#include <cstddef>
#include <string>
#include <vector>

namespace robotalk {

struct UrdfImportOptions {
  /// Every warning becomes an error (UrdfError listing all of them).
  bool strict = false;
  /// Merge chains of joints joined by massless intermediate links that share
  /// the joint origin into one multi-dof joint named "J1+J2" (a pan-tilt unit
  /// becomes one 2-dof joint). The intermediate links disappear from the
  /// model. Fixed and mimic joints are never merged.
  bool merge_massless_chains = false;
  /// Replaces the <robot name="..."> when not empty.
  std::string robot_name;
  /// Largest file (or XML text) accepted, in bytes. Import needs about 40
  /// times the file size in memory (a 50 MB file took 1.8 GB); the largest
  /// real robot we know is 133 KB. A bigger input is refused before it is
  /// read whole.
  std::size_t max_file_bytes = 16 * 1024 * 1024;
  /// Deepest element nesting accepted. TinyXML parses recursively, so a
  /// document nested 100,000 deep overflows the stack; the depth is counted
  /// by a linear scan of the text before any XML parser runs. URDFs nest
  /// fewer than 10 deep.
  int max_xml_depth = 100;
};

struct UrdfImportResult {
  RobotModel model;
  /// One line per repaired defect, each naming the element, e.g.
  /// "joint 'ptu_pan': lower limit 2.775 > upper -2.775; swapped".
  std::vector<std::string> warnings;
};

/// Reads and imports a URDF file. Links and joints keep the file order as
/// indices. Throws UrdfError naming the file and what is wrong (missing file,
/// malformed XML, a joint naming an unknown link, a cycle, negative mass, a
/// typo in the <robotalk> block, a file over max_file_bytes or nested deeper
/// than max_xml_depth, ...); in strict mode also for any warning.
/// Time and memory are linear in the file size (merge_massless_chains too).
UrdfImportResult LoadUrdfFile(const std::string& path, const UrdfImportOptions& options = {});

/// Same, from the XML text. `source_name` is used in messages.
UrdfImportResult ParseUrdf(const std::string& xml, const UrdfImportOptions& options = {},
                           const std::string& source_name = "<string>");

}  // namespace robotalk
