// robotalk-logplay export LOG --mcap OUT.mcap (docs/interop.md): a recorded
// session as an MCAP file Foxglove opens, with the channels and schemas
// robotalk-web's Foxglove endpoint publishes live (tools/web/foxglove_messages.h),
// built by the same code from the same inputs: each robot's configuration
// (ROBOTALK/<robot>/CONFIG, logged when a client connected) and its STATE
// samples, posed with the project's forward kinematics. Added for the record:
//   /ROBOT/requests  robotalk.Request     every REQUEST package as logged
//                                          (retransmissions included)
//   /ROBOT/replies   robotalk.ReplyBatch  every REPLY batch
// Every message's log time is the LCM logger's receive time; its publish
// time is the sample's server time for states (the log time otherwise).
// A robot given a URDF (McapGeometry, --urdf ROBOT=PATH) is drawn from it as
// robotalk-web draws it live, its meshes embedded in the scene; the others as
// their equivalent inertia boxes (the configuration carries no geometry).
// A robot's states before its first logged configuration cannot be posed:
// they are counted and named on `warnings`, as are undecodable messages.
//
// Thread safety: none. Errors: throws LogError when the log cannot be read
// or the file cannot be written.
#pragma once

#include "session_log.h"

#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

namespace robotalk::logplay {

struct McapExportResult {
  std::uint64_t events = 0;       ///< LCM events read
  std::uint64_t messages = 0;     ///< MCAP messages written
  std::uint64_t bytes = 0;        ///< size of the MCAP file
  std::uint64_t log_bytes = 0;    ///< payload bytes of the LCM events read
  std::uint64_t unposed = 0;      ///< states of robots without a configuration yet
  std::uint64_t undecodable = 0;  ///< RoboTalk messages that did not decode
};

/// The robots' URDFs: --urdf ROBOT=PATH, --package-path DIRS (then ROS_PACKAGE_PATH).
struct McapGeometry {
  std::map<std::string, std::string> urdf;  ///< robot -> URDF file
  std::vector<std::string> package_paths;   ///< where package:// meshes are found
};
/// From the option values; throws robotalk::Error naming a value that is not
/// NAME=PATH, a URDF file that does not exist, a path list naming no folder.
McapGeometry ParseGeometryOptions(const std::vector<std::string>& urdf,
                                  const std::vector<std::string>& package_paths,
                                  const std::string& ros_package_path);

McapExportResult ExportMcap(const std::string& log_path, const std::string& mcap_path, std::ostream& warnings,
                            const McapGeometry& geometry = {});

}  // namespace robotalk::logplay
