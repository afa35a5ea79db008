#include "trajectory_tracker.h"

#include "expiry.h"
#include "planner_answers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace robotalk {
namespace {

using planner_answers::Append;
using planner_answers::MakeAnswer;
using planner_answers::Seconds;

std::string Number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

// "<whose>: superseded by <by> command <id>", what a replaced waypoint answers.
std::string SupersededBy(const std::string& whose, const std::string& by, CommandId id) {
  return whose + ": superseded by " + by + " command " + std::to_string(id);
}

// What a trajectory of another interpolation answers when `item` replaces it.
std::string SupersededByInterpolation(const std::string& whose, const QueuedItem& item) {
  return whose + ": superseded by command " + std::to_string(item.command.id) + " (" +
         InterpolationName(item.interpolation) + ")";
}

}  // namespace

TrajectoryTracker::Pending& TrajectoryTracker::PendingQueue::push_back() {
  if (count_ == slots_.size()) {  // full: unroll the ring, then double it
    std::rotate(slots_.begin(), slots_.begin() + static_cast<std::ptrdiff_t>(head_), slots_.end());
    head_ = 0;
    slots_.resize(std::max<std::size_t>(4, 2 * slots_.size()));
  }
  return (*this)[count_++];
}

TrajectoryTracker::TrajectoryTracker(const RobotModel& model, TrackerOptions options)
    : model_(model),
      options_(options),
      tracks_(static_cast<std::size_t>(model.joints().size())),
      frame_tracks_(model.frames().size()),
      kinematics_(model),
      ik_(model) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    Track& t = tracks_[j];
    const Joint& joint = model.joint(static_cast<int>(j));
    t.first_dof = model.dof_offset(static_cast<int>(j));
    t.dofs = static_cast<int>(joint.dofs.size());
    t.limits.position_min.resize(t.dofs);
    t.limits.position_max.resize(t.dofs);
    t.limits.velocity.resize(t.dofs);
    t.limits.acceleration = Eigen::VectorXd::Constant(t.dofs, options.acceleration_limit);
    for (int k = 0; k < t.dofs; ++k) {
      const DofLimits& l = joint.dofs[static_cast<std::size_t>(k)].limits;
      t.limits.position_min[k] = l.lower;
      t.limits.position_max[k] = l.upper;
      t.limits.velocity[k] = std::isfinite(l.velocity) ? l.velocity : kInf;
    }
  }
  for (std::size_t f = 0; f < frame_tracks_.size(); ++f) {
    Track& t = frame_tracks_[f];
    t.frame = static_cast<int>(f);
    t.dofs = 6;
    t.limits.acceleration = Eigen::VectorXd::Constant(6, options.acceleration_limit);
    const std::span<const std::uint8_t> mask = ik_.default_mask(static_cast<int>(f));
    for (std::size_t j = 0; j < tracks_.size(); ++j) {
      const int first = model.dof_offset(static_cast<int>(j));
      for (int k = 0; k < tracks_[j].dofs; ++k) {
        if (mask[static_cast<std::size_t>(first + k)]) {
          t.chain.push_back(static_cast<int>(j));
          break;
        }
      }
    }
  }
  for (std::size_t j = 0; j < tracks_.size(); ++j)
    tracks_[j].label = std::string("JOINT_SETPOINT '") + model.joint(static_cast<int>(j)).name + "'";
  for (std::size_t f = 0; f < frame_tracks_.size(); ++f)
    frame_tracks_[f].label = std::string("FRAME_SETPOINT '") + model.frame(static_cast<int>(f)).name + "'";
  // The buffers an addition reuses, sized once.
  for (std::vector<Track>* tracks : {&tracks_, &frame_tracks_}) {
    for (Track& t : *tracks) {
      t.incoming.waypoint.position = Eigen::VectorXd::Zero(t.dofs);
      t.batch.assign(3, Waypoint{{}, Eigen::VectorXd::Zero(t.dofs), {}, {}});
    }
  }
  // A joint a frame's trajectory moves gets its references from the
  // inverse kinematics, limited as its own (sized once).
  for (Track& t : tracks_) {
    for (Eigen::VectorXd* v : {&t.sample.position, &t.sample.velocity, &t.sample.acceleration,
                               &t.ref_position, &t.ref_velocity, &t.ref_acceleration, &t.solved_velocity}) {
      *v = Eigen::VectorXd::Zero(t.dofs);
    }
  }
  ik_start_ = Eigen::VectorXd::Zero(model.num_dofs());
  int widest = 6;  // a frame's track
  for (const Track& t : tracks_) widest = std::max(widest, t.dofs);
  velocity_before_ = Eigen::VectorXd::Zero(widest);
  references_.reserve(tracks_.size());
  order_.reserve(64);
}

std::size_t TrajectoryTracker::pending() const {
  std::size_t n = 0;
  for (const Track& t : tracks_) n += t.pending.size();
  for (const Track& t : frame_tracks_) n += t.pending.size();
  return n;
}

void TrajectoryTracker::CountPending(planner_answers::HeldCounts& counts) const {
  for (const std::vector<Track>* tracks : {&tracks_, &frame_tracks_}) {
    for (const Track& t : *tracks) {
      for (std::size_t i = 0; i < t.pending.size(); ++i)
        planner_answers::CountHeld(counts, t.pending[i].client_id);
    }
  }
}

void TrajectoryTracker::Add(std::span<const QueuedItem> waypoints, TimePoint now, const RobotState& state,
                            std::vector<Answer>& answers, std::vector<Started>& started) {
  // Waypoints in time order per joint (ties in arrival order), so a package's
  // batch appends rather than splicing into itself.
  std::vector<const QueuedItem*>& order = order_;
  order.clear();
  for (const QueuedItem& w : waypoints) order.push_back(&w);
  // std::sort, not stable_sort (which allocates): ties in arrival order by
  // their place in `waypoints`.
  std::sort(order.begin(), order.end(), [](const QueuedItem* a, const QueuedItem* b) {
    if (a->command.type != b->command.type) return a->command.type < b->command.type;
    if (a->command.target != b->command.target) return a->command.target < b->command.target;
    return a->start != b->start ? a->start < b->start : a < b;
  });
  for (const QueuedItem* w : order) {
    if (w->command.type == CommandType::kFrameSetPoint) {
      AddFrameWaypoint(*w, now, state, answers, started);
    } else {
      AddJointWaypoint(*w, now, state, answers, started);
    }
  }
}

void TrajectoryTracker::AddJointWaypoint(const QueuedItem& item, TimePoint now, const RobotState& state,
                                         std::vector<Answer>& answers, std::vector<Started>& started) {
  const int joint = item.command.target;
  Track& t = tracks_[static_cast<std::size_t>(joint)];
  const std::string& label = t.label;
  if (t.moved_by >= 0) {  // a frame's trajectory moves it: the joint's own waypoint replaces that
    EndFrame(t.moved_by, now,
             SupersededBy(frame_tracks_[static_cast<std::size_t>(t.moved_by)].label, label, item.command.id),
             answers);
  }
  // A trajectory of another interpolation is replaced from now, as a splice.
  if (t.trajectory && t.trajectory->interpolation() != item.interpolation)
    EndTrack(t, now, SupersededByInterpolation(label, item), answers);
  Pending& p = Incoming(t, item);
  Waypoint& w = p.waypoint;
  for (int k = 0; k < t.dofs; ++k) {
    const double want = item.command.values[static_cast<std::size_t>(k)];
    const double got = std::clamp(want, t.limits.position_min[k], t.limits.position_max[k]);
    w.position[k] = got;
    if (got != want) {
      p.note = Append(p.note, "dof " + std::to_string(k) + ": " + Number(want) + " clamped to the " +
                                  (want > got ? "upper" : "lower") + " limit " + Number(got));
    }
  }
  // Given rates, or empty (chosen); the vectors keep their memory while the kind does not change.
  const auto rates = [&t](Eigen::VectorXd& out, int given, const std::array<double, 6>& values) {
    if (given == t.dofs) {
      out = Eigen::Map<const Eigen::VectorXd>(values.data(), t.dofs);
    } else if (out.size() != 0) {
      out.resize(0);
    }
  };
  rates(w.velocity, item.num_velocities, item.velocities);
  rates(w.acceleration, item.num_accelerations, item.accelerations);
  const bool idle = !t.trajectory;
  TrajectoryState start;  // where an idle joint's trajectory starts
  if (idle) {
    start.position = state.position.segment(t.first_dof, t.dofs);
    start.velocity = state.velocity.segment(t.first_dof, t.dofs);
  }
  if (!Join(t, label, p, item, now, start, answers)) return;
  if (idle || t.owner != item.client_id)
    started.push_back({item.client_id, CommandType::kJointSetPoint, joint});
  t.owner = item.client_id;
}

void TrajectoryTracker::AddFrameWaypoint(const QueuedItem& item, TimePoint now, const RobotState& state,
                                         std::vector<Answer>& answers, std::vector<Started>& started) {
  const int frame = item.command.target;
  Track& t = frame_tracks_[static_cast<std::size_t>(frame)];
  const std::string& label = t.label;
  if (t.chain.empty()) {  // as a step FRAME_SETPOINT would be answered by the drivers
    answers.push_back(
        {item.client_id, MakeAnswer(item.command.id, Signal::kNa,
                                    label + ": no joint between the frame and its root accepts set-points",
                                    now, Duration(0))});
    return;
  }
  if (t.trajectory && t.trajectory->interpolation() != item.interpolation)
    EndFrame(frame, now, SupersededByInterpolation(label, item), answers);
  const bool idle = !t.trajectory;
  TrajectoryState start;
  if (idle) {
    // Its joints leave whatever trajectory they had; it starts where the frame is.
    for (int j : t.chain) {
      Track& joint = tracks_[static_cast<std::size_t>(j)];
      if (joint.moved_by >= 0) {
        EndFrame(joint.moved_by, now,
                 SupersededBy(frame_tracks_[static_cast<std::size_t>(joint.moved_by)].label, label,
                              item.command.id),
                 answers);
      }
      if (joint.trajectory) EndTrack(joint, now, SupersededBy(joint.label, label, item.command.id), answers);
    }
    roots_.clear();
    for (const Pose& r : state.root_poses) roots_.push_back(r.ToIsometry());
    kinematics_.Update(state.position, roots_);
    const Eigen::Isometry3d pose = kinematics_.frame_pose(frame);
    t.base = Eigen::Quaterniond(pose.rotation());
    const Eigen::Matrix<double, 6, 1> twist = kinematics_.FrameJacobian(frame) * state.velocity;
    start.position = Eigen::VectorXd::Zero(6);
    start.position.head<3>() = pose.translation();
    start.velocity = Eigen::VectorXd::Zero(6);
    start.velocity.head<3>() = twist.head<3>();
    start.velocity.tail<3>() = t.base.conjugate() * Eigen::Vector3d(twist.tail<3>());
    ik_start_ = state.position;
  }
  Pending& p = Incoming(t, item);
  Waypoint& w = p.waypoint;
  const auto& v = item.command.values;
  Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  q.normalize();
  if (q.dot(t.base) < 0) q.coeffs() = -q.coeffs();  // the same rotation, the short way from the base
  const Eigen::AngleAxisd relative(t.base.conjugate() * q);
  w.position << v[0], v[1], v[2], relative.angle() * relative.axis();
  // Given rates are world twists: the rotation part in the base's axes (the
  // rotation vector's rate, exact while the rotation turns about one axis).
  const auto twist = [&t](Eigen::VectorXd& out, int given, const std::array<double, 6>& r) {
    if (given != 6) {
      if (out.size() != 0) out.resize(0);
      return;
    }
    out.resize(6);
    out.head<3>() = Eigen::Vector3d(r[0], r[1], r[2]);
    out.tail<3>() = t.base.conjugate() * Eigen::Vector3d(r[3], r[4], r[5]);
  };
  twist(w.velocity, item.num_velocities, item.velocities);
  twist(w.acceleration, item.num_accelerations, item.accelerations);
  if (!Join(t, label, p, item, now, start, answers)) return;
  if (idle) {
    for (int j : t.chain) {
      Track& joint = tracks_[static_cast<std::size_t>(j)];
      joint.moved_by = frame;
      joint.ref_position = state.position.segment(joint.first_dof, joint.dofs);
      joint.ref_velocity = state.velocity.segment(joint.first_dof, joint.dofs);
      joint.ref_acceleration.setZero();
      joint.solved_velocity = joint.ref_velocity;
      joint.last_sample = now;
      joint.fresh = true;
      joint.on_plan = true;
      joint.limited.clear();
    }
  }
  if (idle || t.owner != item.client_id)
    started.push_back({item.client_id, CommandType::kFrameSetPoint, frame});
  t.owner = item.client_id;
}

TrajectoryTracker::Pending& TrajectoryTracker::Incoming(Track& t, const QueuedItem& item) {
  Pending& p = t.incoming;
  p.client_id = item.client_id;
  p.id = item.command.id;
  p.requested = item.start;
  p.note.clear();
  p.waypoint.time = item.start;
  return p;
}

bool TrajectoryTracker::Join(Track& t, const std::string& label, Pending& p, const QueuedItem& item,
                             TimePoint now, const TrajectoryState& start, std::vector<Answer>& answers) {
  Waypoint& w = p.waypoint;
  // Late: after its time. Skipped when a later waypoint is planned (the
  // trajectory already runs past it); else joined one period from now.
  if (w.time <= now) {
    // Past its deadline (issue 23, the package's max_late or the robot's
    // --max-late): not executed, as any expired servo command.
    if (std::optional<std::string> expired =
            ExpiryRefusal(now - w.time, item.max_late, item.received - item.start)) {
      answers.push_back({item.client_id, MakeAnswer(item.command.id, Signal::kInterrupted,
                                                    *expired + " (" + label + ")", now, now - w.time)});
      return false;
    }
    const bool later_planned = !t.pending.empty() && t.pending.back().waypoint.time > now;
    if (later_planned) {
      answers.push_back({item.client_id,
                         MakeAnswer(item.command.id, Signal::kInterrupted,
                                    label + ": arrived " + Seconds(now - w.time) +
                                        " after its time; a later waypoint is already planned; not executed",
                                    now, now - w.time)});
      return false;
    }
    p.note = Append(p.note, "arrived " + Seconds(now - w.time) + " after its time: joined " +
                                Seconds(options_.period) + " from its arrival");
    w.time = now + options_.period;
  }
  const bool idle = !t.trajectory;
  if (idle) {
    t.trajectory.emplace(item.interpolation, now, start, t.limits.acceleration);
    t.sample = t.trajectory->MakeSample();
    t.ref_position = start.position;
    t.ref_velocity = start.velocity.size() ? start.velocity : Eigen::VectorXd::Zero(t.dofs);
    t.ref_acceleration = Eigen::VectorXd::Zero(t.dofs);
    t.last_sample = now;
    t.on_plan = true;
    t.fresh = true;
    t.limited.clear();
    ++active_;
  }
  Trajectory& traj = *t.trajectory;
  // Waypoints at or after the new one's time are replaced; the one just
  // before it is planned again (its velocity depends on its next).
  std::size_t keep = t.pending.size();
  while (keep > 0 && t.pending[keep - 1].waypoint.time >= w.time) --keep;
  if (keep < t.pending.size()) {
    Interrupt(t, keep, now,
              label + ": superseded by command " + std::to_string(item.command.id) +
                  (t.pending[keep].client_id == item.client_id ? std::string()
                                                               : " of another client (last commanded wins)"),
              answers);
  }
  std::size_t batch = 0;  // t.batch's used entries
  TimePoint splice = now;
  // The waypoints whose chosen rates depend on the new one are planned again:
  // the one before it (its velocity), and for quintic the one before that
  // too (its acceleration depends on the next velocity) -- those still ahead.
  const std::size_t again = traj.interpolation() == Interpolation::kQuintic ? 2 : 1;
  std::size_t from = keep;
  while (from > 0 && keep - from < again && t.pending[from - 1].waypoint.time > now) --from;
  if (from < keep) {
    // Splice at the knot before them, when that is still ahead.
    const TimePoint prior = from >= 1 ? t.pending[from - 1].waypoint.time : traj.knot_time(0);
    splice = std::max(prior, now);
    for (std::size_t i = from; i < keep; ++i) t.batch[batch++] = t.pending[i].waypoint;
  }
  t.batch[batch++] = w;
  try {
    traj.Splice(splice, std::span<const Waypoint>(t.batch.data(), batch));
  } catch (const Error& e) {  // a time the trajectory cannot take: refused, nothing changed
    answers.push_back({item.client_id, MakeAnswer(item.command.id, Signal::kError, label + ": " + e.what(),
                                                  now, Duration(0))});
    if (idle && t.pending.empty()) {
      t.trajectory.reset();
      --active_;
    }
    return false;
  }
  t.pending.push_back() = p;
  return true;
}

void TrajectoryTracker::Interrupt(Track& t, std::size_t from, TimePoint now, const std::string& why,
                                  std::vector<Answer>& answers) {
  for (std::size_t i = from; i < t.pending.size(); ++i) {
    answers.push_back(
        {t.pending[i].client_id, MakeAnswer(t.pending[i].id, Signal::kInterrupted, why, now, Duration(0))});
  }
  t.pending.truncate(from);
}

void TrajectoryTracker::AnswerPassed(Track& t, TimePoint now, const std::string& label,
                                     std::vector<Answer>& answers) {
  while (!t.pending.empty() && t.pending.front().waypoint.time <= now) {
    Pending& p = t.pending.front();
    const Duration late = p.waypoint.time > p.requested ? p.waypoint.time - p.requested : Duration(0);
    if (!t.limited.empty()) {  // since the previous waypoint
      p.note = Append(p.note, "reference limited: " + label + " " + t.limited);
      if (t.frame < 0) {
        const double off = (t.ref_position - t.sample.position).cwiseAbs().maxCoeff();
        p.note += "; the reference was " + Number(off) + " from it at its time";
      }
      t.limited.clear();
    }
    const Signal signal = p.note.empty() ? Signal::kSuccess : Signal::kModified;
    answers.push_back({p.client_id, MakeAnswer(p.id, signal, std::move(p.note), p.waypoint.time, late)});
    t.pending.pop_front();
  }
}

void TrajectoryTracker::Sample(TimePoint now, std::vector<Answer>& answers) {
  references_.clear();
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    Track& t = tracks_[j];
    if (!t.trajectory) continue;
    Trajectory& traj = *t.trajectory;
    traj.Sample(now, &t.sample);
    Limit(t, now);
    if (!t.pending.empty() && t.pending.front().waypoint.time <= now) {
      AnswerPassed(t, now, t.label, answers);
    }
    references_.push_back(JointReference{static_cast<int>(j),
                                         {t.ref_position.data(), static_cast<std::size_t>(t.dofs)},
                                         {t.ref_velocity.data(), static_cast<std::size_t>(t.dofs)},
                                         {t.ref_acceleration.data(), static_cast<std::size_t>(t.dofs)}});
    // Passed and at rest: the joint holds its last reference; the trajectory
    // ends (the driver keeps the set-point).
    if (t.pending.empty() && t.sample.holding && t.on_plan && t.ref_velocity.isZero(0.0)) {
      t.trajectory.reset();
      --active_;
    } else if (traj.num_knots() > 64) {
      traj.Forget(now);  // bounded however long a stream runs
    }
  }
  for (Track& f : frame_tracks_) {
    if (f.trajectory) SampleFrame(f, now, answers);
  }
}

void TrajectoryTracker::SampleFrame(Track& f, TimePoint now, std::vector<Answer>& answers) {
  Trajectory& traj = *f.trajectory;
  traj.Sample(now, &f.sample);
  const double dt = std::clamp(ToSeconds(now - f.last_sample), 1e-4, 1.0);
  const bool first = f.fresh;
  if (now <= f.last_sample && !first) return;
  f.fresh = false;
  f.last_sample = now;
  // The pose: the position, and the base orientation turned by the rotation vector.
  const Eigen::Vector3d r = f.sample.position.tail<3>();
  const double angle = r.norm();
  const Eigen::Quaterniond orientation =
      angle > 0 ? f.base * Eigen::Quaterniond(Eigen::AngleAxisd(angle, r / angle)) : f.base;
  const InverseKinematics::Result solved =
      ik_.Solve(f.frame, f.sample.position.head<3>(), orientation, ik_start_, roots_);
  ik_start_ = ik_.solution();
  bool joints_on_plan = true, at_rest = true;
  for (int j : f.chain) {
    Track& t = tracks_[static_cast<std::size_t>(j)];
    for (int k = 0; k < t.dofs; ++k) {
      const double q = ik_start_[t.first_dof + k];
      const double v = first ? t.ref_velocity[k] : (q - t.sample.position[k]) / dt;
      t.sample.acceleration[k] = first ? 0.0 : (v - t.solved_velocity[k]) / dt;
      t.sample.velocity[k] = v;
      t.solved_velocity[k] = v;
      t.sample.position[k] = q;
    }
    t.sample.holding = f.sample.holding;
    Limit(t, now);
    if (!t.limited.empty() && f.limited.empty())
      f.limited = "joint '" + model_.joint(j).name + "': " + t.limited;
    t.limited.clear();
    joints_on_plan = joints_on_plan && t.on_plan;
    at_rest = at_rest && t.ref_velocity.isZero(0.0);
    references_.push_back(JointReference{j,
                                         {t.ref_position.data(), static_cast<std::size_t>(t.dofs)},
                                         {t.ref_velocity.data(), static_cast<std::size_t>(t.dofs)},
                                         {t.ref_acceleration.data(), static_cast<std::size_t>(t.dofs)}});
  }
  if (!f.pending.empty() && f.pending.front().waypoint.time <= now) {
    if (!solved.within_tolerance) {
      char text[160];
      std::snprintf(text, sizeof text, "the inverse kinematics ended %.3g m and %.3g rad from the pose",
                    solved.position_error, solved.orientation_error);
      f.pending.front().note = Append(f.pending.front().note, text);
    }
    AnswerPassed(f, now, f.label, answers);
  }
  if (f.pending.empty() && f.sample.holding && f.sample.velocity.isZero(0.0) && joints_on_plan && at_rest) {
    EndFrame(f.frame, now, "", answers);
  } else if (traj.num_knots() > 64) {
    traj.Forget(now);
  }
}

void TrajectoryTracker::Limit(Track& t, TimePoint now) {
  if (now <= t.last_sample && !t.fresh) return;  // sampled at this time already: the same reference
  const bool first = t.fresh;
  t.fresh = false;
  // A fresh trajectory's first reference is at its start, where the joint is:
  // the plan's position there is the start's, but its velocity need not be (a
  // linear plan's first slope, unlimited before review 10): it may step by
  // one period's worth of the limit, as after a reference a period before.
  const double dt =
      first ? ToSeconds(options_.period) : std::clamp(ToSeconds(now - t.last_sample), 1e-4, 1.0);
  t.last_sample = now;
  bool on_plan = true;
  velocity_before_.head(t.dofs) = t.ref_velocity;
  for (int k = 0; k < t.dofs; ++k) {
    const double amax = t.limits.acceleration[k], vmax = t.limits.velocity[k];
    const double lo = t.limits.position_min[k], hi = t.limits.position_max[k];
    const double p = t.sample.position[k], v = t.sample.velocity[k], a = t.sample.acceleration[k];
    const double p0 = t.ref_position[k], v0 = t.ref_velocity[k];
    constexpr double kRound = 1e-9;
    // The plan's sample, if it is within the limits and a motion within the
    // acceleration limit leads there from the last reference in dt (its
    // velocity change at most amax·dt, its mean velocity within amax·dt/4 of
    // the trapezoid's).
    const bool within =
        std::abs(v) <= vmax * (1 + kRound) && std::abs(a) <= amax * (1 + kRound) && p >= lo && p <= hi;
    const bool reachable = std::abs(v - v0) <= amax * dt * (1 + kRound) + kRound &&
                           (first || std::abs((p - p0) / dt - 0.5 * (v0 + v)) <= amax * dt / 4 + kRound);
    if (within && reachable) {
      t.ref_position[k] = p;
      t.ref_velocity[k] = v;
      t.ref_acceleration[k] = a;
      continue;
    }
    // Else toward it within the limits: a velocity that closes the position
    // error no faster than it could brake, reached within the acceleration
    // limit (a rate limiter, which catches the plan up when it can).
    on_plan = false;
    if (t.limited.empty()) {  // the first limit met since the last waypoint (allocates once)
      char what[160];
      if (std::abs(v) > vmax * (1 + kRound)) {
        std::snprintf(what, sizeof what, "dof %d: the plan's |velocity| %.4g exceeds the limit %.4g", k,
                      std::abs(v), vmax);
      } else if (p < lo || p > hi) {
        std::snprintf(what, sizeof what, "dof %d: the plan's position %.4g is outside [%.4g, %.4g]", k, p, lo,
                      hi);
      } else {
        std::snprintf(what, sizeof what,
                      "dof %d: the plan needs an |acceleration| of %.4g, beyond the limit %.4g", k,
                      std::max(std::abs(a), std::abs(v - v0) / dt), amax);
      }
      t.limited = what;
    }
    if (first) {  // at the start: the plan's position, the velocity toward the plan's within the limits
      const double a1 = std::clamp((v - v0) / dt, -amax, amax);
      t.ref_position[k] = std::clamp(p, lo, hi);
      t.ref_velocity[k] = std::clamp(v0 + a1 * dt, -vmax, vmax);
      t.ref_acceleration[k] = a1;
      continue;
    }
    const double e = p - (p0 + v0 * dt);  // the plan against where the reference would coast to
    const double close = std::min(std::abs(e) / (4 * dt), std::sqrt(2 * amax * std::abs(e)));
    const double v_want = std::clamp(v + std::copysign(close, e), -vmax, vmax);
    const double a1 = std::clamp((v_want - v0) / dt, -amax, amax);
    double v1 = v0 + a1 * dt;
    double p1 = p0 + 0.5 * (v0 + v1) * dt;
    if (p1 < lo || p1 > hi) {
      p1 = std::clamp(p1, lo, hi);
      v1 = 0;
    }
    t.ref_position[k] = p1;
    t.ref_velocity[k] = v1;
    t.ref_acceleration[k] = a1;
  }
  t.on_plan = on_plan;
  for (int k = 0; k < t.dofs; ++k) {
    max_reference_acceleration_ =
        std::max(max_reference_acceleration_, std::abs(t.ref_velocity[k] - velocity_before_[k]) / dt);
  }
}

void TrajectoryTracker::EndTrack(Track& t, TimePoint now, const std::string& why,
                                 std::vector<Answer>& answers) {
  if (!t.trajectory) return;
  // Waypoints whose time has come were passed (the next control period would
  // have answered them): only the ones still ahead are interrupted.
  if (!t.pending.empty() && t.pending.front().waypoint.time <= now) AnswerPassed(t, now, t.label, answers);
  Interrupt(t, 0, now, why, answers);
  t.trajectory.reset();
  --active_;
}

void TrajectoryTracker::EndFrame(int frame, TimePoint now, const std::string& why,
                                 std::vector<Answer>& answers) {
  Track& f = frame_tracks_[static_cast<std::size_t>(frame)];
  EndTrack(f, now, why, answers);
  for (int j : f.chain) {
    if (tracks_[static_cast<std::size_t>(j)].moved_by == frame)
      tracks_[static_cast<std::size_t>(j)].moved_by = -1;
  }
}

void TrajectoryTracker::End(int joint, TimePoint now, const std::string& why, std::vector<Answer>& answers) {
  Track& t = tracks_[static_cast<std::size_t>(joint)];
  if (t.moved_by >= 0) EndFrame(t.moved_by, now, why, answers);
  EndTrack(t, now, why, answers);
}

void TrajectoryTracker::EndAll(TimePoint now, const std::string& why, std::vector<Answer>& answers) {
  for (std::size_t f = 0; f < frame_tracks_.size(); ++f) EndFrame(static_cast<int>(f), now, why, answers);
  for (Track& t : tracks_) EndTrack(t, now, why, answers);
}

void TrajectoryTracker::Abandon(TimePoint now, const std::string& why, std::vector<Answer>& answers) {
  for (std::vector<Track>* kind : {&frame_tracks_, &tracks_}) {
    for (Track& t : *kind) {
      Interrupt(t, 0, now, t.label + ": " + why, answers);
      t.trajectory.reset();
      t.moved_by = -1;
    }
  }
  references_.clear();
  active_ = 0;
}

}  // namespace robotalk
