// The RobotDaemon's read-out and timing (robot_daemon.h): answering queries
// (queued, or on receipt from the state snapshot), state samples, and the
// thread's timing option (timer slack, final spin, SCHED_FIFO).
#include "robot_daemon.h"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace robotalk {
namespace {

void WritePose(const Eigen::Isometry3d& x, double* out) {
  const Eigen::Quaterniond q(x.linear());
  out[0] = x.translation().x();
  out[1] = x.translation().y();
  out[2] = x.translation().z();
  out[3] = q.w();
  out[4] = q.x();
  out[5] = q.y();
  out[6] = q.z();
}

double Yaw(const Eigen::Isometry3d& x) { return std::atan2(x.linear()(1, 0), x.linear()(0, 0)); }

std::string NotFinite(double v) { return std::isnan(v) ? "NaN" : (v > 0 ? "+inf" : "-inf"); }

}  // namespace

std::optional<std::string> NonFiniteState(const RobotModel& model, const RobotState& state) {
  // The usual case, allocation-free: everything finite.
  const auto finite = [](const Eigen::VectorXd& v) { return v.allFinite(); };
  bool roots_finite = std::isfinite(state.base_v) && std::isfinite(state.base_omega);
  for (const Pose& p : state.root_poses) {
    roots_finite = roots_finite && p.translation.allFinite() && p.rotation.coeffs().allFinite();
  }
  if (finite(state.position) && finite(state.velocity) && finite(state.effort) && roots_finite) {
    return std::nullopt;
  }
  static constexpr const char* kWhat[3] = {"position", "velocity", "effort"};
  const Eigen::VectorXd* vectors[3] = {&state.position, &state.velocity, &state.effort};
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const Joint& joint = model.joint(j);
    for (int k = 0; k < static_cast<int>(joint.dofs.size()); ++k) {
      const int i = model.dof_offset(j) + k;
      for (int w = 0; w < 3; ++w) {
        if (i < vectors[w]->size() && !std::isfinite((*vectors[w])[i])) {
          return "joint '" + joint.name + "' dof " + std::to_string(k) + " " + kWhat[w] + " is " +
                 NotFinite((*vectors[w])[i]);
        }
      }
    }
  }
  if (!std::isfinite(state.base_v)) return "base v is " + NotFinite(state.base_v);
  if (!std::isfinite(state.base_omega)) return "base omega is " + NotFinite(state.base_omega);
  for (std::size_t r = 0; r < state.root_poses.size(); ++r) {
    const Pose& p = state.root_poses[r];
    const std::string root =
        r < model.roots().size() ? "root '" + model.link(model.roots()[r].link).name + "'" : "root";
    static constexpr const char* kAxis[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
      if (!std::isfinite(p.translation[a]))
        return root + " " + kAxis[a] + " is " + NotFinite(p.translation[a]);
    }
    if (!p.rotation.coeffs().allFinite()) return root + " orientation is not finite";
  }
  return "a value is not finite";  // sizes that do not match the model
}

// Absolute deadline: the next start time, driver period or sample. With
// precise timing, the last `final_spin` before a start time or sample is a
// busy wait with the lock released (a futex wake-up is tens of µs late on a
// loaded machine); it ends at the deadline, so it is bounded by final_spin.
void RobotDaemon::WaitUntil(std::unique_lock<std::mutex>& lock, TimePoint next) {
  const auto woken = [this] { return wake_flag_ || !running_ || flush_deferred_.load(); };
  // The condition variable sleeps on the steady clock; `next` is on clock_
  // (an offset or a test's clock): wait for the same distance from now.
  // Saturating: `t` may be TimePoint::min() (an item due at once) or
  // TimePoint::max() (idle), and neither may overflow (UBSan).
  const auto steady_deadline = [this](TimePoint t) {
    using Steady = std::chrono::steady_clock;
    const Steady::time_point steady_now = Steady::now();
    const Duration distance = SaturatingSub(t, clock_.Now());
    if (distance <= Duration(0)) return steady_now;
    if (distance >= Steady::time_point::max() - steady_now) return Steady::time_point::max();
    return steady_now + distance;
  };
  if (next <= clock_.Now()) return;  // already due (an item "at once" has TimePoint::min())
  if (!precise_ || !spin_ || options_.final_spin.count() <= 0 || next == TimePoint::max()) {
    wake_.wait_until(lock, steady_deadline(next), woken);
    return;
  }
  // The spin's budget: spin_share of a core, at most 20 spins saved up.
  const auto refill = [this] {
    const auto t = std::chrono::steady_clock::now();
    const auto earned = std::chrono::duration_cast<Duration>(t - budget_time_) * options_.spin_share;
    spin_budget_ = std::min<Duration>(20 * options_.final_spin,
                                      spin_budget_ + std::chrono::duration_cast<Duration>(earned));
    budget_time_ = t;
    return t;
  };
  refill();
  if (spin_budget_ < options_.final_spin) {  // dense deadlines: the spin would cost too much
    wake_.wait_until(lock, steady_deadline(next), woken);
    return;
  }
  if (wake_.wait_until(lock, steady_deadline(next - options_.final_spin), woken)) return;
  lock.unlock();
  // Bounded in real time too (a test's ManualClock does not move by itself).
  const auto start = refill();
  const auto bound = start + 2 * options_.final_spin;
  while (clock_.Now() < next && std::chrono::steady_clock::now() < bound) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  spin_budget_ -= std::chrono::duration_cast<Duration>(std::chrono::steady_clock::now() - start);
  lock.lock();
}

void RobotDaemon::ApplyTiming() {
  std::string what = "default timer slack, no final spin, SCHED_OTHER (precise_timing off)";
  if (options_.precise_timing) {
    precise_ = true;
    const bool slack = prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL) == 0;
    sched_param param{};
    param.sched_priority = options_.fifo_priority;
    const bool fifo = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
    char buf[200];
    std::snprintf(buf, sizeof buf, "%s, final spin %lld us, %s",
                  slack ? "1 ns timer slack" : "default timer slack",
                  static_cast<long long>(
                      std::chrono::duration_cast<std::chrono::microseconds>(options_.final_spin).count()),
                  fifo ? ("SCHED_FIFO priority " + std::to_string(param.sched_priority)).c_str()
                       : "SCHED_OTHER (SCHED_FIFO not permitted)");
    what = buf;
  }
  std::lock_guard lock(mutex_);
  timing_ = what;
  outbox_.log.push_back("robot '" + robot_name_ + "': RobotDaemon timing: " + what);
}

std::string RobotDaemon::timing() const {
  std::lock_guard lock(mutex_);
  return timing_;
}

void RobotDaemon::AnswerFrom(const RobotState& state, Kinematics& kinematics,
                             std::vector<Eigen::Isometry3d>& roots, const QueuedItem& item,
                             Reply& reply) const {
  const RobotModel& m = model();
  auto& v = reply.values;
  try {
    switch (item.query) {
      case QueryType::kJointState: {
        int first = 0, count = m.num_dofs();
        if (item.query_target >= 0) {
          first = m.dof_offset(item.query_target);
          count = static_cast<int>(m.joint(item.query_target).dofs.size());
        }
        v.reserve(3 * static_cast<std::size_t>(count));
        for (const Eigen::VectorXd* vec : {&state.position, &state.velocity, &state.effort}) {
          v.insert(v.end(), vec->data() + first, vec->data() + first + count);
        }
        break;
      }
      case QueryType::kLinkPoses:
      case QueryType::kFramePoses: {
        for (std::size_t i = 0; i < roots.size(); ++i) roots[i] = state.root_poses[i].ToIsometry();
        kinematics.Update(state.position, roots);
        const bool links = item.query == QueryType::kLinkPoses;
        const int n = static_cast<int>(links ? m.links().size() : m.frames().size());
        for (int i = 0; i < n; ++i) {
          if (item.query_target >= 0 && i != item.query_target) continue;
          v.resize(v.size() + 7);
          WritePose(links ? kinematics.link_pose(i) : kinematics.frame_pose(i), v.data() + v.size() - 7);
        }
        break;
      }
      case QueryType::kBasePose: {
        const Eigen::Isometry3d base = state.root_poses.front().ToIsometry();
        v = {base.translation().x(), base.translation().y(), Yaw(base), state.base_v, state.base_omega};
        break;
      }
      default:
        reply.signal = Signal::kError;
        reply.message = std::string(ToString(item.query)) + " is answered on receipt, not queued";
        return;
    }
    reply.signal = Signal::kSuccess;
  } catch (const std::exception& e) {  // a non-finite state from the driver
    reply.signal = Signal::kError;
    reply.message = std::string(ToString(item.query)) + ": " + e.what();
    v.clear();
  }
}

void RobotDaemon::FillSample(TimePoint now, Duration period) {
  RobotSample& s = sample_;
  s.time = now;
  s.period = period;
  s.sample = ++samples_;
  s.panic = panic_.load();
  s.moving = state_.moving;
  s.position = state_.position;  // same sizes: copies, no allocation
  s.velocity = state_.velocity;
  s.effort = state_.effort;
  const Eigen::Isometry3d base = state_.root_poses.front().ToIsometry();
  s.base = {base.translation().x(), base.translation().y(), Yaw(base), state_.base_v, state_.base_omega};
  s.frames_valid = true;
  if (!s.frame_poses.empty()) {
    try {
      for (std::size_t i = 0; i < roots_.size(); ++i) roots_[i] = state_.root_poses[i].ToIsometry();
      kinematics_.Update(state_.position, roots_);
      for (std::size_t f = 0; f < s.frame_poses.size() / 7; ++f) {
        WritePose(kinematics_.frame_pose(static_cast<int>(f)), s.frame_poses.data() + 7 * f);
      }
    } catch (const std::exception&) {
      s.frames_valid = false;  // a driver reporting a non-finite state: send the rest
    }
  }
}

}  // namespace robotalk
