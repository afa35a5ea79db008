// RobotSessions' link health (issue 23, link_health.h): each session's
// figures in SERVER_COUNTERS and on the state stream, the warnings when a
// link degrades, and the opt-in --link-stop policy.
#include "robot_sessions.h"
#include "robot_sessions_text.h"

namespace robotalk {

using namespace sessions_text;

namespace {
// A level's warning is not repeated sooner than this while it lasts (the
// server log's own limiter also applies).
constexpr Duration kLinkLogEvery = std::chrono::seconds(10);
}  // namespace

void RobotSessions::AppendLinkCounters(const Session& s, Reply& r) const {
  const LinkFigures f = s.link.Figures();
  const auto add = [&r](const char* name, double value) {
    r.message += (r.message.empty() ? "" : " ") + std::string(name);
    r.values.push_back(value);
  };
  // The asking session's own link, as the server measured it.
  add("link_level", static_cast<double>(s.link.Evaluate().level));
  add("link_round_trip_s", f.round_trip ? ToSeconds(*f.round_trip) : 0.0);
  add("link_delay_s", f.delay() ? ToSeconds(*f.delay()) : 0.0);
  add("link_jitter_s", ToSeconds(f.jitter));
  add("link_loss", f.loss);
  add("link_recent_loss", f.recent_loss);
  add("link_packages", static_cast<double>(f.packages));
  add("link_expected", static_cast<double>(f.expected));
  add("link_lost", static_cast<double>(f.lost));
  add("link_retransmitted", static_cast<double>(f.retransmitted));
  add("link_duplicates", static_cast<double>(f.duplicates));
  add("link_reordered", static_cast<double>(f.reordered));
  add("link_replies", static_cast<double>(f.replies));
  add("link_late", static_cast<double>(f.late));
  add("link_expired", static_cast<double>(f.expired));
}

std::optional<LinkFigures> RobotSessions::link(std::int64_t client_id) const {
  const Session* s = table_.Find(robot_id_, client_id);
  if (s == nullptr) return std::nullopt;
  return s->link.Figures();
}

LinkState RobotSessions::MotionLink() const {
  LinkState out;
  if (motion_owner_ == 0) return out;
  const Session* s = table_.Find(robot_id_, motion_owner_);
  if (s == nullptr) return out;
  const LinkFigures f = s->link.Figures();
  out.client_id = motion_owner_;
  out.level = s->link.Evaluate().level;
  out.round_trip = f.round_trip.value_or(Duration(0));
  out.jitter = f.jitter;
  out.loss = f.recent_loss;
  out.late = static_cast<std::int64_t>(f.late);
  out.expired = static_cast<std::int64_t>(f.expired);
  return out;
}

void RobotSessions::CheckLinks(TimePoint now) {
  std::vector<std::pair<std::int64_t, std::string>> to_stop;
  for (const auto& [id, session] : table_.live(robot_id_)) {
    Session& s = *session;
    if (!s.active) continue;
    s.link.Tick(now);
    const LinkHealth::Verdict v = s.link.Evaluate();
    const bool worse = v.level > s.link_logged && v.level >= LinkHealth::Level::kDegraded;
    const bool again = v.level >= LinkHealth::Level::kDegraded && now - s.link_logged_at >= kLinkLogEvery;
    if (worse || again) {
      log_.push_back("robot '" + robot_ + "': " + s.who + "'s link is " + ToString(v.level) + ": " + v.why);
      s.link_logged_at = now;
      s.link_logged = v.level;
    } else if (v.level == LinkHealth::Level::kGood && s.link_logged >= LinkHealth::Level::kDegraded) {
      log_.push_back("robot '" + robot_ + "': " + s.who + "'s link is good again");
      s.link_logged = v.level;
      s.link_stopped = false;
    }
    // The policy acts once per bad spell: the client may move the robot
    // again (each new bad spell stops it again once the link was good).
    if (options_.link_stop && v.level == LinkHealth::Level::kBad && !s.link_stopped) {
      s.link_stopped = true;
      to_stop.emplace_back(s.client_id, s.who + "'s link is bad (" + v.why + "; --link-stop)");
    }
  }
  for (auto& [client, why] : to_stop) {
    flushed_.clear();
    daemon_.FlushClient(client, flushed_);
    // Its playback sequences are queued commands too: the frames buffered
    // for a start not yet decided are dropped with the rest, and a sequence
    // does not go on without the frames it had (review 10: they ran after
    // the stop once the sequence started).
    if (Session* s = table_.Find(robot_id_, client))
      EndPlaybacks(*s, Session::Ended::kLinkStop, "--link-stop", now);
    for (const QueuedItem& item : flushed_) {
      Deliver(client, MakeReply(item.command.id, Signal::kInterrupted, "not executed: " + why, now));
    }
    StopOwned(client, why);
  }
}

bool RobotSessions::StopOwned(std::int64_t client, const std::string& why) {
  // A STOP of only what it owns (Driver::StopOnly cannot refuse: its GOTO
  // is interrupted); another client's motion runs on.
  std::vector<int> joints;
  for (std::size_t j = 0; j < joint_owner_.size(); ++j) {
    if (joint_owner_[j] != client) continue;
    joints.push_back(static_cast<int>(j));
    joint_owner_[j] = 0;
  }
  const bool base = base_owner_ == client;
  if (base) base_owner_ = 0;
  const bool owned = base || !joints.empty();
  if (owned) {
    log_.push_back("robot '" + robot_ + "': " + why + "; stopping what it moved (" +
                   (base ? std::string("the base") : std::string()) + (base && !joints.empty() ? ", " : "") +
                   (joints.empty() ? std::string() : std::to_string(joints.size()) + " joint(s)") + ")");
    daemon_.QueueStopOnly(std::move(joints), base);
  }
  return owned;
}

}  // namespace robotalk
