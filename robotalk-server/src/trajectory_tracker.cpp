#include "trajectory_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace robotalk {
namespace {

std::string Seconds(Duration d) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g s", ToSeconds(d));
  return text;
}

std::string Number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", x);
  return text;
}

Reply MakeAnswer(CommandId id, Signal signal, std::string message, TimePoint exec, Duration lateness) {
  Reply r;
  r.id = id;
  r.signal = signal;
  r.message = std::move(message);
  r.exec_time = exec;
  r.lateness = lateness;
  return r;
}

std::string Append(const std::string& note, const std::string& more) {
  return note.empty() ? more : note + "; " + more;
}

}  // namespace

TrajectoryTracker::TrajectoryTracker(const RobotModel& model, TrackerOptions options)
    : model_(model), options_(options), tracks_(static_cast<std::size_t>(model.joints().size())) {
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
  references_.reserve(tracks_.size());
}

std::size_t TrajectoryTracker::pending() const {
  std::size_t n = 0;
  for (const Track& t : tracks_) n += t.pending.size();
  return n;
}

void TrajectoryTracker::Add(std::span<const QueuedItem> waypoints, TimePoint now, const RobotState& state,
                            std::vector<Answer>& answers,
                            std::vector<std::pair<std::int64_t, int>>& started) {
  // Waypoints in time order per joint (ties in arrival order), so a package's
  // batch appends rather than splicing into itself.
  std::vector<const QueuedItem*> order;
  order.reserve(waypoints.size());
  for (const QueuedItem& w : waypoints) order.push_back(&w);
  std::stable_sort(order.begin(), order.end(), [](const QueuedItem* a, const QueuedItem* b) {
    return a->command.target != b->command.target ? a->command.target < b->command.target
                                                  : a->start < b->start;
  });
  for (const QueuedItem* w : order) AddOne(w->command.target, *w, now, state, answers, started);
}

void TrajectoryTracker::AddOne(int joint, const QueuedItem& item, TimePoint now, const RobotState& state,
                               std::vector<Answer>& answers,
                               std::vector<std::pair<std::int64_t, int>>& started) {
  Track& t = tracks_[static_cast<std::size_t>(joint)];
  const std::string label = std::string("JOINT_SETPOINT '") + model_.joint(joint).name + "'";
  Pending p;
  p.client_id = item.client_id;
  p.id = item.command.id;
  p.requested = item.start;
  Waypoint& w = p.waypoint;
  w.time = item.start;
  w.position.resize(t.dofs);
  for (int k = 0; k < t.dofs; ++k) {
    const double want = item.command.values[static_cast<std::size_t>(k)];
    const double got = std::clamp(want, t.limits.position_min[k], t.limits.position_max[k]);
    w.position[k] = got;
    if (got != want) {
      p.note = Append(p.note, "dof " + std::to_string(k) + ": " + Number(want) + " clamped to the " +
                                  (want > got ? "upper" : "lower") + " limit " + Number(got));
    }
  }
  if (item.num_velocities == t.dofs) {
    w.velocity = Eigen::Map<const Eigen::VectorXd>(item.velocities.data(), t.dofs);
  }
  if (item.num_accelerations == t.dofs) {
    w.acceleration = Eigen::Map<const Eigen::VectorXd>(item.accelerations.data(), t.dofs);
  }

  // A trajectory of another interpolation is replaced from now, as a splice.
  if (t.trajectory && t.trajectory->interpolation() != item.interpolation) {
    End(joint, now,
        label + ": superseded by command " + std::to_string(item.command.id) + " (" +
            InterpolationName(item.interpolation) + ")",
        answers);
  }
  // Late: after its time. Skipped when a later waypoint is planned (the
  // trajectory already runs past it); else joined one period from now.
  if (w.time <= now) {
    const bool later_planned = !t.pending.empty() && t.pending.back().waypoint.time > now;
    if (later_planned) {
      answers.push_back({item.client_id,
                         MakeAnswer(item.command.id, Signal::kInterrupted,
                                    label + ": arrived " + Seconds(now - w.time) +
                                        " after its time; a later waypoint is already planned; not executed",
                                    now, now - w.time)});
      return;
    }
    p.note = Append(p.note, "arrived " + Seconds(now - w.time) + " after its time: joined " +
                                Seconds(options_.period) + " from its arrival");
    w.time = now + options_.period;
  }

  const bool idle = !t.trajectory;
  if (idle) {
    TrajectoryState start;
    start.position = state.position.segment(t.first_dof, t.dofs);
    start.velocity = state.velocity.segment(t.first_dof, t.dofs);
    t.trajectory.emplace(item.interpolation, now, start, t.limits.acceleration);
    t.sample = t.trajectory->MakeSample();
    t.ref_position = start.position;
    t.ref_velocity = start.velocity;
    t.ref_acceleration = Eigen::VectorXd::Zero(t.dofs);
    t.last_sample = now;
    t.on_plan = true;
    t.fresh = true;
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
  std::vector<Waypoint> batch;
  TimePoint splice = now;
  if (keep > 0) {
    const Pending& before = t.pending[keep - 1];
    if (before.waypoint.time > now) {
      // Splice at the knot before it, when that is still ahead.
      const TimePoint prior = keep >= 2 ? t.pending[keep - 2].waypoint.time : traj.knot_time(0);
      splice = std::max(prior, now);
      batch.push_back(before.waypoint);
    }
  }
  batch.push_back(w);
  try {
    traj.Splice(splice, batch);
  } catch (const Error& e) {  // a time the trajectory cannot take: refused, nothing changed
    answers.push_back({item.client_id, MakeAnswer(item.command.id, Signal::kError, label + ": " + e.what(),
                                                  now, Duration(0))});
    if (idle && t.pending.empty()) {
      t.trajectory.reset();
      --active_;
    }
    return;
  }
  t.pending.push_back(std::move(p));
  if (idle || t.owner != item.client_id) started.emplace_back(item.client_id, joint);
  t.owner = item.client_id;
}

void TrajectoryTracker::Interrupt(Track& t, std::size_t from, TimePoint now, const std::string& why,
                                  std::vector<Answer>& answers) {
  for (std::size_t i = from; i < t.pending.size(); ++i) {
    answers.push_back(
        {t.pending[i].client_id, MakeAnswer(t.pending[i].id, Signal::kInterrupted, why, now, Duration(0))});
  }
  t.pending.erase(t.pending.begin() + static_cast<std::ptrdiff_t>(from), t.pending.end());
}

void TrajectoryTracker::Sample(TimePoint now, std::vector<Answer>& answers) {
  const auto label_of = [this](int joint) { return "JOINT_SETPOINT '" + model_.joint(joint).name + "'"; };
  references_.clear();
  for (std::size_t j = 0; j < tracks_.size(); ++j) {
    Track& t = tracks_[j];
    if (!t.trajectory) continue;
    Trajectory& traj = *t.trajectory;
    traj.Sample(now, &t.sample);
    Limit(t, now);
    while (!t.pending.empty() && t.pending.front().waypoint.time <= now) {
      Pending& p = t.pending.front();
      const Duration late = p.waypoint.time > p.requested ? p.waypoint.time - p.requested : Duration(0);
      if (!t.limited.empty()) {  // since the previous waypoint
        const double off = (t.ref_position - t.sample.position).cwiseAbs().maxCoeff();
        p.note = Append(p.note, "reference limited: " + label_of(static_cast<int>(j)) + " " + t.limited +
                                    "; the reference was " + Number(off) + " from it at its time");
        t.limited.clear();
      }
      const Signal signal = p.note.empty() ? Signal::kSuccess : Signal::kModified;
      answers.push_back({p.client_id, MakeAnswer(p.id, signal, std::move(p.note), p.waypoint.time, late)});
      t.pending.pop_front();
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
}

void TrajectoryTracker::Limit(Track& t, TimePoint now) {
  if (now <= t.last_sample && !t.fresh) return;  // sampled at this time already: the same reference
  const bool first = t.fresh;
  t.fresh = false;
  const double dt = std::clamp(ToSeconds(now - t.last_sample), 1e-4, 1.0);
  t.last_sample = now;
  bool on_plan = true;
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
    const bool reachable = first || (std::abs(v - v0) <= amax * dt * (1 + kRound) + kRound &&
                                     std::abs((p - p0) / dt - 0.5 * (v0 + v)) <= amax * dt / 4 + kRound);
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
}

void TrajectoryTracker::End(int joint, TimePoint now, const std::string& why, std::vector<Answer>& answers) {
  Track& t = tracks_[static_cast<std::size_t>(joint)];
  if (!t.trajectory) return;
  Interrupt(t, 0, now, why, answers);
  t.trajectory.reset();
  --active_;
}

void TrajectoryTracker::EndAll(TimePoint now, const std::string& why, std::vector<Answer>& answers) {
  for (std::size_t j = 0; j < tracks_.size(); ++j) End(static_cast<int>(j), now, why, answers);
}

}  // namespace robotalk
