// The geometry of a URDF robot: every <visual> and <collision> shape of every
// link, read with urdfdom. RobotModel carries no geometry (nor does the robot
// configuration on the wire); the tools that draw a robot (robotalk-web's
// Foxglove scene, robotalk-logplay export --mcap) and the ODE driver (its
// collision bodies) read it from the URDF file with this one function.
//
// Thread safety: may be called from several threads (urdfdom runs as in
// urdf_import.h, its messages captured). Errors: LoadUrdfShapes throws
// UrdfError naming the file when it cannot be read, is larger than
// `max_file_bytes`, nests deeper than `max_xml_depth`, or urdfdom refuses it.
#pragma once

#include "robotalk/model_types.h"

#include <Eigen/Core>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

/// One <visual> or <collision> element of a link.
struct UrdfShape {
  enum class Kind { kBox, kCylinder, kSphere, kMesh };
  std::string link;        ///< URDF link name (= RobotModel link name)
  bool collision = false;  ///< a <collision> element; a <visual> one otherwise
  Kind kind = Kind::kBox;
  /// kBox: x y z sizes, m; kCylinder: radius, length (along the shape's z), 0;
  /// kSphere: radius, 0, 0; kMesh: the mesh's scale.
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Pose origin;       ///< the shape's frame in the link frame
  std::string mesh;  ///< kMesh: the filename as the URDF writes it (package://, file://, a path)
  /// A <visual>'s material colour (r g b a, 0..1), its own or the robot-level
  /// <material> it names; none for collisions and visuals without a material.
  std::optional<Eigen::Vector4d> rgba;
};

/// Every <visual> and <collision> of every link of the URDF file at `path`:
/// links in urdfdom's order (by name), each link's visuals then collisions in
/// file order. Shapes without geometry are skipped.
std::vector<UrdfShape> LoadUrdfShapes(const std::string& path, std::size_t max_file_bytes = 16 * 1024 * 1024,
                                      int max_xml_depth = 100);

}  // namespace robotalk
