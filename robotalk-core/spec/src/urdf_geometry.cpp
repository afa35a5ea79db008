#include "robotalk/urdf_geometry.h"

#include "robotalk/error.h"
#include "urdf_extensions.h"

#include <urdf_model/model.h>

namespace robotalk {
namespace {

Pose ToPose(const urdf::Pose& o) {
  Pose p;
  p.translation = {o.position.x, o.position.y, o.position.z};
  double qx, qy, qz, qw;
  o.rotation.getQuaternion(qx, qy, qz, qw);
  p.rotation = Eigen::Quaterniond(qw, qx, qy, qz).normalized();
  return p;
}

// Fills kind, size and mesh; false for a geometry type urdfdom added later.
bool SetGeometry(const urdf::Geometry& g, UrdfShape& s) {
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(g);
      s.kind = UrdfShape::Kind::kBox;
      s.size = {b.dim.x, b.dim.y, b.dim.z};
      return true;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(g);
      s.kind = UrdfShape::Kind::kCylinder;
      s.size = {c.radius, c.length, 0};
      return true;
    }
    case urdf::Geometry::SPHERE: {
      s.kind = UrdfShape::Kind::kSphere;
      s.size = {static_cast<const urdf::Sphere&>(g).radius, 0, 0};
      return true;
    }
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(g);
      s.kind = UrdfShape::Kind::kMesh;
      s.size = {m.scale.x, m.scale.y, m.scale.z};
      s.mesh = m.filename;
      return true;
    }
  }
  return false;
}

}  // namespace

std::vector<UrdfShape> LoadUrdfShapes(const std::string& path, std::size_t max_file_bytes,
                                      int max_xml_depth) {
  const std::string xml = urdf_detail::ReadLimited(path, max_file_bytes, "LoadUrdfShapes");
  urdf_detail::CheckXmlDepth(xml, max_xml_depth, path);
  urdf_detail::UrdfdomMessages messages;
  const urdf::ModelInterfaceSharedPtr model = urdf_detail::ParseQuietly(xml, messages);
  if (!model) {
    throw UrdfError(path + ": urdfdom rejected the file: " +
                    (messages.errors.empty() ? std::string("no reason given") : messages.errors.front()));
  }
  std::vector<UrdfShape> shapes;
  for (const auto& [name, link] : model->links_) {  // std::map: sorted, deterministic
    for (const urdf::VisualSharedPtr& v : link->visual_array) {
      UrdfShape s{.link = name, .collision = false, .origin = v ? ToPose(v->origin) : Pose{}};
      if (!v || !v->geometry || !SetGeometry(*v->geometry, s)) continue;
      if (v->material) {
        const urdf::Color& c = v->material->color;
        s.rgba = Eigen::Vector4d(c.r, c.g, c.b, c.a);
      }
      shapes.push_back(std::move(s));
    }
    for (const urdf::CollisionSharedPtr& c : link->collision_array) {
      UrdfShape s{.link = name, .collision = true, .origin = c ? ToPose(c->origin) : Pose{}};
      if (!c || !c->geometry || !SetGeometry(*c->geometry, s)) continue;
      shapes.push_back(std::move(s));
    }
  }
  // In a file with a cycle urdfdom's links own each other (urdf_import.cpp).
  for (auto& [name, link] : model->links_) {
    link->child_links.clear();
    link->child_joints.clear();
  }
  return shapes;
}

}  // namespace robotalk
