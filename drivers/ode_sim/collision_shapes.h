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
#include <optional>
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

/// A foot's sole: the flat rectangle it stands on, in the foot link's frame
/// (x forward, y left, z up when the foot stands flat), m.
struct Sole {
  double front = 0, back = 0;  ///< its extent ahead of (+x) and behind (-x) the link origin
  double left = 0, right = 0;  ///< its extent toward +y and toward -y
  double z = 0;                ///< the sole plane's height (the lowest contact)
  /// The ground contacts of the sole lying flat: 4 for a box (its corners),
  /// else the number of contact points in the sole plane.
  int contacts = 0;
  bool from_points = false;  ///< true: derived from contact points, not from a box
  /// The sole as a box shape of `link`, `thickness` thick above the sole plane.
  CollisionShape Box(const std::string& link, double thickness) const;
};

/// Contact points within this height (m) of a foot's lowest one are its sole.
inline constexpr double kSoleFlatness = 1e-3;

/// The sole of `link` from its collision shapes: the bottom face of its
/// lowest box (unrotated in the link frame), or else the bounding rectangle
/// of its lowest contact points: spheres (radius 0 included, as Drake's
/// models give a foot's contact points) whose lowest points lie within
/// kSoleFlatness of the lowest. nullopt with *why naming what is missing
/// (no box and no points, a rotated box, points that span no area).
std::optional<Sole> FindSole(const std::string& link, const std::vector<CollisionShape>& shapes,
                             std::string* why);

}  // namespace robotalk
