// ImpairedChannel: the maths of one direction of the impairment relay, with
// no I/O, no threads and no clock of its own. Given each message's arrival
// TimePoint it answers when (if ever) its copies are to be released.
//
// Per message, in this order:
//   1. loss:        dropped with probability `loss` (before the link);
//   2. congestion:  a single-server FIFO link. Service starts at
//                   max(arrival, link free); it lasts U[0, congestion_max];
//                   the message leaves the link at start + service, and the
//                   next message cannot start before that (Lindley recursion);
//   3. copies:      one copy, two with probability `duplicate`;
//   4. per copy:    release = link exit + max(0, latency + jitter)
//                   (+ reorder_delay with probability `reorder`).
//   5. outage:      a message arriving within the outage window (from
//                   `outage_at` after the channel's first message, for
//                   `outage`) is held: its copies leave no earlier than
//                   the window's end, all at once (a stalled Wi-Fi link's
//                   burst; issue 23). Draws no random numbers.
//   Jitter is U[-jitter, +jitter] (kUniform) or N(0, jitter^2) clamped to
//   +-3 jitter (kNormal). Jitter larger than the send interval reorders too.
//
// Determinism: the random numbers come from std::mt19937_64 and are turned
// into doubles by this file (not by std:: distributions), so a seed and an
// arrival sequence give the same schedule on every standard library. Every
// message consumes the same count of random numbers whatever the parameters,
// so e.g. which messages are lost does not depend on the latency setting.
//
// Thread safety: none; one instance per direction, used by one thread at a time.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <random>

#include <robotalk/clock.h>

namespace robotalk::relay {

enum class JitterDistribution { kUniform, kNormal };

/// One direction's impairments. Probabilities in [0, 1], durations >= 0.
struct ImpairmentParams {
  Duration latency{0};  ///< fixed one-way delay of every copy
  Duration jitter{0};   ///< half-width (uniform) or sigma (normal)
  JitterDistribution jitter_distribution = JitterDistribution::kUniform;
  double loss = 0.0;           ///< probability a message is dropped
  double duplicate = 0.0;      ///< probability a message is released twice
  double reorder = 0.0;        ///< probability a copy is held back by reorder_delay
  Duration reorder_delay{0};   ///< extra delay of a held-back copy
  Duration congestion_max{0};  ///< link service time is U[0, congestion_max]; 0 = no link
  Duration outage_at{0};       ///< the outage starts this long after the first message
  Duration outage{0};          ///< how long it holds everything; 0 = none
};

/// Throws std::invalid_argument naming the field and value if `params` is out of range.
void Validate(const ImpairmentParams& params);

/// The fate of one message: zero (lost), one or two release times.
struct Releases {
  int count = 0;
  std::array<TimePoint, 2> at{};
  bool lost = false;
  bool duplicated = false;
  std::array<bool, 2> reordered{};  ///< copy i was held back by reorder_delay
  TimePoint link_exit{};            ///< when the message left the congested link
};

/// Counters since construction.
struct ChannelStats {
  std::uint64_t arrived = 0;
  std::uint64_t lost = 0;
  std::uint64_t duplicated = 0;
  std::uint64_t reordered = 0;  ///< copies held back
  std::uint64_t copies = 0;     ///< release times handed out
  std::uint64_t held = 0;       ///< messages held by the outage
};

class ImpairedChannel {
 public:
  /// Throws std::invalid_argument if `params` is invalid (see Validate).
  ImpairedChannel(const ImpairmentParams& params, std::uint64_t seed);

  /// Decides the fate of a message arriving at `arrival`. Release times are
  /// never before `arrival`. Arrivals are expected in non-decreasing order
  /// (an earlier one just queues behind the link as it is).
  Releases Admit(TimePoint arrival);

  const ImpairmentParams& params() const { return params_; }
  const ChannelStats& stats() const { return stats_; }
  /// When the congested link becomes free (the last message's link exit);
  /// stays at the epoch without congestion.
  TimePoint link_free_at() const { return link_free_; }

 private:
  double Uniform01();  // [0, 1), 53 random bits
  Duration CopyDelay(bool reordered, double u1, double u2) const;

  ImpairmentParams params_;
  std::mt19937_64 rng_;
  TimePoint link_free_{};
  std::optional<TimePoint> first_arrival_;  // the outage window counts from here
  ChannelStats stats_;
};

}  // namespace robotalk::relay
