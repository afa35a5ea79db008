#include "ode_world.h"

#include "robotalk/error.h"
#include "robotalk/kinematics.h"
#include "robotalk/log_writer.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <mutex>
#include <numbers>
#include <string>

namespace robotalk::ode_detail {
namespace {

constexpr int kMaxContactsPerGeom = 8;
constexpr double kPi = std::numbers::pi;

// ODE's own lines (dMessage, e.g. "LCP internal error" mid-step on the
// robot's thread; dError and dDebug, after which ODE ends the process) go
// through the process's one writer of stderr, as the server's do: ODE's
// default handlers write to stderr directly, and one that takes nothing would
// hold the robot's thread, its STOP included.
void SayOde(const char* what, int number, const char* format, va_list args) {
  char text[512];
  std::vsnprintf(text, sizeof text, format, args);
  LogWriter::Stderr().Write(std::string("robotalk ode driver: ") + what + " " + std::to_string(number) +
                            ": " + text);
}

// ODE needs one library initialisation per process and per-thread data in
// every thread that steps or collides (the server constructs drivers in one
// thread and runs them in its RobotDaemon).
void EnsureOdeThread() {
  static std::once_flag init;
  std::call_once(init, [] {
    dInitODE2(0);
    dSetMessageHandler([](int n, const char* f, va_list a) { SayOde("ODE Message", n, f, a); });
    dSetErrorHandler([](int n, const char* f, va_list a) { SayOde("ODE Error", n, f, a); });
    dSetDebugHandler([](int n, const char* f, va_list a) { SayOde("ODE INTERNAL ERROR", n, f, a); });
  });
  thread_local bool allocated = false;
  if (!allocated) {
    dAllocateODEDataForThread(dAllocateMaskAll);
    allocated = true;
  }
}

void SetPose(dBodyID b, const Eigen::Vector3d& p, const Eigen::Matrix3d& r) {
  dBodySetPosition(b, p.x(), p.y(), p.z());
  const Eigen::Quaterniond q(r);
  const dQuaternion dq = {q.w(), q.x(), q.y(), q.z()};
  dBodySetQuaternion(b, dq);
}

Eigen::Isometry3d BodyPose(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  x.translation() << p[0], p[1], p[2];
  return x;
}

Eigen::Isometry3d DofMotion(const Dof& d, double q) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  if (d.type == DofType::kRevolute) {
    m.linear() = Eigen::AngleAxisd(q, d.axis).toRotationMatrix();
  } else {
    m.translation() = q * d.axis;
  }
  return m;
}

Eigen::Isometry3d Translation(const Eigen::Vector3d& t) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.translation() = t;
  return x;
}

// Lowest world z of a shape posed at `x` (box, cylinder along z, sphere).
double LowestZ(CollisionShape::Kind kind, const Eigen::Vector3d& size, const Eigen::Isometry3d& x) {
  const Eigen::Matrix3d& r = x.linear();
  const double z = x.translation().z();
  switch (kind) {
    case CollisionShape::Kind::kBox:
      return z - 0.5 * (std::abs(r(2, 0)) * size.x() + std::abs(r(2, 1)) * size.y() +
                        std::abs(r(2, 2)) * size.z());
    case CollisionShape::Kind::kCylinder: {
      const double c = std::abs(r(2, 2));
      return z - (c * 0.5 * size.y() + size.x() * std::sqrt(std::max(0.0, 1 - c * c)));
    }
    case CollisionShape::Kind::kSphere:
      return z - size.x();
    case CollisionShape::Kind::kMesh:
      break;
  }
  return z;
}

// The solid box with a link's mass and inertia (principal axes at the COM):
// how a mesh is approximated. Returns false for a massless link.
bool InertiaBox(const Link& link, Eigen::Vector3d* size, Pose* origin) {
  if (link.mass <= 0) return false;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(link.inertia);
  Eigen::Matrix3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  const Eigen::Vector3d i = eig.eigenvalues();
  const double k = 6.0 / link.mass;  // I_x = m (b² + c²) / 12  =>  a² = 6 (I_y + I_z - I_x) / m
  for (int a = 0; a < 3; ++a) {
    const double s2 = k * (i[(a + 1) % 3] + i[(a + 2) % 3] - i[a]);
    (*size)[a] = std::sqrt(std::max(s2, 1e-6));
  }
  origin->translation = link.com;
  origin->rotation = Eigen::Quaterniond(axes).normalized();
  return true;
}

}  // namespace

OdeWorld::OdeWorld(const RobotModel& model, const std::vector<CollisionShape>& shapes,
                   const OdeWorldOptions& options, const Eigen::VectorXd& q0)
    : model_(model), options_(options) {
  EnsureOdeThread();
  world_ = dWorldCreate();
  // ODE's default stepping runs on one process-wide threading object with
  // fake mutexes: two worlds stepped from two RobotDaemon threads corrupt its
  // job list (ODE INTERNAL ERROR in ReleaseAJob, seen with the Pioneer and
  // the humanoid in one server). Each world gets its own.
  threading_ = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_), threading_);
  contacts_ = dJointGroupCreate(0);
  dWorldSetGravity(world_, 0, 0, -options_.gravity);
  dWorldSetQuickStepNumIterations(world_, options_.quickstep_iterations);
  rand_state_ = options_.seed;
  const int n = model_.num_dofs();
  q_ = q0;
  qd_.setZero(n);
  effort_.setZero(n);
  for (const RootLink& r : model_.roots()) root_poses_.push_back(r.pose_in_world.ToIsometry());
  BuildGroups();
  if (options_.place_on_ground && options_.ground) PlaceOnGround(shapes, q0);
  initial_root_pose_ = root_poses_.front();
  BuildBodies(q0);
  BuildGeoms(shapes);
  BuildJoints(q0);
  if (options_.ground) ground_ = dCreatePlane(nullptr, 0, 0, 1, options_.ground_z);
  contact_scratch_.resize(kMaxContactsPerGeom);
  contact_feedback_.resize(geoms_.size() * kMaxContactsPerGeom);
  contacts_out_.reserve(contact_feedback_.size());
  ReadJoints();
}

OdeWorld::~OdeWorld() {
  EnsureOdeThread();
  for (Geom& g : geoms_) dGeomDestroy(g.geom);
  if (ground_) dGeomDestroy(ground_);
  dJointGroupDestroy(contacts_);
  dWorldDestroy(world_);  // bodies and joints with it
  dThreadingFreeImplementation(threading_);
}

// A link whose parent joint has no dof belongs to its parent's group.
void OdeWorld::BuildGroups() {
  const size_t nl = model_.links().size();
  group_of_.resize(nl);
  primary_to_link_.assign(nl, Eigen::Isometry3d::Identity());
  for (size_t l = 0; l < nl; ++l) group_of_[l] = static_cast<int>(l);
  for (int j : model_.topological_joint_order()) {
    const Joint& joint = model_.joint(j);
    if (!joint.dofs.empty()) continue;
    const Link& p = model_.link(joint.parent_link);
    const Link& c = model_.link(joint.child_link);
    const Eigen::Isometry3d x = Translation(p.com + joint.inboard) *
                                Eigen::Isometry3d(joint.rest.normalized()) *
                                Translation(-(c.com + joint.outboard));
    const auto pl = static_cast<size_t>(joint.parent_link), cl = static_cast<size_t>(joint.child_link);
    group_of_[cl] = group_of_[pl];
    primary_to_link_[cl] = primary_to_link_[pl] * x;
    ++num_fused_;
  }
}

void OdeWorld::PlaceOnGround(const std::vector<CollisionShape>& shapes, const Eigen::VectorXd& q0) {
  Kinematics kin(model_);
  kin.Update(q0, root_poses_);
  const int root = model_.roots().front().link;
  double lowest = std::numeric_limits<double>::infinity();
  for (const CollisionShape& s : shapes) {
    const std::optional<int> l = model_.FindLink(s.link);
    if (!l || model_.root_of(*l) != root) continue;
    CollisionShape::Kind kind = s.kind;
    Eigen::Vector3d size = s.size;
    Pose origin = s.origin;
    if (kind == CollisionShape::Kind::kMesh) {
      if (!InertiaBox(model_.link(*l), &size, &origin)) continue;
      kind = CollisionShape::Kind::kBox;
    }
    lowest = std::min(lowest, LowestZ(kind, size, kin.link_pose(*l) * origin.ToIsometry()));
  }
  if (std::isfinite(lowest)) root_poses_.front().translation().z() += options_.ground_z - lowest;
}

void OdeWorld::BuildBodies(const Eigen::VectorXd& q0) {
  Kinematics kin(model_);
  kin.Update(q0, root_poses_);
  const size_t nl = model_.links().size();
  body_of_.assign(nl, nullptr);
  group_com_.assign(nl, Eigen::Vector3d::Zero());
  const int first_root = model_.roots().front().link;
  const BaseType first_base = model_.roots().front().base;
  for (size_t g = 0; g < nl; ++g) {
    if (group_of_[g] != static_cast<int>(g)) continue;
    // Mass, COM and inertia of the group in the primary link's frame.
    double mass = 0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    for (size_t l = 0; l < nl; ++l) {
      if (group_of_[l] != static_cast<int>(g)) continue;
      const Link& link = model_.link(static_cast<int>(l));
      mass += link.mass;
      moment += link.mass * (primary_to_link_[l] * link.com);
    }
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    Eigen::Vector3d com = Eigen::Vector3d::Zero();
    if (mass > 0) {
      com = moment / mass;
      for (size_t l = 0; l < nl; ++l) {
        if (group_of_[l] != static_cast<int>(g)) continue;
        const Link& link = model_.link(static_cast<int>(l));
        const Eigen::Matrix3d r = primary_to_link_[l].linear();
        const Eigen::Vector3d d = primary_to_link_[l] * link.com - com;
        inertia += r * link.inertia * r.transpose() +
                   link.mass * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
      }
    }
    if (mass <= 0 || inertia.trace() <= 0) {  // massless group: a small virtual sphere
      mass = options_.virtual_mass;
      com.setZero();
      inertia = 0.4 * mass * options_.virtual_radius * options_.virtual_radius * Eigen::Matrix3d::Identity();
    }
    dBodyID b = dBodyCreate(world_);
    dMass m;
    dMassSetParameters(&m, mass, 0, 0, 0, inertia(0, 0), inertia(1, 1), inertia(2, 2), inertia(0, 1),
                       inertia(0, 2), inertia(1, 2));
    dBodySetMass(b, &m);
    const Eigen::Isometry3d primary = kin.link_pose(static_cast<int>(g));
    SetPose(b, primary * com, primary.linear());
    const bool is_root = model_.parent_joint(static_cast<int>(g)) < 0;
    if (is_root) {
      bool kinematic = true;  // fixed roots are bolted to the world
      for (const RootLink& r : model_.roots()) {
        if (r.link == static_cast<int>(g) && r.base != BaseType::kFixed) kinematic = false;
      }
      if (static_cast<int>(g) == first_root && first_base != BaseType::kFixed &&
          options_.kinematic_first_root) {
        kinematic = true;
      }
      if (kinematic) dBodySetKinematic(b);
      if (static_cast<int>(g) == first_root) root_kinematic_ = kinematic;
    }
    body_of_[g] = b;
    group_com_[g] = com;
    bodies_.push_back(b);
  }
}

void OdeWorld::BuildGeoms(const std::vector<CollisionShape>& shapes) {
  std::vector<std::uint8_t> mesh_box_done(model_.links().size(), 0);
  for (const CollisionShape& s : shapes) {
    const std::optional<int> l = model_.FindLink(s.link);
    if (!l) continue;  // a link merged away by merge_massless_chains
    const auto li = static_cast<size_t>(*l);
    CollisionShape::Kind kind = s.kind;
    Eigen::Vector3d size = s.size;
    Pose origin = s.origin;
    if (kind == CollisionShape::Kind::kMesh) {
      // One inertia box per link however many meshes it has.
      if (mesh_box_done[li] || !InertiaBox(model_.link(*l), &size, &origin)) {
        if (!mesh_box_done[li]) ++num_skipped_meshes_;
        continue;
      }
      mesh_box_done[li] = 1;
      kind = CollisionShape::Kind::kBox;
      ++num_mesh_boxes_;
    }
    dGeomID g = nullptr;
    switch (kind) {
      case CollisionShape::Kind::kBox:
        g = dCreateBox(nullptr, std::max(size.x(), 1e-4), std::max(size.y(), 1e-4), std::max(size.z(), 1e-4));
        break;
      case CollisionShape::Kind::kCylinder:
        g = dCreateCylinder(nullptr, std::max(size.x(), 1e-4), std::max(size.y(), 1e-4));
        break;
      case CollisionShape::Kind::kSphere:
        g = dCreateSphere(nullptr, std::max(size.x(), 1e-4));
        break;
      case CollisionShape::Kind::kMesh:
        continue;
    }
    const auto primary = static_cast<size_t>(group_of_[li]);
    dBodyID b = body_of_[primary];
    dGeomSetBody(g, b);
    const Eigen::Isometry3d offset =
        Translation(-group_com_[primary]) * primary_to_link_[li] * origin.ToIsometry();
    dGeomSetOffsetPosition(g, offset.translation().x(), offset.translation().y(), offset.translation().z());
    const Eigen::Quaterniond r(offset.linear());
    const dQuaternion dq = {r.w(), r.x(), r.y(), r.z()};
    dGeomSetOffsetQuaternion(g, dq);
    const bool caster = std::find(options_.caster_links.begin(), options_.caster_links.end(), s.link) !=
                        options_.caster_links.end();
    geoms_.push_back(Geom{.geom = g, .frictionless = caster, .link = *l});
  }
}

dBodyID OdeWorld::VirtualBody(const Eigen::Isometry3d& pose) {
  dBodyID b = dBodyCreate(world_);
  dMass m;
  dMassSetSphereTotal(&m, options_.virtual_mass, options_.virtual_radius);
  dBodySetMass(b, &m);
  SetPose(b, pose.translation(), pose.linear());
  bodies_.push_back(b);
  return b;
}

// ODE's hinge angle and slider position grow when the child (body 2) moves
// along -axis relative to the parent (body 1) (checked with ODE 0.16), so q =
// q0 - raw, and motor velocities and added torques are negated.
void OdeWorld::BuildJoints(const Eigen::VectorXd& q0) {
  Kinematics kin(model_);
  kin.Update(q0, root_poses_);
  dofs_.resize(static_cast<size_t>(model_.num_dofs()));
  for (int j : model_.topological_joint_order()) {
    const Joint& joint = model_.joint(j);
    if (joint.dofs.empty()) continue;
    const Link& p = model_.link(joint.parent_link);
    Eigen::Isometry3d frame = kin.link_pose(joint.parent_link) * Translation(p.com + joint.inboard) *
                              Eigen::Isometry3d(joint.rest.normalized());
    dBodyID prev = body_of_[static_cast<size_t>(group_of_[static_cast<size_t>(joint.parent_link)])];
    const int off = model_.dof_offset(j);
    for (size_t k = 0; k < joint.dofs.size(); ++k) {
      const Dof& dof = joint.dofs[k];
      const bool last = k + 1 == joint.dofs.size();
      const int i = off + static_cast<int>(k);
      const double qi = q0[i];
      const Eigen::Isometry3d next = frame * DofMotion(dof, qi);
      dBodyID child = last ? body_of_[static_cast<size_t>(joint.child_link)] : VirtualBody(next);
      const Eigen::Vector3d axis = frame.linear() * dof.axis;
      DofJoint& d = dofs_[static_cast<size_t>(i)];
      d.revolute = dof.type == DofType::kRevolute;
      d.q0 = qi;
      if (d.revolute) {
        d.joint = dJointCreateHinge(world_, nullptr);
        dJointAttach(d.joint, prev, child);
        dJointSetHingeAnchor(d.joint, frame.translation().x(), frame.translation().y(),
                             frame.translation().z());
        dJointSetHingeAxis(d.joint, axis.x(), axis.y(), axis.z());
      } else {
        d.joint = dJointCreateSlider(world_, nullptr);
        dJointAttach(d.joint, prev, child);
        dJointSetSliderAxis(d.joint, axis.x(), axis.y(), axis.z());
      }
      // Stops in ODE's sign: raw = q0 - q. Hinge stops must lie within (-pi, pi).
      const double lo = qi - dof.limits.upper, hi = qi - dof.limits.lower;
      if (std::isfinite(lo) && std::isfinite(hi) && (!d.revolute || (lo > -kPi && hi < kPi))) {
        if (d.revolute) {
          dJointSetHingeParam(d.joint, dParamLoStop, lo);
          dJointSetHingeParam(d.joint, dParamHiStop, hi);
        } else {
          dJointSetSliderParam(d.joint, dParamLoStop, lo);
          dJointSetSliderParam(d.joint, dParamHiStop, hi);
        }
      }
      dJointSetFeedback(d.joint, &d.feedback);
      d.last_raw = 0;
      d.unwrapped = 0;
      prev = child;
      frame = next;
    }
  }
}

void OdeWorld::SetMotor(int dof, double velocity, double max_force) {
  DofJoint& d = dofs_[static_cast<size_t>(dof)];
  d.effort_mode = false;
  d.effort_cmd = 0;
  const double f = std::isfinite(max_force) ? max_force : dInfinity;
  if (d.revolute) {
    dJointSetHingeParam(d.joint, dParamVel, -velocity);
    dJointSetHingeParam(d.joint, dParamFMax, f);
  } else {
    dJointSetSliderParam(d.joint, dParamVel, -velocity);
    dJointSetSliderParam(d.joint, dParamFMax, f);
  }
}

void OdeWorld::SetEffort(int dof, double effort) {
  DofJoint& d = dofs_[static_cast<size_t>(dof)];
  if (!d.effort_mode) {
    if (d.revolute) {
      dJointSetHingeParam(d.joint, dParamFMax, 0);
    } else {
      dJointSetSliderParam(d.joint, dParamFMax, 0);
    }
  }
  d.effort_mode = true;
  d.effort_cmd = effort;
}

void OdeWorld::SetRootVelocity(const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  if (!root_kinematic_) return;
  dBodyID b = body_of_[static_cast<size_t>(model_.roots().front().link)];
  // The body origin is the group's COM: v_com = v_link + w x (com - link).
  const Eigen::Isometry3d x = BodyPose(b);
  const Eigen::Vector3d link_origin = x * (-group_com_[static_cast<size_t>(model_.roots().front().link)]);
  const Eigen::Vector3d vc = v + w.cross(x.translation() - link_origin);
  dBodySetLinearVel(b, vc.x(), vc.y(), vc.z());
  dBodySetAngularVel(b, w.x(), w.y(), w.z());
}

void OdeWorld::AddRootForce(const Eigen::Vector3d& force) {
  dBodyAddForce(body_of_[static_cast<size_t>(model_.roots().front().link)], force.x(), force.y(), force.z());
}

void OdeWorld::SetContactSpring(int link, double stiffness, double damping) {
  const double hk = options_.step * stiffness;
  for (Geom& g : geoms_) {
    if (g.link != link) continue;
    g.erp = hk / (hk + damping);
    g.cfm = 1.0 / (hk + damping);
  }
}

void OdeWorld::Step() {
  EnsureOdeThread();
  for (DofJoint& d : dofs_) {
    if (!d.effort_mode || d.effort_cmd == 0) continue;
    if (d.revolute) {
      dJointAddHingeTorque(d.joint, -d.effort_cmd);
    } else {
      dJointAddSliderForce(d.joint, -d.effort_cmd);
    }
  }
  contacts_out_.clear();
  if (ground_) {
    for (const Geom& g : geoms_) {
      dBodyID b = dGeomGetBody(g.geom);
      if (dBodyIsKinematic(b)) continue;  // the ground cannot move it
      const int n =
          dCollide(g.geom, ground_, kMaxContactsPerGeom, contact_scratch_.data(), sizeof(dContactGeom));
      for (int c = 0; c < n; ++c) {
        dContact contact{};
        contact.geom = contact_scratch_[static_cast<size_t>(c)];
        contact.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
        contact.surface.mu = g.frictionless ? 0.0 : options_.friction;
        contact.surface.soft_erp = g.erp >= 0 ? g.erp : options_.contact_erp;
        contact.surface.soft_cfm = g.cfm >= 0 ? g.cfm : options_.contact_cfm;
        dJointID cj = dJointCreateContact(world_, contacts_, &contact);
        dJointAttach(cj, b, nullptr);
        const size_t k = contacts_out_.size();
        dJointSetFeedback(cj, &contact_feedback_[k]);
        const dReal* pos = contact.geom.pos;
        ContactPoint& out = contacts_out_.emplace_back();
        out.link = g.link;
        out.position = Eigen::Vector3d(pos[0], pos[1], pos[2]);
      }
    }
  }
  if (options_.quickstep) {
    // dRand is process-wide: keep this world's own sequence so that two
    // worlds in one process stay independent and reproducible.
    dRandSetSeed(rand_state_);
    dWorldQuickStep(world_, options_.step);
    rand_state_ = dRandGetSeed();
  } else {
    dWorldStep(world_, options_.step);
  }
  for (size_t k = 0; k < contacts_out_.size(); ++k) {
    const dReal* f = contact_feedback_[k].f1;
    contacts_out_[k].force = {f[0], f[1], f[2]};
  }
  dJointGroupEmpty(contacts_);
  ++steps_;
  ReadJoints();
}

void OdeWorld::ReadJoints() {
  for (size_t i = 0; i < dofs_.size(); ++i) {
    DofJoint& d = dofs_[i];
    if (!d.joint) continue;
    const auto ii = static_cast<Eigen::Index>(i);
    double axial = 0;
    if (d.revolute) {
      const double raw = dJointGetHingeAngle(d.joint);
      d.unwrapped += std::remainder(raw - d.last_raw, 2 * kPi);
      d.last_raw = raw;
      qd_[ii] = -dJointGetHingeAngleRate(d.joint);
      dVector3 a, anchor;
      dJointGetHingeAxis(d.joint, a);
      dJointGetHingeAnchor2(d.joint, anchor);
      const dReal* p2 = dBodyGetPosition(dJointGetBody(d.joint, 1));
      const Eigen::Vector3d axis(a[0], a[1], a[2]);
      const Eigen::Vector3d r(p2[0] - anchor[0], p2[1] - anchor[1], p2[2] - anchor[2]);
      const Eigen::Vector3d f(d.feedback.f2[0], d.feedback.f2[1], d.feedback.f2[2]);
      const Eigen::Vector3d t(d.feedback.t2[0], d.feedback.t2[1], d.feedback.t2[2]);
      axial = axis.dot(t + r.cross(f));
    } else {
      d.unwrapped = dJointGetSliderPosition(d.joint);
      qd_[ii] = -dJointGetSliderPositionRate(d.joint);
      dVector3 a;
      dJointGetSliderAxis(d.joint, a);
      axial = a[0] * d.feedback.f2[0] + a[1] * d.feedback.f2[1] + a[2] * d.feedback.f2[2];
    }
    q_[ii] = d.q0 - d.unwrapped;
    effort_[ii] = axial + (d.effort_mode ? d.effort_cmd : 0.0);
  }
}

Eigen::Isometry3d OdeWorld::LinkPose(int link) const {
  const auto l = static_cast<size_t>(link);
  const auto g = static_cast<size_t>(group_of_[l]);
  return BodyPose(body_of_[g]) * Translation(-group_com_[g]) * primary_to_link_[l];
}

Eigen::Vector3d OdeWorld::LinkLinearVelocity(int link) const {
  const Eigen::Vector3d p = LinkPose(link).translation();
  const auto g = static_cast<size_t>(group_of_[static_cast<size_t>(link)]);
  dVector3 v;
  dBodyGetPointVel(body_of_[g], p.x(), p.y(), p.z(), v);
  return {v[0], v[1], v[2]};
}

Eigen::Vector3d OdeWorld::LinkAngularVelocity(int link) const {
  const auto g = static_cast<size_t>(group_of_[static_cast<size_t>(link)]);
  const dReal* w = dBodyGetAngularVel(body_of_[g]);
  return {w[0], w[1], w[2]};
}

}  // namespace robotalk::ode_detail
