// FaultyTransport: a Transport decorator for tests that loses, repeats,
// reorders, delays or silences messages on their way, so that the real client
// and the real server core can be tested against a bad network without a
// hand-written stand-in for either.
//
//   MemoryTransport end(bus);
//   FaultyTransport net(end, {.seed = 5});
//   net.Add({.channel_regex = "ROBOTALK/.*/REPLY/.*", .drop_probability = 0.3});
//   Server server(net, ...);   // its replies now get lost 30% of the time
//
// A Fault applies to the messages of one direction whose channel matches its
// regex (as a whole, POSIX extended, as Transport::Subscribe) and, when given,
// its `when` predicate on the bytes. Each message goes through the faults in
// the order they were added: the first that drops it ends its way; a
// duplicate goes out twice; the first that holds it (delay or reversed batch)
// keeps it until it is released.
//
// Directions: kOutgoing faults act in Publish() (a held message is published
// later, from the thread that releases it). kIncoming faults act when the
// inner transport dispatches a message to a handler subscribed through this
// decorator (once per subscription the message matches); they can drop,
// duplicate, silence and count, but not hold (handlers must run inside
// HandleFor(); Add() refuses an incoming delay or batch).
//
// Time: delays run on `options.clock` (a ManualClock in tests) and leave only
// when ReleaseDue() or ReleaseAll() is called, or, as a convenience, at the
// start of this transport's Publish() and HandleFor(). Nothing sleeps.
//
// Randomness: one std::mt19937_64 seeded with `options.seed`; the same
// messages through the same faults give the same losses.
//
// Thread safety: every method may be called from any thread (one mutex; the
// `when` predicates run under it and must not call this transport). The
// rules of transport.h hold for the inner transport.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/transport.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

namespace robotalk::testing {

enum class Direction { kOutgoing, kIncoming };

/// A predicate on a message: its channel and bytes.
using MessageFilter = std::function<bool(const std::string& channel, std::span<const std::uint8_t> bytes)>;

struct Fault {
  std::string channel_regex = ".*";
  Direction direction = Direction::kOutgoing;
  /// Only messages it returns true for (empty: every message on the channel).
  MessageFilter when;
  /// Drop every matching message (a server fallen silent).
  bool mute = false;
  /// Drop the first this many matching messages.
  int drop_first = 0;
  /// Drop each matching message with this probability (seeded).
  double drop_probability = 0.0;
  /// Deliver each matching message twice with this probability (seeded).
  double duplicate_probability = 0.0;
  /// Outgoing: hold matching messages until this many are held, then send
  /// them last first. 0 = off.
  std::size_t reverse_batch = 0;
  /// Outgoing: hold each matching message this long on the clock. 0 = off.
  Duration delay{0};
};

/// What one fault did so far (messages).
struct FaultCounts {
  std::uint64_t matched = 0;     ///< messages that reached this fault and matched it
  std::uint64_t dropped = 0;     ///< by mute, drop_first or drop_probability
  std::uint64_t duplicated = 0;  ///< sent a second time
  std::uint64_t held = 0;        ///< held for a delay or a batch
  std::uint64_t released = 0;    ///< held messages sent since
};

struct FaultyTransportOptions {
  std::uint64_t seed = 1;
  /// The clock delays run on; nullptr = the steady clock. Must outlive the transport.
  const Clock* clock = nullptr;
};

class FaultyTransport final : public Transport {
 public:
  using FaultId = int;

  /// Wraps `inner`, which must outlive this transport.
  explicit FaultyTransport(Transport& inner, FaultyTransportOptions options = {});
  /// Held messages that were never released are dropped (never sent).
  ~FaultyTransport() override;

  /// Adds a fault after those already there. Throws Error for a bad regex, a
  /// probability outside [0, 1], an incoming fault that holds, or a fault that
  /// both delays and reverses.
  FaultId Add(Fault fault);
  /// Removes a fault; the messages it holds are sent first (a partial batch
  /// last first). Unknown ids are ignored.
  void Remove(FaultId id);
  /// What fault `id` did. Throws Error for an unknown id.
  FaultCounts counts(FaultId id) const;

  /// Sends the held messages whose delay has passed on the clock, in the
  /// order they were held. Returns how many were sent.
  int ReleaseDue();
  /// Sends every held message now: delayed ones in order, then each partial
  /// batch last first. Returns how many were sent.
  int ReleaseAll();
  /// Messages held now.
  std::size_t held() const;

  // Transport.
  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override;
  int HandleFor(Duration timeout) override;
  int fileno() const override;
  std::string url() const override;  ///< the inner transport's

 private:
  struct State;
  Transport& inner_;
  std::shared_ptr<State> state_;  // shared with the handlers of incoming faults
};

}  // namespace robotalk::testing
