// RobotSessions' playback mode (paper §V-C): a sequence's frames wait in the
// session's playback queue until its delay is estimated, then move to the
// RobotDaemon's command queue; a finished sequence is freed.
#include "robot_sessions.h"
#include "robot_sessions_text.h"

#include <algorithm>
#include <cmath>

namespace robotalk {

using namespace sessions_text;

void RobotSessions::AdmitPlayback(Session& s, const Request& r, TimePoint now, TimePoint arrived,
                                  std::vector<Reply>& immediate) {
  const PlaybackDeclaration& d = r.playback;
  const std::string label = "PLAYBACK " + std::to_string(d.id);
  const auto refuse = [&](const std::string& why, bool delay_reply) {
    for (const Command& c : r.commands) immediate.push_back(MakeReply(c.id, Signal::kError, why, now));
    // A sequence that never starts: its delay reply is this refusal too.
    if (delay_reply) immediate.push_back(MakeReply(d.id, Signal::kError, why, now));
  };
  if (const std::optional<Session::Ended> ended = s.PlaybackEnded(d.id)) {
    // Late frames of a sequence that ended: answered, never a new sequence
    // that would wait forever for the frames it had before.
    if (*ended == Session::Ended::kComplete) {
      refuse(label + ": all its declared frames were received already; this frame is beyond them", false);
      return;
    }
    const char* by = *ended == Session::Ended::kPanic ? "a panic" : "--link-stop (its client's link was bad)";
    for (const Command& c : r.commands) {
      immediate.push_back(MakeReply(c.id, Signal::kInterrupted,
                                    label + " was ended by " + by + "; its later frames do not run", now));
    }
    return;
  }
  if (daemon_.in_panic()) {
    for (const Command& c : r.commands)
      Admit(s, c, now, immediate, /*playback=*/true, r.max_late);  // PANIC each
    if (!s.playbacks.count(d.id) || !s.playbacks.at(d.id).start) {
      immediate.push_back(
          MakeReply(d.id, Signal::kPanic, label + ": the robot is in panic; it does not start", now));
    }
    s.EndPlayback(d.id, Session::Ended::kPanic);
    return;
  }
  if (!s.playbacks.count(d.id)) {
    if (d.frames > static_cast<std::int64_t>(options_.max_queue)) {
      refuse(label + ": declares " + std::to_string(d.frames) + " frames; the queue limit is " +
                 std::to_string(options_.max_queue),
             true);
      return;
    }
    if (s.playbacks.size() >= options_.max_playbacks) {
      refuse(Client(s.client_id) + " has " + std::to_string(s.playbacks.size()) +
                 " playback sequences unfinished on robot '" + robot_ + "'; the limit is " +
                 std::to_string(options_.max_playbacks) + "; " + label + " does not start",
             true);
      return;
    }
  }
  auto [it, created] =
      s.playbacks.try_emplace(d.id, static_cast<std::size_t>(d.frames), d.duration, options_.playback);
  PlaybackSequence& seq = it->second;
  if (!created && (seq.total != static_cast<std::size_t>(d.frames) || seq.duration != d.duration)) {
    refuse(label + ": declared " + std::to_string(seq.total) + " frames over " + Seconds(seq.duration) +
               " before, now " + std::to_string(d.frames) + " over " + Seconds(d.duration),
           false);
    return;
  }
  if (created) seq.interpolation = r.interpolation;
  if (seq.interpolation != r.interpolation) {
    refuse(label + ": its packages are " + InterpolationName(seq.interpolation) + ", this one says " +
               InterpolationName(r.interpolation) +
               "; every package of a sequence has the same interpolation",
           false);
    return;
  }
  if (!seq.first_arrival) {
    seq.first_arrival = now;
    // This package's delay is not in it yet (Handle records it after its
    // items): frame 0 counts once, as a frame.
    seq.estimator->SetDelayHistory(s.delays.RecentSamples(now));
  }
  const std::optional<TimePoint> sent =
      r.send_time != TimePoint{} ? std::optional<TimePoint>(r.send_time) : std::nullopt;
  const std::optional<Duration> delay = sent ? OneWayDelay(*sent, now) : std::nullopt;
  for (const Command& c : r.commands) {
    std::optional<QueuedItem> item =
        Admit(s, c, now, immediate, /*playback=*/true, r.max_late, r.interpolation);
    if (!item) {  // answered: one frame fewer to wait for
      ++seq.received;
      continue;
    }
    const Duration offset = c.start_time.offset().value_or(Duration(0));
    if (offset > seq.duration || ++seq.received > seq.total) {
      immediate.push_back(MakeReply(c.id, Signal::kError,
                                    label + ": frame at " + Seconds(offset) + " is beyond the declared " +
                                        std::to_string(seq.total) + " frames over " + Seconds(seq.duration),
                                    now));
      continue;
    }
    item->has_start_time = true;
    if (seq.start) {  // already playing: straight to the RobotDaemon
      item->start = seq.schedule->Place(offset, now, delay).at;
      if (!Superseded(s, *item, now, immediate)) daemon_.Submit(std::move(*item));
    } else if (seq.decide_by) {
      // Waiting for frame 0's second copy: decided from frame 0 (as without
      // the wait); this frame is placed when it starts.
      seq.frames.push_back({offset, std::move(*item), now, delay});
    } else {
      seq.estimator->Add(offset, now, sent, arrived < now ? now - arrived : Duration(0));
      seq.frames.push_back({offset, std::move(*item), now, delay});
    }
  }
  if (!seq.start && !seq.decide_by && seq.estimator->ready()) {
    if (WaitForFrameCopy(seq, now)) {
      seq.decide_by = seq.estimator->StartTime() - options_.playback.copies_hold;
      copy_waits_.push_back({s.client_id, d.id, *seq.decide_by});
    } else {
      Start(s, d.id, seq, now, immediate);
    }
  }
  // Every declared frame is in the command queue: nothing of it is left here.
  if (seq.start && seq.received >= seq.total) s.EndPlayback(d.id, Session::Ended::kComplete);
}

// Frames that come twice ("Frames that come twice" in playback_estimator.h):
// an adaptive start decided at frame 0 from send times waits for frame 0's
// second copy until copies_hold before the start it would take without one,
// so a client that sends once starts as before, and one that sends twice
// starts no later. The wait changes neither the start's inputs (later frames
// are buffered, not added) nor, without a copy, the start.
bool RobotSessions::WaitForFrameCopy(const PlaybackSequence& seq, TimePoint now) const {
  const PlaybackEstimator& e = *seq.estimator;
  if (!options_.playback.copies_start || e.frames_seen() != 1 || e.frames_copied() || !e.adaptive() ||
      e.followed() || e.queued())
    return false;
  return e.StartTime() - options_.playback.copies_hold > now;
}

void RobotSessions::OnPlaybackCopy(Session& s, const Request& r, TimePoint now, std::vector<Reply>& replies) {
  if (r.mode != RequestMode::kPlayback || r.send_time == TimePoint{}) return;
  auto it = s.playbacks.find(r.playback.id);
  if (it == s.playbacks.end() || it->second.start || !it->second.decide_by || !it->second.estimator) return;
  PlaybackSequence& seq = it->second;
  // A redundancy copy comes within the delays' spread of the first (a
  // retransmission a timeout later, which the wait, shorter than the spread, does not reach).
  const std::optional<Duration> spread = seq.estimator->delay_spread();
  if (!seq.first_arrival || !spread || now - *seq.first_arrival > *spread) return;
  seq.estimator->AddFrameCopy(r.send_time, now);
  std::vector<Reply> started;
  Start(s, r.playback.id, seq, now, started);
  for (Reply& reply : started) {
    Bound(reply);
    s.replies.RecordReply(reply);
    replies.push_back(std::move(reply));
  }
  if (seq.received >= seq.total) s.EndPlayback(r.playback.id, Session::Ended::kComplete);
}

bool RobotSessions::DecidePlaybacks(TimePoint now) {
  bool any = false;
  for (std::size_t k = 0; k < copy_waits_.size();) {
    const CopyWait w = copy_waits_[k];
    Session* s = table_.Find(robot_id_, w.client_id);
    auto it = s != nullptr ? s->playbacks.find(w.playback_id) : decltype(s->playbacks.end()){};
    const bool live = s != nullptr && it != s->playbacks.end() && !it->second.start && it->second.decide_by &&
                      it->second.estimator;
    if (live && w.until > now) {
      ++k;
      continue;
    }
    copy_waits_.erase(copy_waits_.begin() + static_cast<std::ptrdiff_t>(k));
    if (!live) continue;
    // Decided now: a thread that woke late starts later, never with a frame past its time.
    it->second.estimator->DecideAt(now);
    std::vector<Reply> started;
    Start(*s, w.playback_id, it->second, now, started);
    for (Reply& reply : started) {
      Bound(reply);
      Deliver(w.client_id, std::move(reply));
    }
    if (it->second.received >= it->second.total) s->EndPlayback(w.playback_id, Session::Ended::kComplete);
    any = true;
  }
  return any;
}

std::optional<TimePoint> RobotSessions::NextPlaybackDecision() const {
  std::optional<TimePoint> next;
  for (const CopyWait& w : copy_waits_)
    if (!next || w.until < *next) next = w.until;
  return next;
}

// The delay is estimated: every buffered frame moves to the command queue,
// the client learns when the sequence plays, and the estimator and the
// buffer are freed.
void RobotSessions::Start(Session& s, std::int64_t id, PlaybackSequence& seq, TimePoint now,
                          std::vector<Reply>& immediate) {
  const PlaybackEstimator& estimator = *seq.estimator;
  seq.start = estimator.StartTime();
  seq.decide_by.reset();
  if (options_.log_playback)
    log_.push_back("robot '" + robot_ + "': PLAYBACK " + std::to_string(id) + " start " +
                   estimator.Describe());
  // The adaptive estimator's schedule may stretch the gaps between frames;
  // the quick and the paper's estimators keep every frame at start + its offset.
  const PlaybackScheduleOptions schedule = estimator.schedule_options();
  const double stretch = schedule.max_stretch;
  seq.schedule.emplace(*seq.start, estimator.playout_delay(), schedule);
  // The buffered frames, in offset order (the schedule stretches forward).
  std::stable_sort(seq.frames.begin(), seq.frames.end(),
                   [](const auto& a, const auto& b) { return a.offset < b.offset; });
  for (PlaybackSequence::Frame& frame : seq.frames) {
    frame.item.start = seq.schedule->Place(frame.offset, frame.arrival, frame.delay).at;
    if (!Superseded(s, frame.item, now, immediate)) daemon_.Submit(std::move(frame.item));
  }
  std::vector<PlaybackSequence::Frame>().swap(seq.frames);
  const Duration delay = *seq.start - *seq.first_arrival;
  std::string why;
  if (estimator.followed()) {
    why =
        "adaptive start on a queue: this client's recent one-way delays vary by " +
        Seconds(*estimator.delay_spread()) +
        ", more than a frame interval, on the link (this server kept up); the gaps stretch until the buffer "
        "covers the queue its frames may build (" +
        Seconds(estimator.followed_queue()) + " above the least delay)";
  } else if (estimator.queued()) {
    why = "queue start: this client's recent one-way delays vary by " + Seconds(*estimator.delay_spread()) +
          ", more than a frame interval; covers the queue its frames will build";
  } else if (estimator.adaptive()) {
    why = "adaptive start: this client's recent one-way delays vary by " + Seconds(*estimator.delay_spread());
    if (estimator.burst_discounted()) why += " (less the wait of packages sent together behind each other)";
    if (estimator.start_lead() > Duration(0)) {
      why += "; starts " + Seconds(estimator.start_lead()) +
             " below the worst delay, which the first gap's stretch reaches";
    }
  } else if (estimator.quick()) {
    why = "quick start: this client's packages' one-way delays vary by " + Seconds(*estimator.delay_spread());
  } else {
    why = "mean " + Seconds(estimator.mean_command_interval()) + " between commands, " +
          Seconds(estimator.mean_arrival_interval()) + " between arrivals";
  }
  if (stretch > 0) {
    const auto percent = [](double f) { return std::to_string(static_cast<int>(std::lround(f * 100))); };
    why += "; a gap between frames plays up to " + percent(stretch) + " % longer when the next frame is slow";
    if (schedule.thin_max_stretch > stretch) {
      why += " (up to " + percent(schedule.thin_max_stretch) + " % after a frame that came past that" +
             (schedule.thin_lead > Duration(0) ? " or less than " + Seconds(schedule.thin_lead) + " before it"
                                               : std::string()) +
             ")";
    }
  }
  Reply reply = MakeReply(id, Signal::kSuccess,
                          "playback of " + std::to_string(seq.total) + " frames starts " + Seconds(delay) +
                              " after its first frame arrived (" + why + ")",
                          now);
  reply.values = {ToSeconds(delay), static_cast<double>(ToWireMicros(*seq.start))};
  immediate.push_back(std::move(reply));
  seq.estimator.reset();
}

}  // namespace robotalk
