#include "collision_shapes.h"

#include "robotalk/error.h"

#include <urdf_parser/urdf_parser.h>

#include <fstream>
#include <sstream>

namespace robotalk {

std::vector<CollisionShape> LoadCollisionShapes(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw UrdfError("LoadCollisionShapes: cannot open '" + path + "'");
  std::stringstream text;
  text << in.rdbuf();
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text.str());
  if (!model) throw UrdfError("LoadCollisionShapes: urdfdom cannot parse '" + path + "'");

  std::vector<CollisionShape> shapes;
  for (const auto& [name, link] : model->links_) {  // std::map: sorted, deterministic
    for (const urdf::CollisionSharedPtr& c : link->collision_array) {
      if (!c || !c->geometry) continue;
      CollisionShape s;
      s.link = name;
      const urdf::Pose& o = c->origin;
      s.origin.translation = {o.position.x, o.position.y, o.position.z};
      double qx, qy, qz, qw;
      o.rotation.getQuaternion(qx, qy, qz, qw);
      s.origin.rotation = Eigen::Quaterniond(qw, qx, qy, qz).normalized();
      switch (c->geometry->type) {
        case urdf::Geometry::BOX: {
          const auto& b = static_cast<const urdf::Box&>(*c->geometry);
          s.kind = CollisionShape::Kind::kBox;
          s.size = {b.dim.x, b.dim.y, b.dim.z};
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& cy = static_cast<const urdf::Cylinder&>(*c->geometry);
          s.kind = CollisionShape::Kind::kCylinder;
          s.size = {cy.radius, cy.length, 0};
          break;
        }
        case urdf::Geometry::SPHERE: {
          const auto& sp = static_cast<const urdf::Sphere&>(*c->geometry);
          s.kind = CollisionShape::Kind::kSphere;
          s.size = {sp.radius, 0, 0};
          break;
        }
        case urdf::Geometry::MESH: {
          const auto& m = static_cast<const urdf::Mesh&>(*c->geometry);
          s.kind = CollisionShape::Kind::kMesh;
          s.size = {m.scale.x, m.scale.y, m.scale.z};
          break;
        }
      }
      shapes.push_back(std::move(s));
    }
  }
  return shapes;
}

}  // namespace robotalk
