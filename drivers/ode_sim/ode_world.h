// OdeWorld: a RobotModel turned into an ODE world (private to the ode driver).
// One ODE body per group of links joined by fixed joints (a link whose parent
// joint has no dof is fused rigidly into its parent's body); massless groups
// get a small virtual mass; a joint of k dofs is a chain of k hinges/sliders
// joined by k-1 virtual bodies; collision shapes collide with a ground plane
// only (no self-collision). docs/ode_sim.md describes the mapping.
//
// Dof conventions match RobotModel: q[i] is the position of dof i
// (dof_offset order); efforts act on the child link, positive along +q.
//
// Thread safety: none; one thread at a time (ODE's per-thread data is
// allocated on first use in each calling thread). Step() allocates nothing of
// its own (ODE's step uses its internal arenas).
// Copy/move: neither (owns ODE handles).
#pragma once

#include "collision_shapes.h"
#include "robotalk/robot_model.h"

#include <ode/ode.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace robotalk::ode_detail {

struct OdeWorldOptions {
  double step = 1e-3;     ///< s
  double gravity = 9.81;  ///< m/s², along -z
  double friction = 1.0;  ///< Coulomb coefficient (pyramid approximation)
  double contact_erp = 0.2;
  double contact_cfm = 1e-5;
  bool quickstep = false;  ///< dWorldQuickStep instead of dWorldStep
  int quickstep_iterations = 50;
  double virtual_mass = 0.05;             ///< kg, of massless groups and joint-chain bodies
  double virtual_radius = 0.03;           ///< m, their inertia is a solid sphere's
  std::vector<std::string> caster_links;  ///< links whose contacts are frictionless
  bool ground = true;
  double ground_z = 0.0;
  bool kinematic_first_root = false;  ///< a mobile first root moved by velocity, not dynamics
  bool place_on_ground = false;       ///< shift the first root in z so its lowest shape touches the ground
  std::uint32_t seed = 1;             ///< dRand state (used by quickstep)
};

/// One ground contact of the last Step(): the link whose shape touched the
/// ground, the contact point and the force the ground exerted on the link
/// (world frame, m and N).
struct ContactPoint {
  int link = -1;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
};

class OdeWorld {
 public:
  /// Builds the world at joint positions q0 (size num_dofs). Throws Error for
  /// what ODE cannot represent (a revolute joint with more than 6 dofs cannot
  /// happen: RobotModel refuses it).
  OdeWorld(const RobotModel& model, const std::vector<CollisionShape>& shapes, const OdeWorldOptions& options,
           const Eigen::VectorXd& q0);
  ~OdeWorld();
  OdeWorld(const OdeWorld&) = delete;
  OdeWorld& operator=(const OdeWorld&) = delete;

  /// Velocity motor of a dof: reaches `velocity` (rad/s | m/s) with at most
  /// `max_force` (N·m | N). Held until changed; turns off the effort mode.
  void SetMotor(int dof, double velocity, double max_force);
  /// Applies `effort` (N·m | N) on the dof every step; turns the motor off.
  void SetEffort(int dof, double effort);
  /// Ground contacts of `link`'s shapes become a spring-damper of `stiffness`
  /// (N/m) and `damping` (N·s/m) per contact point (ODE's soft ERP/CFM at the
  /// step), e.g. a humanoid's rubber soles; other links keep the world's.
  void SetContactSpring(int link, double stiffness, double damping);
  /// Velocity of a kinematic first root, world frame (m/s, rad/s).
  void SetRootVelocity(const Eigen::Vector3d& v, const Eigen::Vector3d& w);
  /// Adds `force` (N, world frame) at the first root's centre of mass for
  /// the next Step() only (OdeDriver::PushForTesting).
  void AddRootForce(const Eigen::Vector3d& force);

  /// One fixed step: ground contacts, dynamics, joint read-out.
  void Step();

  const Eigen::VectorXd& q() const { return q_; }
  /// The ground contacts of the last Step() with their forces.
  const std::vector<ContactPoint>& contacts() const { return contacts_out_; }
  const Eigen::VectorXd& qd() const { return qd_; }
  const Eigen::VectorXd& effort() const { return effort_; }
  /// World pose of a link's frame.
  Eigen::Isometry3d LinkPose(int link) const;
  /// World linear velocity of a link's frame origin and angular velocity.
  Eigen::Vector3d LinkLinearVelocity(int link) const;
  Eigen::Vector3d LinkAngularVelocity(int link) const;
  /// The first root's pose after place_on_ground.
  const Eigen::Isometry3d& initial_root_pose() const { return initial_root_pose_; }
  bool root_kinematic() const { return root_kinematic_; }

  int num_bodies() const { return static_cast<int>(bodies_.size()); }
  int num_geoms() const { return static_cast<int>(geoms_.size()); }
  int num_fused_links() const { return num_fused_; }
  int num_mesh_boxes() const { return num_mesh_boxes_; }
  int num_skipped_meshes() const { return num_skipped_meshes_; }
  std::int64_t steps() const { return steps_; }

 private:
  struct DofJoint {
    dJointID joint = nullptr;
    bool revolute = true;
    double q0 = 0;         // q at creation (ODE's zero)
    double last_raw = 0;   // last ODE angle, for unwrapping
    double unwrapped = 0;  // accumulated ODE angle / position
    bool effort_mode = false;
    double effort_cmd = 0;
    dJointFeedback feedback{};
  };
  struct Geom {
    dGeomID geom = nullptr;
    bool frictionless = false;
    int link = -1;
    double erp = -1, cfm = -1;  // < 0: the world's contact_erp / contact_cfm
  };

  void BuildGroups();
  void PlaceOnGround(const std::vector<CollisionShape>& shapes, const Eigen::VectorXd& q0);
  void BuildBodies(const Eigen::VectorXd& q0);
  void BuildGeoms(const std::vector<CollisionShape>& shapes);
  void BuildJoints(const Eigen::VectorXd& q0);
  dBodyID VirtualBody(const Eigen::Isometry3d& pose);
  void ReadJoints();

  const RobotModel& model_;
  OdeWorldOptions options_;
  dWorldID world_ = nullptr;
  dThreadingImplementationID threading_ = nullptr;  // this world's own (see the constructor)
  dJointGroupID contacts_ = nullptr;
  dGeomID ground_ = nullptr;

  // Per link: its group's primary link, and the primary frame -> link frame transform.
  std::vector<int> group_of_;
  std::vector<Eigen::Isometry3d> primary_to_link_;
  // Per link (primary links only meaningful): body, COM of the group in the primary frame.
  std::vector<dBodyID> body_of_;
  std::vector<Eigen::Vector3d> group_com_;
  std::vector<dBodyID> bodies_;  // every body, virtual ones included
  std::vector<Geom> geoms_;
  std::vector<DofJoint> dofs_;
  std::vector<Eigen::Isometry3d> root_poses_;  // per RobotModel::roots() entry, at build
  Eigen::Isometry3d initial_root_pose_ = Eigen::Isometry3d::Identity();
  bool root_kinematic_ = false;

  Eigen::VectorXd q_, qd_, effort_;
  std::vector<dContactGeom> contact_scratch_;
  std::vector<dJointFeedback> contact_feedback_;  // one per possible contact (sized when built)
  std::vector<ContactPoint> contacts_out_;
  unsigned long rand_state_ = 1;
  std::int64_t steps_ = 0;
  int num_fused_ = 0, num_mesh_boxes_ = 0, num_skipped_meshes_ = 0;
};

}  // namespace robotalk::ode_detail
