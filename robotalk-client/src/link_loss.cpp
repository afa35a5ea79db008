#include "link_loss.h"

#include <algorithm>

namespace robotalk::client {

void LinkLoss::OnSend(std::int64_t sequence, TimePoint now, int copies) {
  Entry& e = entries_[sequence];
  if (e.sent > 0) by_last_send_.erase({e.last_send, sequence});
  e.sent += copies;
  e.last_send = std::max(e.last_send, now);
  by_last_send_.insert({e.last_send, sequence});
  // Beyond kMaxPending the oldest are forgotten, neither lost nor settled:
  // a flood of packages is no evidence of loss.
  while (by_last_send_.size() > kMaxPending) {
    entries_.erase(by_last_send_.begin()->second);
    by_last_send_.erase(by_last_send_.begin());
  }
}

void LinkLoss::OnAck(std::int64_t sequence) {
  // An ack of a package already settled (or never recorded) changes nothing.
  if (auto it = entries_.find(sequence); it != entries_.end()) ++it->second.acked;
}

void LinkLoss::Settle(TimePoint now, Duration settle_after) {
  while (!by_last_send_.empty() && by_last_send_.begin()->first + settle_after <= now) {
    const std::int64_t sequence = by_last_send_.begin()->second;
    by_last_send_.erase(by_last_send_.begin());
    const auto it = entries_.find(sequence);
    if (it == entries_.end()) continue;
    const Entry& e = it->second;
    ++settled_;
    if (e.acked < e.sent) {
      lost_ += static_cast<std::uint64_t>(e.sent - e.acked);
      last_loss_ = now;
    }
    entries_.erase(it);
  }
}

}  // namespace robotalk::client
