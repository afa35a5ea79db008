#include "speed_ramp.h"

#include "expiry.h"
#include "planner_answers.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

namespace robotalk {
namespace {

using planner_answers::Append;
using planner_answers::MakeAnswer;
using planner_answers::Seconds;

std::string Number(double x) {  // 3 significant digits: "5", "0.4", "1.4"
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

// Slack on the limit: a plan exactly at the limit is followed, not flagged.
constexpr double kSlack = 1e-9;

}  // namespace

SpeedRamp::SpeedRamp(SpeedRampOptions options) : options_(std::move(options)) {}

std::int64_t SpeedRamp::Add(std::span<const QueuedItem> frames, TimePoint now, const BaseReference& current,
                            std::vector<Answer>& answers) {
  std::int64_t owner = 0;
  for (const QueuedItem& item : frames) AddFrame(item, now, current, answers, owner);
  return owner;
}

void SpeedRamp::Start(TimePoint now, const BaseReference& current) {
  ref_ = BaseReference{.vx = current.vx, .vy = current.vy, .omega = current.omega};
  from_ = Knot{now, Twist{current.vx, current.vy, current.omega}};
  last_sample_ = now;
  limited_.clear();
  driver_note_.clear();
  owner_ = 0;
  active_ = true;
}

void SpeedRamp::AddFrame(const QueuedItem& item, TimePoint now, const BaseReference& current,
                         std::vector<Answer>& answers, std::int64_t& owner) {
  const DriverCommand& c = item.command;
  if (!options_.mobile) {  // as a step SETSPEED is answered by the drivers
    answers.push_back({item.client_id, MakeAnswer(c.id, Signal::kNa,
                                                  "SETSPEED: robot '" + options_.robot + "' has a fixed base",
                                                  now, Duration(0))});
    return;
  }
  Frame f;
  f.client_id = item.client_id;
  f.id = c.id;
  f.requested = item.start;
  f.lateral = c.num_values == 3;
  f.knot = Knot{item.start, Twist{c.values[0], f.lateral ? c.values[1] : 0.0, c.values[c.num_values - 1]}};
  if (item.start <= now) {  // late
    const Duration late = now - item.start;
    const bool later_planned = active_ && !pending_.empty() && pending_.back().knot.time > now;
    if (std::optional<std::string> expired = ExpiryRefusal(late, item.max_late, item.received - item.start)) {
      answers.push_back(
          {item.client_id, MakeAnswer(c.id, Signal::kInterrupted, *expired + " (SETSPEED)", now, late)});
      // The change it asked for did not happen at its time: the base does not
      // run on at the old twist (as an expired step SETSPEED stops it), it
      // comes to rest within the limit.
      if (!later_planned) {
        if (!active_) Start(now, current);
        AnswerPassed(now, answers);
        from_ = Knot{now, Twist{}};
        limited_.clear();
      }
      return;
    }
    if (later_planned) {
      answers.push_back(
          {item.client_id, MakeAnswer(c.id, Signal::kInterrupted,
                                      "SETSPEED: arrived " + Seconds(late) +
                                          " after its time; a later frame is already planned; not executed",
                                      now, late)});
      return;
    }
    f.note = "arrived " + Seconds(late) + " after its time: joined " + Seconds(options_.period) +
             " from its arrival";
    f.knot.time = now + options_.period;
  }
  const bool starting = !active_;
  if (starting) Start(now, current);
  // Frames at or after the new one's time are replaced (a splice: the plan
  // stays linear from the knot before it, or from where it is now).
  const Twist at_now = Plan(now);
  while (!pending_.empty() && pending_.back().knot.time >= f.knot.time) {
    Frame& old = pending_.back();
    answers.push_back({old.client_id, MakeAnswer(old.id, Signal::kInterrupted,
                                                 "SETSPEED: superseded by command " + std::to_string(c.id),
                                                 now, Duration(0))});
    pending_.pop_back();
  }
  if (pending_.empty() && from_.time < now) from_ = Knot{now, at_now};  // the next segment starts now
  if (f.lateral) ref_.lateral = true;  // the driver gets "vx vy ω" from now on
  if (starting || owner_ != item.client_id) owner = item.client_id;
  owner_ = item.client_id;
  pending_.push_back(std::move(f));
}

SpeedRamp::Segment SpeedRamp::SegmentAt(TimePoint t) const {
  Segment seg{&from_, nullptr};
  for (const Frame& f : pending_) {
    if (t < f.knot.time) {
      seg.to = &f.knot;
      break;
    }
    seg.from = &f.knot;
  }
  return seg;
}

SpeedRamp::Twist SpeedRamp::Plan(TimePoint t) const {
  const Segment seg = SegmentAt(t);
  if (!seg.to || seg.to->time <= seg.from->time) return seg.to ? seg.to->twist : seg.from->twist;
  const double s = ToSeconds(t - seg.from->time) / ToSeconds(seg.to->time - seg.from->time);
  const Twist& a = seg.from->twist;
  const Twist& b = seg.to->twist;
  return {a.vx + s * (b.vx - a.vx), a.vy + s * (b.vy - a.vy), a.omega + s * (b.omega - a.omega)};
}

void SpeedRamp::Approach(TimePoint now) {
  const double dt = ToSeconds(now - last_sample_);
  last_sample_ = now;
  const Twist target = Plan(now);
  const double dvx = target.vx - ref_.vx, dvy = target.vy - ref_.vy, dw = target.omega - ref_.omega;
  const double dv = std::hypot(dvx, dvy);
  const double max_dv = options_.linear_acceleration * dt, max_dw = options_.angular_acceleration * dt;
  const bool clip_v = dv > max_dv * (1 + kSlack) + 1e-12;
  const bool clip_w = std::abs(dw) > max_dw * (1 + kSlack) + 1e-12;
  const double k = clip_v ? max_dv / dv : 1.0;
  ref_.vx = clip_v ? ref_.vx + k * dvx : target.vx;
  ref_.vy = clip_v ? ref_.vy + k * dvy : target.vy;
  ref_.omega = clip_w ? ref_.omega + std::copysign(max_dw, dw) : target.omega;
  if ((clip_v || clip_w) && limited_.empty() && !pending_.empty()) {
    // Name the plan's own acceleration on the segment the reference aims at
    // (the one ending at `now`'s knot, or containing `now`), when that is what exceeds the limit.
    const Segment seg = SegmentAt(now - Duration(1));
    const Knot& a = *seg.from;
    const Knot& to = seg.to ? *seg.to : *seg.from;
    const double span = ToSeconds(to.time - a.time);
    const double a_v =
        span > 0 ? std::hypot(to.twist.vx - a.twist.vx, to.twist.vy - a.twist.vy) / span : HUGE_VAL;
    const double a_w = span > 0 ? std::abs(to.twist.omega - a.twist.omega) / span : HUGE_VAL;
    // The frame it concerns: the one ending that segment (a frame passed
    // earlier in this same period was met; the next one was not).
    limited_until_ = to.time;
    if (clip_v) {
      limited_ = a_v > options_.linear_acceleration * (1 + kSlack)
                     ? "the plan's linear acceleration " + Number(a_v) + " m/s² exceeds the base's limit " +
                           Number(options_.linear_acceleration) + " m/s²"
                     : "catching up with the plan at the base's linear limit " +
                           Number(options_.linear_acceleration) + " m/s²";
    } else {
      limited_ = a_w > options_.angular_acceleration * (1 + kSlack)
                     ? "the plan's angular acceleration " + Number(a_w) +
                           " rad/s² exceeds the base's limit " + Number(options_.angular_acceleration) +
                           " rad/s²"
                     : "catching up with the plan at the base's angular limit " +
                           Number(options_.angular_acceleration) + " rad/s²";
    }
  }
  // The rate toward the plan one period on, within the limits (feed-forward).
  const double p = ToSeconds(options_.period);
  const Twist next = Plan(now + options_.period);
  double ax = (next.vx - ref_.vx) / p, ay = (next.vy - ref_.vy) / p, alpha = (next.omega - ref_.omega) / p;
  const double a = std::hypot(ax, ay);
  if (a > options_.linear_acceleration) {
    ax *= options_.linear_acceleration / a;
    ay *= options_.linear_acceleration / a;
  }
  alpha = std::clamp(alpha, -options_.angular_acceleration, options_.angular_acceleration);
  ref_.ax = ax;
  ref_.ay = ay;
  ref_.alpha = alpha;
}

void SpeedRamp::AnswerPassed(TimePoint now, std::vector<Answer>& answers) {
  while (!pending_.empty() && pending_.front().knot.time <= now) {
    Frame& f = pending_.front();
    const Duration late = f.knot.time > f.requested ? f.knot.time - f.requested : Duration(0);
    if (!limited_.empty() && limited_until_ <= f.knot.time) {
      f.note = Append(f.note, "ramp limited: " + limited_);
      const double gap_v = std::hypot(ref_.vx - f.knot.twist.vx, ref_.vy - f.knot.twist.vy);
      const double gap_w = std::abs(ref_.omega - f.knot.twist.omega);
      std::string gap;
      if (gap_v > 1e-9) gap = Number(gap_v) + " m/s";
      if (gap_w > 1e-9) gap += (gap.empty() ? "" : " and ") + Number(gap_w) + " rad/s";
      if (!gap.empty()) f.note += "; the reference was " + gap + " from it at its time";
      limited_.clear();
    }
    if (!driver_note_.empty()) {
      f.note = Append(f.note, driver_note_);
      driver_note_.clear();
    }
    const Signal signal = f.note.empty() ? Signal::kSuccess : Signal::kModified;
    answers.push_back(
        {f.client_id, MakeAnswer(f.id, signal, f.note.empty() ? std::string() : "SETSPEED: " + f.note,
                                 f.knot.time, late)});
    from_ = f.knot;
    pending_.pop_front();
  }
}

bool SpeedRamp::Sample(TimePoint now, std::vector<Answer>& answers) {
  if (!active_) return false;
  if (now > last_sample_) Approach(now);  // toward the plan at `now` (past the knots passed since)
  AnswerPassed(now, answers);
  if (pending_.empty() && ref_.vx == from_.twist.vx && ref_.vy == from_.twist.vy &&
      ref_.omega == from_.twist.omega) {
    active_ = false;  // there: the base keeps this twist, as after a SETSPEED
    ref_.ax = ref_.ay = ref_.alpha = 0;
  }
  return true;
}

void SpeedRamp::NoteDriver(std::string_view message) {
  constexpr std::string_view kPrefix = "SETSPEED: ";  // the frame's answer says it once
  if (message.substr(0, kPrefix.size()) == kPrefix) message.remove_prefix(kPrefix.size());
  if (message.empty() || pending_.empty() || driver_note_ == message) return;
  driver_note_.assign(message);
}

void SpeedRamp::End(TimePoint now, const std::string& why, std::vector<Answer>& answers) {
  if (!active_) return;
  for (Frame& f : pending_) {
    answers.push_back(
        {f.client_id, MakeAnswer(f.id, Signal::kInterrupted, "SETSPEED: " + why, now, Duration(0))});
  }
  pending_.clear();
  limited_.clear();
  driver_note_.clear();
  active_ = false;
  owner_ = 0;
  ref_.ax = ref_.ay = ref_.alpha = 0;
}

}  // namespace robotalk
