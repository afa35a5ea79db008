// StateQueue (state_queue.h).
#include "state_queue.h"

namespace robotalk::python {

void StateQueue::Push(const StateSample& sample) {
  {
    std::lock_guard lock(mu_);
    if (closed_) return;
    ++received_;
    if (samples_.size() >= capacity_) {
      samples_.pop_front();
      ++dropped_;
    }
    samples_.push_back(sample);
  }
  cv_.notify_one();
}

std::optional<StateSample> StateQueue::Pop(Duration most) {
  std::unique_lock lock(mu_);
  cv_.wait_for(lock, most, [&] { return !samples_.empty() || closed_; });
  if (samples_.empty()) return std::nullopt;
  StateSample s = std::move(samples_.front());
  samples_.pop_front();
  return s;
}

void StateQueue::Close() {
  {
    std::lock_guard lock(mu_);
    closed_ = true;
  }
  cv_.notify_all();
}

bool StateQueue::closed() const {
  std::lock_guard lock(mu_);
  return closed_;
}
std::size_t StateQueue::size() const {
  std::lock_guard lock(mu_);
  return samples_.size();
}
std::uint64_t StateQueue::dropped() const {
  std::lock_guard lock(mu_);
  return dropped_;
}
std::uint64_t StateQueue::received() const {
  std::lock_guard lock(mu_);
  return received_;
}

}  // namespace robotalk::python
