// Playback mode's delay estimate (paper §V-C), as pure maths: no I/O, no
// clock of its own. Feed it the arrival time and the sequence offset of each
// frame; once enough frames are in, it says when offset 0 must play so that
// the whole declared sequence plays without running dry.
//
// Model (paper §V-C): T_c is the average time between commands (their
// offsets), T_a the average time between arrivals. If arrivals are slower
// (T_a > T_c) every frame lags further behind its offset, by (T_a/T_c - 1)
// per second of sequence, so the last frame, at offset D, lags about
// D·(T_a/T_c - 1) more than the first. A congested channel makes that growth
// a random walk (a queue's backlog), so the estimator projects the worst lag
// seen so far to D with the drift and the spread of the walk, both at an
// upper confidence bound (ExtraLagBound), adds a margin, and never starts
// before the moment it decides (playback's start latency).
//
// Quick start (issue 11): waiting for 5 frames costs 0.4 s at 10 Hz where the
// channel's jitter is often a millisecond. Every package carries its client
// send time; arrival − send time is the one-way delay plus the (unknown,
// constant) clock offset, so its differences are the delay's variation. A
// frame sent on time (a paced client sends frame i at offset i after frame
// 0, or earlier) is on time at the server if offset 0 plays at the first
// arrival + (its delay's excess over the first frame's). With enough recent
// delays of this client (DelayHistory) and a channel whose delay spread is
// small beside the frame interval (a queue that cannot build up), the start
// is decided at the first frame: the excess over the first frame's delay of
// a predicted worst delay (the least seen + quick_jitter_factor × the
// spread), plus a small margin. Otherwise (no history, a client without
// send times, a congested channel) the paper's estimate above.
//
// Adaptive start (issue 23 item 3, the default): the quick start's 2.5 ×
// spread + 10 ms was most of its start latency where the channel's jitter is
// a few milliseconds. With a schedule that stretches the gaps between frames
// afterwards, within a bound (playback_schedule.h), the start need not cover
// every frame to come. It is decided at the first frame whenever the delays
// are known and spread by at most adaptive_max_spread intervals, to cover the worst recent delay (the
// history's and the frames' max) + spread / n (n delays seen: the max of n samples falls short of the
// channel's by about that) + `adaptive_margin`. The schedule then grows that buffer to the worst delay + 4 ×
// spread / n by stretching the first gaps (at most max_stretch each), and further for any frame slower than
// it. The start itself lies one gap's stretch below that worst delay (start_lead, never before the
// decision + adaptive_margin): frame 0's own delay is unknown against the frames to come (the hindsight
// minimum is the sequence's worst delay less frame 0's), and the first gap's stretch reaches the worst
// delay by frame 1. Where the spread exceeds one frame interval a queue can build that the history (sparse
// packages, no queue) cannot show: the spread beyond one interval is added quick_jitter_factor times. Beyond
// adaptive_max_spread intervals: the paper's estimate, then the stretch. Both thresholds are set for a
// stretch of kGateStretch (10 %: a service of up to 1.1 intervals adds at most one gap's stretch to the
// next frame's delay); a wider max_stretch follows services as much longer and moves both up by
// max_stretch − kGateStretch intervals (Gate()); at kGateStretch and below nothing changes.
// The connect burst (burst_wait_discount, on): a client's hello, clock and
// heartbeat leave together and, on a congested FIFO link, wait behind each
// other, a spread its frames (one interval apart) do not meet. Where the
// delays as measured exceed the gate, or every package seen arrived in the
// order it was sent (a FIFO link; burst_wait_discount_fifo), each package
// sent less than a frame interval after the one before it counts without
// that wait (ChannelDelays); if the gate then passes, the adaptive start
// decides from those delays.
// The copies (issue 23, ninth session): a package the client resent because
// its acknowledgement was late (the relay's U[0, 100] ms link holds a
// package up to 100 ms, the client's first resend is after 100 ms) reaches
// the server as a duplicate, and the package sent after it waits behind it
// on a FIFO link: its delay then includes a queue the client's own copy made
// (in 46 of 55 relay misses it set the start's worst delay). The session
// records when each copy was handled (DelayHistory::AddCopy), and the burst
// discount leaves a package's wait behind a copy out of its delay whenever it
// was sent; Services reads its service behind the copy.
//
// Frames that come twice (issue 23, eleventh session; copies_start, an option, off): a
// client that sends each playback package twice (`playback_copies = 2`, or
// its automatic rule once it counted a loss) gets each frame at the earlier
// of two delays, so the frames' worst delay lies below the single-copy
// delays of the connect-time packages the start covers (on the relay's WAN
// profiles starts above 1.25 × the hindsight minimum in 6 of 40 runs with
// two copies). Once the server has seen a second copy of a frame of the
// sequence (AddFrameCopy; RobotSessions waits for frame 0's until shortly
// before the single-copy start, never past it), the start covers the
// quantile of the single-copy delays (the history's, both copies of the
// frames') at which M frames to come, each the earlier of two independent
// draws (P(min > x) = P(X > x)²), exceed it copies_tail times on average:
// a tail of sqrt(copies_tail / M); the order statistics' plotting position
// k / (n + 1), and past the largest of n, spread / n a rank (the
// single-copy rule's headroom, which it equals as the tail goes to 0).
//
// Queue follow (issue 23 item 3, seventh session; follow_queue, on): beyond
// the gate, where the server handled every package seen within one gap's
// stretch of its arrival at the socket (the queue is the link's, not the
// server's own, as in the paper's Fig. 11) and the services read off them
// (Services) average at most (1 + max_stretch) intervals, the adaptive start
// decides at the first frame without the 2.5 × excess, and the playout delay
// is QueueWorst: the schedule stretches each gap (within max_stretch) until
// the buffer covers the simulated queue.
//
// Queue start (issue 23 item 3; `queue_start`, off by default): beyond
// `adaptive_max_spread` intervals the delays are a queue's (a congested link),
// and the frames, one every interval, will queue behind each other as the
// sparse connect-time packages did not. It reads each package's service time
// off the packages seen (what it added behind the package before it,
// Lindley's recursion read backwards; Services), simulates the sequence's
// queue from resamples of those services, and covers the worst of the
// simulated sequences (queue_quantile); the stretch grows the buffer for a
// frame slower than that. It is decided once the next frame may come after
// the start (until then nothing plays, and each frame adds its service).
// A channel whose mean service may exceed (1 + max_stretch) intervals (the
// upper confidence bound) drifts faster than the stretch can follow: the
// paper's estimate. Why off by default: the paper's congestion (Fig. 11: a
// server pausing U[0, 0.25] s after each package, 8 packages a second
// against 10 frames) drifts 25 %; a start decided at the first frame from
// the delays seen (the adaptive start at any spread) leaves that drift to a
// stretch bounded to 10 %: in the model, 37 of 129 frames a run past the bound
// (a pause each), which is why fig11_congestion failed with it. The queue start
// sees the drift only where a sparse package met a pause, and misses it in
// about a fifth of such runs (tests/server/playback_schedule_test.cpp);
// the paper's estimate waits for 13 frames, which show it.
#pragma once

#include "playback_schedule.h"
#include "robotalk/clock.h"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace robotalk {

struct PlaybackEstimatorOptions {
  /// Frames needed before estimating: max(min_frames, fraction * N), capped at N.
  std::size_t min_frames = 5;
  double fraction = 0.1;
  /// Added to the estimate, on top of the jitter observed.
  Duration margin = std::chrono::milliseconds(100);
  /// The arrival rate is taken at the upper bound of its confidence interval,
  /// mean + z · standard error (2 ≈ 97.5 % one-sided for many frames).
  double confidence_z = 2.0;
  /// Quick start from send times (see above); off = always the paper's estimate.
  bool quick_start = true;
  /// Recent one-way delays needed (the first frame's included).
  std::size_t quick_min_delays = 4;
  /// The channel keeps up when its delay spread (max − min) is at most this
  /// fraction of the mean frame interval.
  double quick_max_spread = 1.0;
  /// The worst delay to come is taken as the least seen + this × the spread.
  double quick_jitter_factor = 2.5;
  /// Added on top (the RobotDaemon's wake-up, the decision itself).
  Duration quick_margin = std::chrono::milliseconds(10);
  /// The adaptive start (see above; off: the quick start or the paper's).
  bool adaptive = true;
  /// Above this spread (in frame intervals) the delays may be a queue's
  /// (the paper's congestion): the adaptive start gives way to the paper's
  /// estimate, which waits for frames and projects their drift. Set for a
  /// stretch of kGateStretch; a wider max_stretch raises it (and the
  /// adaptive start's quick_max_spread) by max_stretch − kGateStretch.
  double adaptive_max_spread = 1.2;
  static constexpr double kGateStretch = 0.10;
  /// Added to the worst recent delay; also the schedule's margin.
  Duration adaptive_margin = std::chrono::milliseconds(2);
  /// And the spread × this / the delays seen: the max of n samples falls
  /// short of the channel's by about spread / n (uniform jitter), so twice that.
  double adaptive_headroom = 4.0;
  /// The start covers only this much of the headroom (same unit); the
  /// schedule reaches the rest by stretching the first gaps within max_stretch.
  double start_headroom = 1.0;
  /// With the adaptive start, each gap between frames may play up to this
  /// fraction longer than recorded (PlaybackScheduleOptions::max_stretch).
  double max_stretch = 0.10;
  /// A thin buffer (issue 23, tenth session; PlaybackScheduleOptions): a
  /// frame that arrives after the latest time max_stretch allows, or on a
  /// FIFO link less than thin_lead × the delay spread before it, may take up
  /// to thin_stretch of its gap (and plays that lead after its arrival). 0
  /// (the default: an option, 0.25 measured) or at or below max_stretch: off. It
  /// moves neither the gate nor the start.
  double thin_stretch = 0;
  double thin_lead = 0.25;
  /// The adaptive start lies this many gaps' stretch (max_stretch × the mean
  /// frame interval each) below the delay it covers, never before the
  /// decision + adaptive_margin: the schedule's stretch of the first gaps
  /// reaches that delay by the frame after them (see above). 0: the start
  /// covers it itself (issue 23's first adaptive start).
  double start_lead = 1.0;
  /// Beyond adaptive_max_spread: the queue start (see above) instead of the
  /// paper's estimate. Off by default: it misses the drift of a channel
  /// slower than the sequence in a fifth of the runs (Fig. 11's injector).
  bool queue_start = false;
  /// The queue start covers this quantile of the worst delay of its
  /// resampled queues.
  double queue_quantile = 1.0;
  /// Resampled queues (each as long as the sequence, at most kQueueHorizon frames).
  std::size_t queue_resamples = 200;
  /// A package sent less than a frame interval after the one before it (the
  /// connect-time burst: hello, clock, heartbeat; the first frame too) that
  /// waited behind it on a FIFO link: that wait is left out of its delay for
  /// the spread and the worst delay where the delays as measured exceed
  /// adaptive_max_spread (see ChannelDelays). Off: every delay as measured.
  bool burst_wait_discount = true;
  /// And within the gate too where every package seen arrived in the order
  /// it was sent (a FIFO link: the burst's own queue is no delay a frame
  /// meets; a jittery link reorders a burst, and there its spread is
  /// jitter). Off: only where the delays as measured exceed the gate.
  bool burst_wait_discount_fifo = true;
  /// Beyond adaptive_max_spread, a queue the stretch can follow (see above,
  /// "Queue follow"): the adaptive start (without the spread's 2.5 × excess)
  /// and a playout delay that covers the simulated queue, which the schedule
  /// reaches by stretching the gaps. Off: the paper's estimate there (or the
  /// queue start, with queue_start).
  bool follow_queue = true;
  /// The queue is followed only where the server handled every package seen
  /// within this many gaps' stretch (max_stretch × the mean frame interval
  /// each) of its arrival at the socket: a server that lags behind its own
  /// input (the paper's Fig. 11 pauses after each package) is a queue whose
  /// drift its sparse packages do not show.
  double follow_max_lag = 1.0;
  /// The queue's mean service may be at most (1 + max_stretch) intervals at
  /// mean + follow_z × its standard error (the queue start uses confidence_z).
  double follow_z = 0.0;
  /// Frames that come twice (issue 23, eleventh session; the client's
  /// redundancy, `playback_copies`): once the server has seen a second copy
  /// of a frame of this sequence (AddFrameCopy), each frame arrives at the
  /// earlier of two delays, and the adaptive start covers the frames' worst
  /// such delay (CopiesWorst, see "Frames that come twice" above) where that
  /// is below the single-copy worst. Off (the default: on the relay's WAN
  /// profiles it met the goal in 58 of 80 runs against 59 without it): the
  /// single-copy start, decided at frame 0.
  bool copies_start = false;
  /// The worst of the frames to come, M of them, each the earlier of two
  /// independent delays: the single-copy delays' quantile whose tail is
  /// sqrt(copies_tail / M) (P(min > x) = P(X > x)², so M frames exceed it
  /// copies_tail times on average). 0.1 (the pure model, seeds 1-300 on a
  /// U[0, 100] ms jitter: 0.25 met 9 more runs and made a frame late in 2
  /// more; playback_copies_test).
  double copies_tail = 0.1;
  /// The server waits for frame 0's second copy until this long before the
  /// single-copy start (then starts with it: frame 0 is handed over in time).
  Duration copies_hold = std::chrono::milliseconds(5);
};

/// arrival − send time, or nullopt when it does not fit or exceeds 2^61 ns
/// (73 years; two such delays still subtract and add without overflow).
std::optional<Duration> OneWayDelay(TimePoint sent, TimePoint arrival);

/// The one-way delays (arrival − client send time) of one client's latest
/// packages, for PlaybackEstimator's quick start. Not thread-safe (one
/// session, the ServerDaemon's thread).
class DelayHistory {
 public:
  static constexpr std::size_t kCapacity = 32;
  struct Sample {
    TimePoint received;
    Duration delay;
    Duration lag{0};  ///< handled − reached the socket (the server's own lag); kCopy: a copy
    /// A copy (AddCopy): no delay of the channel (`delay` is its arrival − its
    /// first copy's send time, for diagnostics); marked in `lag`, never
    /// negative otherwise.
    static constexpr Duration kCopy = Duration::min();
    bool copy() const { return lag == kCopy; }
  };
  /// Records one package, handled at `received` after it reached the socket
  /// at `arrived` (both on the server clock; `arrived` later than `received`
  /// counts as no lag); a send time whose difference to `received` does not
  /// fit is ignored (a hostile header must not overflow anything).
  void Add(TimePoint sent, TimePoint received, std::optional<TimePoint> arrived = std::nullopt);
  /// Records that a copy of an earlier package (a duplicate, or a
  /// retransmission whose first copy was lost), stamped `sent` by the client,
  /// was handled at `received`: no delay of the channel, but on a FIFO link
  /// the package after it waited behind it (see "The copies" above). Kept in
  /// a ring of its own: a WAN's resends (every package whose round trip
  /// exceeds the client's resend interval) never push delays out.
  void AddCopy(TimePoint sent, TimePoint received);
  /// The delays recorded within `window` before `now`, oldest first (copies left out).
  std::vector<Duration> Recent(TimePoint now, Duration window = std::chrono::seconds(30)) const;
  /// The same with their arrival times (the queue start reads the queue from them), copies included.
  std::vector<Sample> RecentSamples(TimePoint now, Duration window = std::chrono::seconds(30)) const;

 private:
  struct Ring {
    std::array<Sample, kCapacity> samples{};
    std::size_t next = 0, size = 0;
    void Push(const Sample& s);
    void AppendRecent(TimePoint now, Duration window, std::vector<Sample>& out) const;
  };
  Ring delays_, copies_;
};

class PlaybackEstimator {
 public:
  /// `total_frames` and `duration` (offset of the last frame) as the client declared.
  PlaybackEstimator(std::size_t total_frames, Duration duration, PlaybackEstimatorOptions options = {});

  /// The client's recent one-way delays (DelayHistory::Recent), before or
  /// with the first frame; the quick start needs them.
  void SetDelayHistory(std::vector<Duration> delays) {
    history_ = std::move(delays);
    history_received_.clear();
    history_lag_.clear();
    copies_.clear();
  }
  /// The same with their arrival times (DelayHistory::RecentSamples), oldest first.
  void SetDelayHistory(const std::vector<DelayHistory::Sample>& samples);
  /// Records one frame: its offset from the sequence start, its arrival
  /// (handled), the client's send time of its package (nullopt: unknown) and
  /// how long after it reached the socket the server handled it.
  void Add(Duration offset, TimePoint arrival, std::optional<TimePoint> sent = std::nullopt,
           Duration lag = Duration(0));
  std::size_t frames_seen() const { return frames_.size(); }
  std::size_t frames_needed() const { return needed_; }
  /// Heap memory it holds (its frames and delay history), for the session's accounting.
  std::size_t heap_bytes() const {
    return frames_.capacity() * sizeof(Frame) + history_.capacity() * sizeof(Duration) +
           history_received_.capacity() * sizeof(TimePoint) + history_lag_.capacity() * sizeof(Duration) +
           copies_.capacity() * sizeof(Copy) + frame_copies_.capacity() * sizeof(Duration);
  }
  bool ready() const;
  /// Whether the start is decided at the first frames from send times (the
  /// quick or the adaptive start, see above).
  bool quick() const;
  /// Whether the start is the adaptive one (see above), and whether it is
  /// its queue start (the delays spread by more than adaptive_max_spread).
  bool adaptive() const;
  bool queued() const;
  /// Whether it is the adaptive start beyond the gate on a queue the stretch
  /// can follow (follow_queue, see above): its playout delay covers the queue.
  bool followed() const;
  /// With followed(): how far above the least delay seen its playout delay lies (the simulated
  /// queue's worst). REQUIRES: followed().
  Duration followed_queue() const;
  /// Frames the queue start simulates at most (a longer sequence's queue is
  /// extrapolated at its drift).
  static constexpr std::size_t kQueueHorizon = 2000;
  /// With the adaptive start, the worst delay it covers + its margin (the
  /// schedule's playout delay, PlaybackSchedule); else nullopt.
  std::optional<Duration> playout_delay() const;
  /// A second copy of a frame of this sequence (the client sent it twice:
  /// `playback_copies`), stamped `sent` by the client, handled at `received`:
  /// its frames come twice (copies_start). The decision is then no earlier
  /// than `received`.
  void AddFrameCopy(TimePoint sent, TimePoint received);
  /// The start is decided at `now` (later than the latest frame: a wait for a
  /// second copy ended): it is never before `now` + the margin.
  void DecideAt(TimePoint now) { decided_at_ = std::max(decided_at_, now); }
  /// Whether a frame of this sequence came twice (AddFrameCopy).
  bool frames_copied() const { return !frame_copies_.empty(); }
  /// The schedule's options: with the adaptive estimator its stretch, margin
  /// and thin buffer (its lead from the delay spread), else the fixed
  /// schedule (the quick and the paper's estimators).
  PlaybackScheduleOptions schedule_options() const;
  /// How far below the worst delay it covers the adaptive start lies
  /// (start_lead × max_stretch × the mean frame interval).
  Duration start_lead() const;
  /// Max − min of the recent one-way delays and the frames' (nullopt: too
  /// few, or a frame without a send time).
  std::optional<Duration> delay_spread() const;
  /// Whether that spread (and the worst delay) leaves out the wait of a
  /// connect-time burst's packages behind each other (burst_wait_discount):
  /// only where the delays as measured exceed adaptive_max_spread and the
  /// discounted ones do not.
  bool burst_discounted() const;

  /// The server time at which offset 0 plays. REQUIRES: ready().
  TimePoint StartTime() const;
  /// What the start was decided from, one JSON object (diagnostics, --log-playback): the
  /// delays seen in ms above the least (history and frames, as measured and as the channel's),
  /// the server's lag, the spread, the worst delay covered, frame 0's delay, the lead, the start
  /// after the first frame and the playout delay. REQUIRES: ready().
  std::string Describe() const;
  /// Average time between commands and between arrivals over the frames seen.
  Duration mean_command_interval() const;
  Duration mean_arrival_interval() const;
  /// How much more than the worst lag seen so far the last frame may lag,
  /// `remaining` seconds of sequence later (upper confidence bound).
  Duration ExtraLagBound(Duration remaining) const;

 private:
  struct Frame {
    Duration offset;
    TimePoint arrival;
    std::optional<Duration> delay;  // arrival − send time
    Duration lag;                   // handled − reached the socket
  };
  // Offset 0's time covering a worst delay `worst`. REQUIRES: quick().
  // `lead`: that much earlier, but never before the decision + margin.
  TimePoint StartCovering(Duration worst, Duration margin, Duration lead = Duration(0)) const;
  Duration AdaptiveWorst(double headroom) const;  // REQUIRES: adaptive()
  // With frames_copied(): the worst of the frames to come as the earlier of
  // two delays (copies_start), never above AdaptiveWorst(headroom).
  Duration CopiesWorst() const;          // REQUIRES: adaptive()
  Duration StartWorst() const;           // REQUIRES: adaptive()
  Duration QueueWorst() const;           // REQUIRES: queued() or followed()
  std::vector<double> Services() const;  // s, of the packages seen; REQUIRES: delay_spread()
  TimePoint PaperStart() const;          // the paper's estimate
  bool QueueFollowable(double z) const;  // REQUIRES: delay_spread()
  bool ServerKeptUp() const;             // every package seen handled within follow_max_lag of its arrival
  bool SpreadWithinGate() const;
  double WiderStretch() const;  // max(0, max_stretch − kGateStretch), intervals
  double Gate() const;          // the spread beyond which the adaptive start gives way, s
  struct Spread {
    Duration least, most;  // of the recent delays, retransmissions left out
    std::size_t kept;      // delays within the fence
  };
  std::optional<Spread> FencedSpread() const;
  // The delays seen (the history's, then the frames', both in arrival order),
  // with their arrivals where known; empty: too few, or a frame without a send time.
  struct Seen {
    TimePoint arrival;
    Duration delay;
    bool known_arrival;
  };
  std::vector<Seen> SeenPackages() const;
  // Their delays (empty: too few, or a frame without a send time). With
  // burst_wait_discount, where the measured spread exceeds the gate and
  // discounting brings it within, each less its wait behind the package
  // before it where it was sent less than a frame interval after it (not a
  // frame after the first): `discounted`.
  struct Channel {
    std::vector<Duration> delays;
    bool discounted = false;
  };
  Channel ChannelDelays() const;
  static bool ArrivedInSendOrder(const std::vector<Seen>& seen);

  double interval() const;  // the declared mean frame interval, s
  std::size_t total_;
  Duration duration_;
  PlaybackEstimatorOptions options_;
  std::size_t needed_;
  std::vector<Frame> frames_;
  std::vector<Duration> history_;
  std::vector<TimePoint> history_received_;  // empty, or history_'s arrivals
  std::vector<Duration> history_lag_;        // empty, or the server's lag handling each
  struct Copy {
    TimePoint received;
    Duration delay;  // its arrival − its first copy's send time (diagnostics)
  };
  std::vector<Copy> copies_;            // copies of earlier packages the history saw handled, oldest first
  std::vector<Duration> frame_copies_;  // the delays of this sequence's frames' second copies
  TimePoint decided_at_ = TimePoint::min();  // the latest AddFrameCopy or DecideAt
  // The latest copy handled after `after` and before `before`, else `after`.
  TimePoint BehindCopy(TimePoint after, TimePoint before) const;
};

}  // namespace robotalk
