// RobotSessions' queries: answered at once where the answer is known here
// (CLOCK, STATE_STREAM, COMMAND_STATUS, SERVER_COUNTERS, CONFIG) or from the
// RobotDaemon's last published state, else queued in order with the commands.
#include "robot_sessions.h"
#include "robot_sessions_text.h"
#include "robotalk/channels.h"
#include "robotalk/command_status.h"

namespace robotalk {

using namespace sessions_text;

void RobotSessions::AdmitQuery(Session& s, const Query& q, TimePoint now, std::vector<Reply>& immediate,
                               bool& publish_config) {
  const RobotModel& model = daemon_.model();
  if (auto bad = CheckQuery(model, q)) {
    immediate.push_back(MakeReply(q.id, bad->signal, bad->message, now));
    return;
  }
  switch (q.type) {
    case QueryType::kClock:
      immediate.push_back(MakeReply(q.id, Signal::kSuccess, "", now));
      return;
    case QueryType::kStateStream:
    case QueryType::kStateStreamCancel: {
      const Duration period =
          daemon_.SetStream(s.client_id, q.type == QueryType::kStateStream ? q.period : Duration(0));
      Reply r =
          MakeReply(q.id, Signal::kSuccess,
                    period.count() == 0 ? "no state stream"
                                        : "state every " + Seconds(period) + " on " + StateChannel(robot_),
                    now);
      r.values = {ToSeconds(period)};
      immediate.push_back(std::move(r));
      return;
    }
    case QueryType::kCommandStatus:
      immediate.push_back(CommandStatus(s, q, now));
      return;
    case QueryType::kServerCounters: {
      Reply r = MakeReply(q.id, Signal::kSuccess, "", now);
      if (options_.counters) {
        for (const auto& [name, value] : options_.counters()) {
          r.message += (r.message.empty() ? "" : " ") + std::string(name);
          r.values.push_back(value);
        }
      }
      r.message += (r.message.empty() ? "" : " ") +
                   std::string("refused_packages expired_commands reference_max_acceleration");
      r.values.push_back(static_cast<double>(refused_packages_));
      r.values.push_back(static_cast<double>(expired_commands_));
      r.values.push_back(daemon_.max_reference_acceleration());
      AppendLinkCounters(s, r);
      immediate.push_back(std::move(r));
      return;
    }
    case QueryType::kConfig:
      publish_config = true;
      immediate.push_back(MakeReply(q.id, Signal::kSuccess, Hex64(config_hash_), now));
      return;
    default:
      break;
  }
  if (std::string full = QueueRefusal(s); !full.empty()) {
    immediate.push_back(MakeReply(q.id, Signal::kError, std::move(full) + "; query not queued", now));
    return;
  }
  QueuedItem item;
  item.client_id = s.client_id;
  item.is_query = true;
  item.query = q.type;
  item.command.id = q.id;
  if (!q.target.empty()) {
    switch (q.type) {
      case QueryType::kJointState:
        item.query_target = *model.FindJoint(q.target);
        break;
      case QueryType::kLinkPoses:
        item.query_target = *model.FindLink(q.target);
        break;
      case QueryType::kFramePoses:
        item.query_target = *model.FindFrame(q.target);
        break;
      default:
        break;
    }
  }
  // On receipt, from the state the RobotDaemon published, when that is what
  // the driver would report now (query_snapshot.h); else in order, queued.
  if (Reply reply; daemon_.snapshot().Answer(item, reply)) {
    immediate.push_back(std::move(reply));
    return;
  }
  daemon_.Submit(std::move(item));
}

// What became of a command of this session: its own final reply once it
// ended, BUSY while it waits or runs, NA when this session never got it.
Reply RobotSessions::CommandStatus(const Session& s, const Query& q, TimePoint now) const {
  const std::optional<std::optional<Reply>> known = s.replies.Lookup(q.about);
  if (!known)
    return MakeReply(q.id, Signal::kNa, CommandStatusText(CommandStatusKind::kNotReceived, q.about), now);
  if (!*known)
    return MakeReply(q.id, Signal::kBusy, CommandStatusText(CommandStatusKind::kNotEnded, q.about), now);
  Reply r = **known;
  r.id = q.id;
  return r;
}

}  // namespace robotalk
