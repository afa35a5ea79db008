#include "return_cache.h"

namespace robotalk::client {

using Kind = ReturnCache::Outcome::Kind;

void ReturnCache::Expect(CommandId id) {
  std::lock_guard lock(mu_);
  entries_.try_emplace(id);
}

bool ReturnCache::Put(const Reply& reply) {
  {
    std::lock_guard lock(mu_);
    auto it = entries_.find(reply.id);
    if (it == entries_.end() || it->second.outcome.kind != Kind::kPending) {
      ++ignored_;
      return false;
    }
    it->second.outcome.kind = Kind::kReply;
    it->second.outcome.reply = reply;
    answered_order_.push_back(reply.id);
    ++num_answered_;
    EvictLocked();
  }
  cv_.notify_all();
  return true;
}

bool ReturnCache::Fail(CommandId id, const std::string& why, bool timed_out) {
  {
    std::lock_guard lock(mu_);
    auto it = entries_.find(id);
    if (it == entries_.end() || it->second.outcome.kind != Kind::kPending) return false;
    it->second.outcome.kind = Kind::kFailed;
    it->second.outcome.failure = why;
    it->second.outcome.timed_out = timed_out;
    answered_order_.push_back(id);
    ++num_answered_;
    EvictLocked();
  }
  cv_.notify_all();
  return true;
}

void ReturnCache::FailAll(const std::string& why, bool timed_out) {
  {
    std::lock_guard lock(mu_);
    for (auto& [id, entry] : entries_) {
      if (entry.outcome.kind != Kind::kPending) continue;
      entry.outcome.kind = Kind::kFailed;
      entry.outcome.failure = why;
      entry.outcome.timed_out = timed_out;
      answered_order_.push_back(id);
      ++num_answered_;
    }
    EvictLocked();
  }
  cv_.notify_all();
}

void ReturnCache::Forget(CommandId id) {
  std::lock_guard lock(mu_);
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  if (it->second.outcome.kind != Kind::kPending) --num_answered_;
  entries_.erase(it);
}

ReturnCache::Outcome ReturnCache::Take(CommandId id) {
  std::lock_guard lock(mu_);
  return TakeLocked(id);
}

ReturnCache::Outcome ReturnCache::WaitTake(CommandId id, std::chrono::steady_clock::time_point deadline,
                                           std::stop_token stop) {
  std::unique_lock lock(mu_);
  Outcome o;
  cv_.wait_until(lock, stop, deadline, [&] {
    o = TakeLocked(id);
    return o.kind != Kind::kPending;
  });
  return o;
}

ReturnCache::Outcome ReturnCache::TakeLocked(CommandId id) {
  auto it = entries_.find(id);
  if (it == entries_.end()) return Outcome{.kind = Kind::kUnknown};
  if (it->second.outcome.kind == Kind::kPending) return Outcome{};
  Outcome o = std::move(it->second.outcome);
  entries_.erase(it);
  --num_answered_;
  return o;
}

void ReturnCache::EvictLocked() {
  // answered_order_ may name ids already collected or forgotten: skip those.
  auto live = [this](CommandId id) {
    auto it = entries_.find(id);
    return it != entries_.end() && it->second.outcome.kind != Kind::kPending;
  };
  while (!answered_order_.empty()) {
    const CommandId id = answered_order_.front();
    if (!live(id)) {
      answered_order_.pop_front();
      continue;
    }
    if (num_answered_ <= capacity_) break;
    answered_order_.pop_front();
    entries_.erase(id);
    --num_answered_;
  }
  // An old reply nobody collects must not pin every later stale id.
  if (answered_order_.size() > 2 * capacity_ + 16) {
    std::deque<CommandId> kept;
    for (CommandId id : answered_order_)
      if (live(id)) kept.push_back(id);
    answered_order_.swap(kept);
  }
}

std::size_t ReturnCache::size() const {
  std::lock_guard lock(mu_);
  return entries_.size();
}

std::uint64_t ReturnCache::ignored() const {
  std::lock_guard lock(mu_);
  return ignored_;
}

}  // namespace robotalk::client
