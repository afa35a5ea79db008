#include "collision_shapes.h"

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

}  // namespace robotalk
