#include "outstanding_packages.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace robotalk::client {

Duration OutstandingPackages::BaseTimeout() const {
  // RFC 6298: srtt + 4 rttvar, never below the configured interval.
  return srtt_ ? std::max(policy_.interval, *srtt_ + 4 * rttvar_) : policy_.interval;
}

Duration OutstandingPackages::Ceiling() const {
  // No gap between two sends of a package is longer than max_interval, nor a
  // quarter of the give-up bound (a package is resent at least ~4 times
  // before it is given up), unless the measured round trip itself is longer.
  return std::max(BaseTimeout(), std::min(policy_.max_interval, policy_.give_up_after / 4));
}

Duration OutstandingPackages::retransmit_timeout() const {
  return std::min(BaseTimeout() * (1 << timer_backoff_), Ceiling());
}

Duration OutstandingPackages::IntervalAt(int step) const {
  // A package backs off on its own resends (step) and with every package
  // after a timeout (timer_backoff_): the larger of the two counts. A slow
  // (congested) server thus gets resends no faster than it answers, instead
  // of a storm of duplicates that would congest it further.
  const Duration base = BaseTimeout();
  const double factor = std::pow(std::max(1.0, policy_.backoff), std::max(step, timer_backoff_));
  const double ns = static_cast<double>(base.count()) * factor;
  const Duration cap = Ceiling();
  if (ns >= static_cast<double>(cap.count())) return cap;
  return std::max(base, Duration(static_cast<Duration::rep>(ns)));
}

void OutstandingPackages::AddNetworkRoundTrip(Duration rtt, TimePoint now) {
  network_rtts_.emplace_back(now, rtt);
  while (network_rtts_.size() > kMaxRoundTrips ||
         (network_rtts_.size() > 1 && now - network_rtts_.front().first > kRoundTripWindow)) {
    network_rtts_.pop_front();
  }
  // A median over a large window moves slowly: past 64 samples, every 8th
  // sample recomputes it (the cost stays a few microseconds per 8 acks).
  if (network_rtts_.size() >= 64 && ++since_median_ < 8) return;
  since_median_ = 0;
  scratch_.clear();
  for (const auto& [at, sample] : network_rtts_) scratch_.push_back(sample);
  const std::size_t n = scratch_.size();
  const auto upper = scratch_.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(scratch_.begin(), upper, scratch_.end());
  reported_rtt_ = *upper;
  if (n % 2 == 0) reported_rtt_ = (*upper + *std::max_element(scratch_.begin(), upper)) / 2;
}

void OutstandingPackages::AddRoundTrip(Duration rtt) {
  timer_backoff_ = 0;
  if (!srtt_) {
    srtt_ = rtt;
    rttvar_ = rtt / 2;
    return;
  }
  const Duration error = rtt > *srtt_ ? rtt - *srtt_ : *srtt_ - rtt;
  rttvar_ = (3 * rttvar_ + error) / 4;
  *srtt_ = (7 * *srtt_ + rtt) / 8;
}

void OutstandingPackages::UpdateStart(CommandId id, TimePoint start, TimePoint now) {
  auto owner = owner_.find(id);
  if (owner == owner_.end()) return;
  auto it = packages_.find(owner->second);
  if (it == packages_.end()) return;
  Package& p = it->second;
  p.pending[id] = start;
  if (p.acked) Reschedule(it->first, p, std::max(now, EarliestStart(p, now)) + IntervalAt(0));
  RefreshSilence(it->first, p);
}

void OutstandingPackages::Reschedule(std::int64_t sequence, Package& p, TimePoint t) {
  if (t == p.next_send) return;
  by_next_send_.erase({p.next_send, sequence});
  p.next_send = t;
  by_next_send_.insert({t, sequence});
}

TimePoint OutstandingPackages::SilentSince(const Package& p) {
  // Once acknowledged, silence counts only from when an answer is due.
  return p.acked ? std::max(p.last_heard, EarliestStart(p, p.last_heard)) : p.last_heard;
}

void OutstandingPackages::RefreshSilence(std::int64_t sequence, Package& p) {
  const TimePoint since = SilentSince(p);
  if (since == p.silent_since) return;
  by_silence_.erase({p.silent_since, sequence});
  p.silent_since = since;
  by_silence_.insert({since, sequence});
}

void OutstandingPackages::Erase(std::unordered_map<std::int64_t, Package>::iterator it) {
  by_next_send_.erase({it->second.next_send, it->first});
  by_silence_.erase({it->second.silent_since, it->first});
  packages_.erase(it);
}

TimePoint OutstandingPackages::NextDeadline() const {
  TimePoint next = TimePoint::max();
  if (!by_next_send_.empty()) next = by_next_send_.begin()->first;
  if (!by_silence_.empty()) {
    // TakeExpired gives up once now - since > give_up_after.
    next = std::min(next, by_silence_.begin()->first + policy_.give_up_after + Duration(1));
  }
  return next;
}

TimePoint OutstandingPackages::EarliestStart(const Package& p, TimePoint fallback) {
  std::optional<TimePoint> earliest;
  for (const auto& [id, start] : p.pending) {
    const TimePoint s = start.value_or(fallback);
    if (!earliest || s < *earliest) earliest = s;
  }
  return earliest.value_or(fallback);
}

void OutstandingPackages::Add(std::int64_t sequence, std::vector<std::uint8_t> bytes, std::vector<Item> items,
                              TimePoint now) {
  assert(!Contains(sequence));
  Package p;
  p.bytes = std::move(bytes);
  for (const Item& item : items) {
    p.pending.emplace(item.id, item.start);
    owner_[item.id] = sequence;
  }
  p.first_send = now;
  p.last_heard = now;
  p.next_send = now + IntervalAt(0);
  p.silent_since = SilentSince(p);
  by_next_send_.insert({p.next_send, sequence});
  by_silence_.insert({p.silent_since, sequence});
  packages_.emplace(sequence, std::move(p));
}

OutstandingPackages::AckInfo OutstandingPackages::OnAck(std::int64_t sequence, TimePoint now,
                                                        std::optional<AckTiming> timing) {
  AckInfo info;
  auto it = packages_.find(sequence);
  if (it == packages_.end()) return info;
  Package& p = it->second;
  info.known = true;
  info.first = !p.acked;
  info.retransmitted = p.sends > 1;
  info.first_send = p.first_send;
  p.last_heard = now;
  if (!p.acked) {
    p.acked = true;
    // Karn's rule: only a package sent once gives an unambiguous round trip.
    if (p.sends == 1) {
      AddRoundTrip(now - p.first_send);
      const AckTiming t = timing.value_or(AckTiming{.received = now});
      // server_hold comes from the reply (forgeable, saturated): compared, never
      // subtracted beyond the round trip, so no overflow.
      const Duration total = t.received - p.first_send;
      if (t.server_hold >= Duration::zero() && t.server_hold < total)
        AddNetworkRoundTrip(total - t.server_hold, now);
    }
    // Replies are not due before the items' start times: ask again only after.
    p.backoff_step = 0;
    Reschedule(sequence, p, std::max(now, EarliestStart(p, now)) + IntervalAt(0));
  }
  if (p.pending.empty()) {
    Erase(it);
    info.completed = true;
    return info;
  }
  RefreshSilence(sequence, p);
  return info;
}

std::optional<std::int64_t> OutstandingPackages::OnReply(CommandId id, TimePoint now) {
  auto owner = owner_.find(id);
  if (owner == owner_.end()) return std::nullopt;
  const std::int64_t sequence = owner->second;
  owner_.erase(owner);
  auto it = packages_.find(sequence);
  if (it == packages_.end()) return std::nullopt;
  Package& p = it->second;
  p.pending.erase(id);
  p.last_heard = now;
  // A reply proves the package arrived even if its ack was lost (it is no
  // round-trip sample: a scheduled command's reply waits for its start).
  if (!p.acked) {
    p.acked = true;
    p.backoff_step = 0;
  }
  if (p.pending.empty()) {
    Erase(it);
    return sequence;
  }
  Reschedule(sequence, p, std::max(p.next_send, std::max(now, EarliestStart(p, now)) + IntervalAt(0)));
  RefreshSilence(sequence, p);
  return std::nullopt;
}

std::vector<OutstandingPackages::Resend> OutstandingPackages::TakeDue(TimePoint now) {
  std::vector<Resend> due;
  bool timed_out = false;
  // The due packages, earliest first (taken out before rescheduling them).
  std::vector<std::int64_t> sequences;
  for (auto k = by_next_send_.begin(); k != by_next_send_.end() && k->first <= now; ++k)
    sequences.push_back(k->second);
  std::size_t deferred = 0;
  for (const std::int64_t sequence : sequences) {
    Package& p = packages_.at(sequence);
    if (due.size() >= kMaxResendsPerCall) {
      // Paced: a burst of due packages (a loss burst, 1000 in flight) leaves
      // kMaxResendsPerCall at a time, one pacing step apart, instead of all
      // at once into a receive buffer that just overflowed.
      Reschedule(sequence, p, now + kPacingStep * static_cast<int>(1 + deferred++ / kMaxResendsPerCall));
      continue;
    }
    due.push_back({sequence, p.bytes});
    timed_out = timed_out || !p.acked;
    ++p.sends;
    ++retransmissions_;
    ++p.backoff_step;
    Reschedule(sequence, p, now + IntervalAt(p.backoff_step));
  }
  // RFC 6298 §5.5: an acknowledgement that did not come in time backs the
  // timer off for every package until a fresh round-trip sample arrives, so a
  // congested server is not fed duplicates faster than it answers.
  if (timed_out && timer_backoff_ < kMaxTimerBackoff) ++timer_backoff_;
  return due;
}

std::vector<OutstandingPackages::Expired> OutstandingPackages::TakeExpired(TimePoint now) {
  std::vector<Expired> expired;
  while (!by_silence_.empty() && now - by_silence_.begin()->first > policy_.give_up_after) {
    auto it = packages_.find(by_silence_.begin()->second);
    const Package& p = it->second;
    Expired e{.sequence = it->first, .acked = p.acked};
    for (const auto& [id, start] : p.pending) {
      e.unanswered.push_back(id);
      owner_.erase(id);
    }
    std::sort(e.unanswered.begin(), e.unanswered.end());
    expired.push_back(std::move(e));
    Erase(it);
  }
  return expired;
}

std::vector<CommandId> OutstandingPackages::Clear() {
  std::vector<CommandId> ids;
  for (const auto& [id, sequence] : owner_) ids.push_back(id);
  owner_.clear();
  packages_.clear();
  by_next_send_.clear();
  by_silence_.clear();
  return ids;
}

bool OutstandingPackages::IsAcked(std::int64_t sequence) const {
  auto it = packages_.find(sequence);
  return it != packages_.end() && it->second.acked;
}

}  // namespace robotalk::client
