// Collision geometry of a URDF robot for the ODE driver: the <collision>
// shapes of robotalk/urdf_geometry.h's LoadUrdfShapes (urdfdom).
// RobotModel has no geometry; the driver reads it from the same file.
//
// Thread safety: LoadCollisionShapes may be called from any thread (it holds
// no state); urdfdom may log through console_bridge's process-wide handler.
#pragma once

#include "robotalk/model_types.h"
#include "robotalk/urdf_geometry.h"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace robotalk {

/// One <collision> element of a link.
struct CollisionShape {
  using Kind = UrdfShape::Kind;  ///< kBox, kCylinder, kSphere, kMesh
  std::string link;              ///< URDF link name (= RobotModel link name)
  Kind kind = Kind::kBox;
  /// kBox: x y z sizes, m; kCylinder: radius, length (along the shape's z), 0;
  /// kSphere: radius, 0, 0; kMesh: the mesh's scale (the mesh is not read).
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Pose origin;  ///< the shape's frame in the link frame
};

/// Every <collision> of every link of the URDF file at `path`, in file order of
/// urdfdom's link map. Throws UrdfError naming the file when urdfdom cannot
/// parse it (LoadUrdfShapes).
std::vector<CollisionShape> LoadCollisionShapes(const std::string& path);

}  // namespace robotalk
