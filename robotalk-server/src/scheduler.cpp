#include "scheduler.h"

#include <algorithm>

namespace robotalk {

Scheduler::Scheduler() = default;

void Scheduler::Push(QueuedItem item) {
  item.arrival = ++arrivals_;
  queues_[item.client_id].Push(std::move(item));
  ++size_;
}

std::size_t Scheduler::queued(std::int64_t client_id) const {
  auto it = queues_.find(client_id);
  return it == queues_.end() ? 0 : it->second.size();
}

void Scheduler::TakeDue(TimePoint now, std::vector<QueuedItem>& out) {
  if (auto server = queues_.find(0); server != queues_.end()) {
    while (!server->second.empty() && server->second.Top().start <= now) {
      out.push_back(server->second.Pop());
      --size_;
    }
  }
  // A linear pick over the clients per item: clients are few (tens), and this
  // keeps each client's queue its own (flushed alone, bounded alone).
  for (;;) {
    CommandQueue* first = nullptr;
    for (auto& [client, queue] : queues_) {
      if (client == 0 || queue.empty() || queue.Top().start > now) continue;
      if (!first || queue.Top().RunsBefore(first->Top())) first = &queue;
    }
    if (!first) break;
    out.push_back(first->Pop());
    --size_;
  }
  std::erase_if(queues_, [](const auto& entry) { return entry.second.empty(); });
}

void Scheduler::FlushAll(std::vector<QueuedItem>& out) {
  for (auto& [client, queue] : queues_) queue.Flush(out);
  queues_.clear();
  size_ = 0;
}

void Scheduler::FlushClient(std::int64_t client_id, std::vector<QueuedItem>& out) {
  auto it = queues_.find(client_id);
  if (it == queues_.end()) return;
  size_ -= it->second.size();
  it->second.Flush(out);
  queues_.erase(it);
}

Duration Scheduler::SetStream(std::int64_t client_id, Duration period, TimePoint now) {
  if (period.count() > 0) {
    stream_requests_[client_id] = period;
  } else {
    stream_requests_.erase(client_id);
  }
  Duration shortest{0};
  for (const auto& [client, p] : stream_requests_)
    shortest = shortest.count() == 0 ? p : std::min(shortest, p);
  if (shortest.count() > 0 && (stream_period_.count() == 0 || shortest < stream_period_)) next_sample_ = now;
  stream_period_ = shortest;
  return stream_period_;
}

bool Scheduler::TakeSampleDue(TimePoint now) {
  if (stream_period_.count() == 0 || now < next_sample_) return false;
  next_sample_ += stream_period_ * ((now - next_sample_) / stream_period_ + 1);
  return true;
}

TimePoint Scheduler::NextDeadline() const {
  TimePoint next = TimePoint::max();
  for (const auto& [client, queue] : queues_) {
    if (!queue.empty()) next = std::min(next, queue.Top().start);
  }
  if (stream_period_.count() > 0) next = std::min(next, next_sample_);
  return next;
}

}  // namespace robotalk
