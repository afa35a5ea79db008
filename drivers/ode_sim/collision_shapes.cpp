#include "collision_shapes.h"

#include "robotalk/driver_support.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace robotalk {

// The <collision> shapes of the one URDF geometry reader the drawing tools
// share (robotalk/urdf_geometry.h).
std::vector<CollisionShape> LoadCollisionShapes(const std::string& path) {
  std::vector<CollisionShape> shapes;
  for (const UrdfShape& u : LoadUrdfShapes(path)) {
    if (!u.collision) continue;
    CollisionShape s;
    s.link = u.link;
    s.kind = u.kind;
    s.size = u.size;
    s.origin = u.origin;
    shapes.push_back(std::move(s));
  }
  return shapes;
}

CollisionShape Sole::Box(const std::string& link, double thickness) const {
  CollisionShape s;
  s.link = link;
  s.kind = CollisionShape::Kind::kBox;
  s.size = Eigen::Vector3d(front + back, left + right, thickness);
  s.origin.translation = Eigen::Vector3d((front - back) / 2, (left - right) / 2, z + thickness / 2);
  return s;
}

std::optional<Sole> FindSole(const std::string& link, const std::vector<CollisionShape>& shapes,
                             std::string* why) {
  using Kind = CollisionShape::Kind;
  constexpr double kMinExtent = 0.01;  // m: a sole narrower than this is a line, not a sole
  const std::string foot = "foot '" + link + "'";
  // A box: the lowest one's bottom face.
  const CollisionShape* box = nullptr;
  for (const CollisionShape& s : shapes) {
    if (s.link != link || s.kind != Kind::kBox) continue;
    const double bottom = s.origin.translation.z() - s.size.z() / 2;
    if (!box || bottom < box->origin.translation.z() - box->size.z() / 2) box = &s;
  }
  if (box) {
    if (box->origin.rotation.angularDistance(Eigen::Quaterniond::Identity()) > 1e-6) {
      *why = foot + "'s sole box is rotated in the link frame (a sole box must be aligned with the foot)";
      return std::nullopt;
    }
    const Eigen::Vector3d t = box->origin.translation, size = box->size;
    return Sole{.front = t.x() + size.x() / 2,
                .back = size.x() / 2 - t.x(),
                .left = t.y() + size.y() / 2,
                .right = size.y() / 2 - t.y(),
                .z = t.z() - size.z() / 2,
                .contacts = 4,
                .from_points = false};
  }
  // Contact points: the spheres' lowest points.
  double lowest = std::numeric_limits<double>::infinity();
  for (const CollisionShape& s : shapes) {
    if (s.link == link && s.kind == Kind::kSphere)
      lowest = std::min(lowest, s.origin.translation.z() - s.size.x());
  }
  if (!std::isfinite(lowest)) {
    *why = foot + " has no box collision shape (a sole) and no contact points (spheres) to derive one from";
    return std::nullopt;
  }
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  int n = 0;
  for (const CollisionShape& s : shapes) {
    if (s.link != link || s.kind != Kind::kSphere) continue;
    if (s.origin.translation.z() - s.size.x() > lowest + kSoleFlatness) continue;
    lo = lo.cwiseMin(s.origin.translation.head<2>());
    hi = hi.cwiseMax(s.origin.translation.head<2>());
    ++n;
  }
  const Eigen::Vector2d extent = hi - lo;
  if (n < 3 || extent.minCoeff() < kMinExtent) {
    *why = foot + "'s lowest contact points (" + std::to_string(n) + " within " +
           driver_support::Num(kSoleFlatness * 1000) + " mm of the lowest) span " +
           driver_support::Num(extent.x()) + " x " + driver_support::Num(extent.y()) +
           " m: no sole to stand on (it needs at least 1 cm either way)";
    return std::nullopt;
  }
  return Sole{.front = hi.x(),
              .back = -lo.x(),
              .left = hi.y(),
              .right = -lo.y(),
              .z = lowest,
              .contacts = n,
              .from_points = true};
}

}  // namespace robotalk
