#include "query_snapshot.h"

#include <cmath>
#include <string>

namespace robotalk {

void WritePose7(const Eigen::Isometry3d& x, double* out) {
  const Eigen::Quaterniond q(x.linear());
  out[0] = x.translation().x();
  out[1] = x.translation().y();
  out[2] = x.translation().z();
  out[3] = q.w();
  out[4] = q.x();
  out[5] = q.y();
  out[6] = q.z();
}

double PlanarYaw(const Eigen::Isometry3d& x) { return std::atan2(x.linear()(1, 0), x.linear()(0, 0)); }

void AnswerQueryFrom(const RobotModel& m, const RobotState& state, Kinematics& kinematics,
                     std::vector<Eigen::Isometry3d>& roots, const QueuedItem& item, Reply& reply) {
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
          WritePose7(links ? kinematics.link_pose(i) : kinematics.frame_pose(i), v.data() + v.size() - 7);
        }
        break;
      }
      case QueryType::kBasePose: {
        const Eigen::Isometry3d base = state.root_poses.front().ToIsometry();
        v = {base.translation().x(), base.translation().y(), PlanarYaw(base), state.base_v, state.base_omega};
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

QuerySnapshot::QuerySnapshot(const RobotModel& model, const RobotState& initial, const Clock& clock,
                             const PanicState& panic)
    : model_(model), clock_(clock), panic_(panic), kinematics_(std::make_unique<Kinematics>(model)) {
  published_.state = initial;
  read_ = published_;
  for (const RootLink& r : model.roots()) roots_.push_back(r.pose_in_world.ToIsometry());
}

void QuerySnapshot::Publish(const RobotState* state, TimePoint time, Duration max_age,
                            std::uint64_t items_taken, TimePoint next_due, bool halted) {
  std::lock_guard lock(mutex_);
  published_.valid = state != nullptr;
  if (!state) return;
  published_.state = *state;  // same sizes: no allocation
  published_.halted = halted;
  published_.time = time;
  published_.max_age = max_age;
  published_.items_taken = items_taken;
  published_.next_due = next_due;
}

bool QuerySnapshot::Answer(const QueuedItem& item, Reply& reply) {
  const TimePoint now = clock_.Now();
  if (item.has_start_time && item.start > now) return false;
  wanted_until_ = (now + std::chrono::seconds(1)).time_since_epoch().count();
  const bool halted_as_asked = panic_.in_panic();
  // A fault, an overrun or the latch: the queued answer names the reason.
  const bool named_panic = panic_.faulted() || panic_.has_reason();
  {
    std::lock_guard lock(mutex_);
    const Copy& p = published_;
    if (!p.valid || p.items_taken < last_due_push_ || now >= p.next_due || p.halted != halted_as_asked ||
        named_panic || now - p.time > p.max_age) {
      return false;
    }
    read_ = p;  // same sizes: no allocation
  }
  reply.id = item.command.id;
  reply.exec_time = now;
  AnswerQueryFrom(model_, read_.state, *kinematics_, roots_, item, reply);
  ++answered_;
  return true;
}

}  // namespace robotalk
