// The subscriptions of a transport that matches channels itself
// (MemoryTransport, LogTransport; LCM keeps its own): regexes with LCM's
// semantics (POSIX extended, whole-name match), the handler of each, and the
// Subscription that removes its entry on destruction -- also when it outlives
// the table (it holds the table weakly).
//
// Thread safety: every member may be called from any thread. An entry taken
// by Matching() stays callable after its Subscription is destroyed; Dispatch()
// skips it from then on (an earlier handler may unsubscribe a later one).
#pragma once

#include "robotalk/transport.h"

#include <atomic>
#include <memory>
#include <mutex>
#include <regex>
#include <span>
#include <string>
#include <vector>

namespace robotalk {

class SubscriptionTable {
 public:
  struct Entry {
    std::regex regex;
    Transport::Handler handler;
    std::atomic<bool> active{true};
  };
  using Matches = std::vector<std::shared_ptr<const Entry>>;

  /// Adds `handler` for channels matching `channel_regex`. Throws
  /// TransportError naming `owner` (the transport) for a bad regex.
  static std::unique_ptr<Subscription> Subscribe(const std::shared_ptr<SubscriptionTable>& table,
                                                 const char* owner, const std::string& channel_regex,
                                                 Transport::Handler handler);

  /// Whether any subscription matches `channel`.
  bool Wants(const std::string& channel) const;
  /// The subscriptions matching `channel` now, in subscription order.
  Matches Matching(const std::string& channel) const;
  /// Calls the handler of each entry of `matches` still subscribed. A
  /// handler's exception propagates (the rest are not called).
  static void Dispatch(const Matches& matches, const std::string& channel,
                       std::span<const std::uint8_t> bytes);

 private:
  friend class TableSubscription;
  mutable std::mutex mu_;
  std::vector<std::shared_ptr<Entry>> entries_;  // GUARDED_BY(mu_)
};

}  // namespace robotalk
