// The motion specification in Python: load_urdf, RobotModel and its parts,
// Kinematics (docs/specification.md, docs/python.md). Vectors and matrices
// are numpy arrays (copies); a pose is x y z qw qx qy qz or a 4x4 matrix.
#include "py_common.h"
#include "robotalk/kinematics.h"
#include "robotalk/sequence_file.h"
#include "robotalk/urdf_import.h"

#include <pybind11/eigen.h>
#include <pybind11/stl.h>

#include <memory>
#include <variant>

namespace robotalk::python {
namespace {

using Eigen::Isometry3d;
using Eigen::Matrix4d;
using Eigen::Vector3d;
using NameOrIndex = std::variant<int, std::string>;

py::array_t<double> PoseArray(const Pose& p) {
  return ToArray({p.translation.x(), p.translation.y(), p.translation.z(), p.rotation.w(), p.rotation.x(),
                  p.rotation.y(), p.rotation.z()});
}
py::array_t<double> QuaternionArray(const Eigen::Quaterniond& q) {
  return ToArray({q.w(), q.x(), q.y(), q.z()});
}

// An index, or a name looked up in the model (LookupError naming both).
int Index(const RobotModel& m, const NameOrIndex& key, int (RobotModel::*by_name)(std::string_view) const,
          std::size_t count, const char* kind) {
  if (const auto* name = std::get_if<std::string>(&key)) return (m.*by_name)(*name);
  const int i = std::get<int>(key);
  if (i < 0 || static_cast<std::size_t>(i) >= count) {
    throw LookupError("robot '" + m.name() + "' has no " + kind + " with index " + std::to_string(i) +
                      " (it has " + std::to_string(count) + ")");
  }
  return i;
}
int LinkIndex(const RobotModel& m, const NameOrIndex& k) {
  return Index(m, k, &RobotModel::LinkIndex, m.links().size(), "link");
}
int JointIndex(const RobotModel& m, const NameOrIndex& k) {
  return Index(m, k, &RobotModel::JointIndex, m.joints().size(), "joint");
}
int FrameIndex(const RobotModel& m, const NameOrIndex& k) {
  return Index(m, k, &RobotModel::FrameIndex, m.frames().size(), "control frame");
}

// Each dof's column name: the joint's, or "joint.k" for a multi-dof joint
// (as robotalk-logplay export names them).
std::vector<std::string> DofNames(const RobotModel& m) {
  std::vector<std::string> names;
  for (const Joint& j : m.joints()) {
    for (std::size_t k = 0; k < j.dofs.size(); ++k)
      names.push_back(j.dofs.size() == 1 ? j.name : j.name + "." + std::to_string(k));
  }
  return names;
}

Isometry3d ToIsometry(const Matrix4d& m) {
  Isometry3d x;
  x.matrix() = m;
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if (!((r * r.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6) ||
      !(m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).isZero(1e-12)) {
    throw UsageError(
        "root pose: not a rigid transform (a 4x4 matrix with a rotation block and 0 0 0 1 below)");
  }
  return x;
}

// Kinematics holds a reference to its model: the binding keeps the model alive.
struct PyKinematics {
  std::shared_ptr<const RobotModel> model;
  Kinematics kin;
  explicit PyKinematics(std::shared_ptr<const RobotModel> m) : model(std::move(m)), kin(*model) {}
};

}  // namespace

void BindSpec(py::module_& m) {
  py::class_<Link>(m, "Link", "A rigid body of a robot model (copied out of the model; read-only).")
      .def_property_readonly("name", [](const Link& l) { return l.name; })
      .def_property_readonly(
          "mass", [](const Link& l) { return l.mass; }, "kg")
      .def_property_readonly(
          "com", [](const Link& l) { return Vector3d(l.com); },
          "Centre of mass in the link frame (m), numpy (3,).")
      .def_property_readonly(
          "inertia", [](const Link& l) { return Eigen::Matrix3d(l.inertia); },
          "Inertia tensor about the COM in link axes (kg m^2), numpy (3, 3).")
      .def("__repr__",
           [](const Link& l) { return "<Link '" + l.name + "' mass " + std::to_string(l.mass) + " kg>"; });

  py::class_<Dof>(m, "Dof", "One degree of freedom of a joint.")
      .def_property_readonly(
          "type", [](const Dof& d) { return std::string(ToString(d.type)); }, "'revolute' or 'prismatic'.")
      .def_property_readonly(
          "axis", [](const Dof& d) { return Vector3d(d.axis); }, "Unit axis, joint frame.")
      .def_property_readonly(
          "lower", [](const Dof& d) { return d.limits.lower; }, "rad or m (-inf: none)")
      .def_property_readonly(
          "upper", [](const Dof& d) { return d.limits.upper; }, "rad or m (inf: none)")
      .def_property_readonly(
          "velocity_limit", [](const Dof& d) { return d.limits.velocity; }, "rad/s or m/s")
      .def_property_readonly(
          "effort_limit", [](const Dof& d) { return d.limits.effort; }, "N m or N")
      .def("__repr__", [](const Dof& d) {
        return std::string("<Dof ") + ToString(d.type) + " [" + std::to_string(d.limits.lower) + ", " +
               std::to_string(d.limits.upper) + "]>";
      });

  py::class_<Joint>(m, "Joint", "A joint of 0 (fixed) to 6 (free) dofs between a parent and a child link.")
      .def_property_readonly("name", [](const Joint& j) { return j.name; })
      .def_property_readonly(
          "parent_link", [](const Joint& j) { return j.parent_link; }, "Link index.")
      .def_property_readonly(
          "child_link", [](const Joint& j) { return j.child_link; }, "Link index.")
      .def_property_readonly(
          "inboard", [](const Joint& j) { return Vector3d(j.inboard); },
          "Parent COM -> joint centre, parent axes (m).")
      .def_property_readonly(
          "outboard", [](const Joint& j) { return Vector3d(j.outboard); },
          "Child COM -> joint centre, child axes (m).")
      .def_property_readonly(
          "rest", [](const Joint& j) { return QuaternionArray(j.rest); },
          "Rotation at q = 0 as a quaternion (w, x, y, z).")
      .def_property_readonly("dofs", [](const Joint& j) { return j.dofs; })
      .def_property_readonly("num_dofs", [](const Joint& j) { return static_cast<int>(j.dofs.size()); })
      .def_property_readonly(
          "servo_types", [](const Joint& j) { return j.servo_types.ToString(); },
          "'setpoint speed force' (those accepted), or 'none'.")
      .def_property_readonly(
          "mimic",
          [](const Joint& j) -> py::object {
            if (!j.mimic) return py::none();
            return py::make_tuple(j.mimic->leader_joint, j.mimic->multiplier, j.mimic->offset);
          },
          "(leader joint index, multiplier, offset), or None.")
      .def("__repr__", [](const Joint& j) {
        return "<Joint '" + j.name + "' " + std::to_string(j.dofs.size()) + " dofs, links " +
               std::to_string(j.parent_link) + " -> " + std::to_string(j.child_link) + ">";
      });

  py::class_<ControlFrame>(m, "ControlFrame", "A frame fixed to a link (end effector, tool, camera).")
      .def_property_readonly("name", [](const ControlFrame& f) { return f.name; })
      .def_property_readonly(
          "parent_link", [](const ControlFrame& f) { return f.parent_link; }, "Link index.")
      .def_property_readonly(
          "pose", [](const ControlFrame& f) { return PoseArray(f.pose_in_link); },
          "Pose in the link frame: x y z qw qx qy qz.")
      .def_property_readonly("servo_types", [](const ControlFrame& f) { return f.servo_types.ToString(); })
      .def("__repr__", [](const ControlFrame& f) {
        return "<ControlFrame '" + f.name + "' on link " + std::to_string(f.parent_link) + ">";
      });

  py::class_<RootLink>(m, "RootLink", "A link without parent joint, posed in the world.")
      .def_property_readonly(
          "link", [](const RootLink& r) { return r.link; }, "Link index.")
      .def_property_readonly(
          "pose", [](const RootLink& r) { return PoseArray(r.pose_in_world); },
          "World pose of its link frame: x y z qw qx qy qz.")
      .def_property_readonly(
          "base", [](const RootLink& r) { return std::string(ToString(r.base)); },
          "'fixed', 'differential', 'holonomic' or 'floating'.")
      .def("__repr__", [](const RootLink& r) {
        return "<RootLink link " + std::to_string(r.link) + " " + ToString(r.base) + ">";
      });

  py::class_<RobotModel, std::shared_ptr<RobotModel>>(
      m, "RobotModel",
      "A validated, immutable robot description: links, joints and control frames, each\n"
      "addressable by name and by index (robotalk/robot_model.h). From load_urdf() or\n"
      "RobotClient.model. Thread-safe (immutable).")
      .def_property_readonly("name", &RobotModel::name)
      .def_property_readonly(
          "links", [](const RobotModel& r) { return std::vector<Link>(r.links().begin(), r.links().end()); })
      .def_property_readonly(
          "joints",
          [](const RobotModel& r) { return std::vector<Joint>(r.joints().begin(), r.joints().end()); })
      .def_property_readonly(
          "frames",
          [](const RobotModel& r) { return std::vector<ControlFrame>(r.frames().begin(), r.frames().end()); },
          "The control frames.")
      .def_property_readonly(
          "roots",
          [](const RobotModel& r) { return std::vector<RootLink>(r.roots().begin(), r.roots().end()); })
      .def_property_readonly("num_dofs", &RobotModel::num_dofs,
                             "Total dofs (the size of a joint-position vector).")
      .def_property_readonly(
          "dof_names", &DofNames,
          "One name per dof in dof order: the joint's, or 'joint.k' for a multi-dof joint.")
      .def_property_readonly("total_mass", &RobotModel::total_mass, "kg")
      .def(
          "link", [](const RobotModel& r, const NameOrIndex& k) { return r.link(LinkIndex(r, k)); },
          py::arg("name_or_index"), "A link by name or index (LookupError if absent).")
      .def(
          "joint", [](const RobotModel& r, const NameOrIndex& k) { return r.joint(JointIndex(r, k)); },
          py::arg("name_or_index"), "A joint by name or index (LookupError if absent).")
      .def(
          "frame", [](const RobotModel& r, const NameOrIndex& k) { return r.frame(FrameIndex(r, k)); },
          py::arg("name_or_index"), "A control frame by name or index (LookupError if absent).")
      .def(
          "link_index", [](const RobotModel& r, const std::string& n) { return r.LinkIndex(n); },
          py::arg("name"))
      .def(
          "joint_index", [](const RobotModel& r, const std::string& n) { return r.JointIndex(n); },
          py::arg("name"))
      .def(
          "frame_index", [](const RobotModel& r, const std::string& n) { return r.FrameIndex(n); },
          py::arg("name"))
      .def(
          "find_link", [](const RobotModel& r, const std::string& n) { return r.FindLink(n); },
          py::arg("name"), "The index, or None.")
      .def(
          "find_joint", [](const RobotModel& r, const std::string& n) { return r.FindJoint(n); },
          py::arg("name"))
      .def(
          "find_frame", [](const RobotModel& r, const std::string& n) { return r.FindFrame(n); },
          py::arg("name"))
      .def(
          "dof_offset",
          [](const RobotModel& r, const NameOrIndex& k) { return r.dof_offset(JointIndex(r, k)); },
          py::arg("joint"), "Index of a joint's first dof in a joint-position vector.")
      .def(
          "parent_joint",
          [](const RobotModel& r, const NameOrIndex& k) { return r.parent_joint(LinkIndex(r, k)); },
          py::arg("link"), "The joint whose child is `link`, or -1 for a root link.")
      .def(
          "__eq__", [](const RobotModel& a, const RobotModel& b) { return a == b; }, py::is_operator())
      .def("__repr__", [](const RobotModel& r) {
        return "<RobotModel '" + r.name() + "': " + std::to_string(r.links().size()) + " links, " +
               std::to_string(r.joints().size()) + " joints, " + std::to_string(r.num_dofs()) + " dofs, " +
               std::to_string(r.frames().size()) + " control frames>";
      });

  m.def(
      "_load_urdf",
      [](const std::string& path, bool strict, bool merge, const std::string& name) {
        UrdfImportResult r = [&] {
          py::gil_scoped_release release;
          return LoadUrdfFile(path, {.strict = strict, .merge_massless_chains = merge, .robot_name = name});
        }();
        return py::make_tuple(std::make_shared<RobotModel>(std::move(r.model)), r.warnings);
      },
      py::arg("path"), py::arg("strict") = false, py::arg("merge_massless_chains") = false,
      py::arg("robot_name") = "");
  m.def(
      "_parse_urdf",
      [](const std::string& xml, bool strict, bool merge, const std::string& name) {
        UrdfImportResult r =
            ParseUrdf(xml, {.strict = strict, .merge_massless_chains = merge, .robot_name = name});
        return py::make_tuple(std::make_shared<RobotModel>(std::move(r.model)), r.warnings);
      },
      py::arg("xml"), py::arg("strict") = false, py::arg("merge_massless_chains") = false,
      py::arg("robot_name") = "");

  py::class_<PyKinematics>(
      m, "Kinematics",
      "Forward kinematics, control-frame Jacobians and centre of mass of a RobotModel\n"
      "(robotalk/kinematics.h). update(q) computes every link pose; the accessors read\n"
      "them. Poses are 4x4 numpy matrices (world from frame); a Jacobian is 6 x num_dofs:\n"
      "rows 0-2 the linear velocity of the point, rows 3-5 the angular velocity, world\n"
      "axes. Not thread-safe: use one per thread. Poses start at q = 0.")
      .def(py::init([](std::shared_ptr<RobotModel> model) {
             return std::make_unique<PyKinematics>(std::move(model));
           }),
           py::arg("model"))
      .def_property_readonly(
          "model", [](const PyKinematics& k) { return std::const_pointer_cast<RobotModel>(k.model); })
      .def(
          "update",
          [](PyKinematics& k, const Eigen::VectorXd& q, std::optional<std::vector<Matrix4d>> roots) {
            std::vector<Isometry3d> root_poses;
            if (roots) {
              for (const Matrix4d& r : *roots) root_poses.push_back(ToIsometry(r));
            }
            k.kin.Update(q, root_poses);
          },
          py::arg("q"), py::arg("root_poses") = py::none(),
          "Computes every link pose for joint positions q (num_dofs values in dof order).\n"
          "root_poses: one 4x4 world pose per model root (default: the model's). Raises\n"
          "RobotalkError naming a wrong size or a non-finite value.")
      .def(
          "link_pose",
          [](const PyKinematics& k, const NameOrIndex& l) {
            return Matrix4d(k.kin.link_pose(LinkIndex(*k.model, l)).matrix());
          },
          py::arg("link"), "World pose (4x4) of a link's frame (not its COM) for the last update().")
      .def(
          "link_poses",
          [](const PyKinematics& k) {
            const auto n = static_cast<py::ssize_t>(k.model->links().size());
            py::array_t<double> out({n, py::ssize_t{4}, py::ssize_t{4}});
            auto v = out.mutable_unchecked<3>();
            for (py::ssize_t i = 0; i < n; ++i) {
              const Matrix4d x = k.kin.link_pose(static_cast<int>(i)).matrix();
              for (int r = 0; r < 4; ++r)
                for (int c = 0; c < 4; ++c) v(i, r, c) = x(r, c);
            }
            return out;
          },
          "Every link's world pose, numpy (num_links, 4, 4), in model order.")
      .def(
          "frame_pose",
          [](const PyKinematics& k, const NameOrIndex& f) {
            return Matrix4d(k.kin.frame_pose(FrameIndex(*k.model, f)).matrix());
          },
          py::arg("frame"), "World pose (4x4) of a control frame for the last update().")
      .def(
          "frame_jacobian",
          [](const PyKinematics& k, const NameOrIndex& f) {
            return Eigen::MatrixXd(k.kin.FrameJacobian(FrameIndex(*k.model, f)));
          },
          py::arg("frame"), "Geometric Jacobian (6 x num_dofs) of a control frame's origin.")
      .def(
          "point_jacobian",
          [](const PyKinematics& k, const NameOrIndex& l, const Vector3d& p) {
            return Eigen::MatrixXd(k.kin.PointJacobian(LinkIndex(*k.model, l), p));
          },
          py::arg("link"), py::arg("point") = Vector3d::Zero(),
          "Geometric Jacobian (6 x num_dofs) of a point fixed to `link`, given in the link frame.")
      .def(
          "center_of_mass", [](const PyKinematics& k) { return Vector3d(k.kin.CenterOfMass()); },
          "Whole-body centre of mass in the world (m); zeros if the robot is massless.")
      .def("__repr__", [](const PyKinematics& k) { return "<Kinematics of '" + k.model->name() + "'>"; });
}

}  // namespace robotalk::python
