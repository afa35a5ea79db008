#include "command_queue.h"

#include <algorithm>

namespace robotalk {
namespace {
// std heap algorithms keep the "largest" on top; make the first-to-run largest.
bool RunsAfter(const QueuedItem& a, const QueuedItem& b) { return b.RunsBefore(a); }
}  // namespace

void CommandQueue::Push(QueuedItem item) {
  heap_.push_back(std::move(item));
  std::push_heap(heap_.begin(), heap_.end(), RunsAfter);
}

QueuedItem CommandQueue::Pop() {
  std::pop_heap(heap_.begin(), heap_.end(), RunsAfter);
  QueuedItem item = std::move(heap_.back());
  heap_.pop_back();
  return item;
}

void CommandQueue::Flush(std::vector<QueuedItem>& out) {
  std::sort(heap_.begin(), heap_.end(),
            [](const QueuedItem& a, const QueuedItem& b) { return a.RunsBefore(b); });
  for (QueuedItem& item : heap_) out.push_back(std::move(item));
  heap_.clear();
}

}  // namespace robotalk
