// The RobotDaemon's base speed ramp (issue 22, item 2): the timed SETSPEED
// frames of an interpolated package (linear, cubic or quintic;
// QueuedItem::is_speed_frame()) joined into one piecewise-linear plan of the
// base's body twist (vx, vy, ω), sampled every control period into the
// reference the driver follows (Driver::TrackBase). A pure class: no
// threads, no clock, no driver calls; the RobotDaemon feeds it arrivals and
// times.
//
// The rules (docs/protocol.md, "Base speed ramps"):
// - A frame is a knot of the plan: the base's twist is the frame's at the
//   frame's time, and linear between consecutive frames (whatever the
//   package's interpolation: a twist is a velocity, and linear is what keeps
//   its rate -- the base's acceleration -- bounded by the frames' own
//   differences). A frame is taken when it arrives; an idle ramp starts then
//   from the base's measured twist, reaching the first frame at its time.
// - The limit: the reference follows the plan exactly while the plan's
//   acceleration is within the base's limit (linear: of the planar speed
//   (vx, vy), m/s²; angular: of ω, rad/s²) and the reference is on it;
//   otherwise it approaches the plan at the limit. A frame the reference did
//   not follow on the way to answers MODIFIED naming the limit, the plan's
//   acceleration and how far the reference was from the frame at its time.
//   So no twist change larger than one period's worth of the limit reaches
//   a driver.
// - After the last frame the base keeps its twist, as after a SETSPEED; the
//   ramp ends once the reference is there. A SETSPEED 0 last brings the base
//   to rest within the limit.
// - A frame at or before a planned one replaces the plan from its time on
//   (a splice, continuous: the reference never jumps); the replaced frames
//   answer INTERRUPTED "superseded by command N", whichever client sent it
//   (last commanded wins).
// - A frame that arrives after its time: INTERRUPTED past its deadline
//   (max_late; and when no later frame is planned the base comes to rest
//   within the limit, as an expired step SETSPEED stops the base); else
//   INTERRUPTED when a later frame is planned, or joined one control period
//   from now (MODIFIED).
// - End() (STOP, panic, the watchdog, a GOTO or a step SETSPEED, a driver's
//   refusal) answers every frame not yet passed INTERRUPTED; what the base
//   does then is the caller's (the driver's Stop() brakes, as before).
//
// Allocation: Sample() allocates only for answers with a message; Add() may.
#pragma once

#include "command_queue.h"
#include "planner_answers.h"
#include "robotalk/command.h"
#include "robotalk/driver.h"

#include <cstdint>
#include <deque>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

/// The default base acceleration limit: a Clearpath Husky's, as its
/// diff_drive_controller ships it (husky_control/config/control.yaml:
/// linear x 3.0 m/s², angular z 6.0 rad/s²); docs/server.md says why.
inline constexpr double kDefaultBaseLinearAcceleration = 3.0;   // m/s²
inline constexpr double kDefaultBaseAngularAcceleration = 6.0;  // rad/s²

struct SpeedRampOptions {
  double linear_acceleration = kDefaultBaseLinearAcceleration;    ///< m/s², of (vx, vy); > 0
  double angular_acceleration = kDefaultBaseAngularAcceleration;  ///< rad/s², of ω; > 0
  /// The driver's control period: a late frame is joined this far ahead.
  Duration period = std::chrono::milliseconds(10);
  /// False for a robot whose first root is fixed: every frame answers NA.
  bool mobile = true;
  std::string robot;  ///< the robot's name, for that answer
};

class SpeedRamp {
 public:
  /// The most heap one held SETSPEED frame costs, for the server's memory
  /// bound (QueuedItemBytes). Measured 100 B (HeldWaypointMemory).
  static constexpr std::size_t kHeldFrameBytes = 128;

  struct Answer {
    std::int64_t client_id = 0;
    Reply reply;
  };

  explicit SpeedRamp(SpeedRampOptions options);

  /// Adds the SETSPEED frames that arrived (QueuedItem::is_speed_frame(), in
  /// arrival order) at `now`; `current` is the base's measured twist (where
  /// an idle ramp starts). Refused, replaced and late frames are answered in
  /// `answers`. Returns the client that this made the base's owner (the
  /// ramp started, or another client's frame took it over), else 0.
  std::int64_t Add(std::span<const QueuedItem> frames, TimePoint now, const BaseReference& current,
                   std::vector<Answer>& answers);

  /// Samples the ramp at `now` into reference(); answers the frames passed
  /// by `now`. Returns false when the ramp was not active (no reference to
  /// hand over). The ramp ends once its last frame is passed and the
  /// reference has reached it (that last reference is still returned).
  bool Sample(TimePoint now, std::vector<Answer>& answers);
  /// The reference of the last Sample().
  const BaseReference& reference() const { return ref_; }

  /// The driver answered the last reference MODIFIED with `message`: the
  /// frame being approached answers MODIFIED with it too.
  void NoteDriver(std::string_view message);
  /// Ends the ramp: every frame not yet passed answers INTERRUPTED
  /// "SETSPEED: " + why. No-op when idle.
  void End(TimePoint now, const std::string& why, std::vector<Answer>& answers);

  bool active() const { return active_; }
  /// Frames waiting to be passed.
  std::size_t pending() const { return pending_.size(); }
  /// Adds each client's frames waiting to be passed to `counts`.
  void CountPending(planner_answers::HeldCounts& counts) const {
    for (const Frame& f : pending_) planner_answers::CountHeld(counts, f.client_id);
  }

 private:
  struct Twist {
    double vx = 0, vy = 0, omega = 0;
  };
  struct Knot {
    TimePoint time{};
    Twist twist;
  };
  struct Frame {  // a frame not yet passed
    std::int64_t client_id = 0;
    CommandId id = 0;
    TimePoint requested{};  // the time the client asked for
    Knot knot;              // at its (joined) time
    bool lateral = false;   // it gave vy (3 values)
    std::string note;       // why it is MODIFIED, or ""
  };

  void AddFrame(const QueuedItem& item, TimePoint now, const BaseReference& current,
                std::vector<Answer>& answers, std::int64_t& owner);
  struct Segment {  // the plan's segment at a time: linear from `from` to `to` (none: holds `from`)
    const Knot* from;
    const Knot* to;
  };
  Segment SegmentAt(TimePoint t) const;
  // The plan's twist at `t` (>= from_.time).
  Twist Plan(TimePoint t) const;
  // Moves the reference toward the plan at `now`, at most at the limits.
  void Approach(TimePoint now);
  void AnswerPassed(TimePoint now, std::vector<Answer>& answers);
  void Start(TimePoint now, const BaseReference& current);

  SpeedRampOptions options_;
  bool active_ = false;
  std::int64_t owner_ = 0;
  Knot from_;  // the last knot passed (or the start): the plan is linear from it to pending_.front()
  std::deque<Frame> pending_;
  BaseReference ref_;
  TimePoint last_sample_{};
  std::string limited_;        // the first limit the reference met since the last frame passed
  TimePoint limited_until_{};  // ... on the way to the frame at this time
  std::string driver_note_;    // the driver's MODIFIED text since the last frame passed
};

}  // namespace robotalk
