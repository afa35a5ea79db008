#include "session.h"

namespace robotalk {

void ReplyCache::RecordPackage(std::int64_t sequence, std::vector<CommandId> ids) {
  if (ids.empty() || packages_.count(sequence)) return;
  for (CommandId id : ids) replies_.emplace(id, std::nullopt);
  packages_.emplace(sequence, std::move(ids));
  order_.push_back(sequence);
  while (order_.size() > max_packages_) {
    for (CommandId id : packages_[order_.front()]) replies_.erase(id);
    packages_.erase(order_.front());
    order_.pop_front();
  }
}

void ReplyCache::RecordReply(const Reply& reply) {
  // Only replies to recorded packages are kept, so memory follows the package bound.
  auto it = replies_.find(reply.id);
  if (it != replies_.end()) it->second = reply;
}

std::vector<Reply> ReplyCache::RepliesFor(std::int64_t sequence) const {
  std::vector<Reply> out;
  auto p = packages_.find(sequence);
  if (p == packages_.end()) return out;
  for (CommandId id : p->second) {
    auto r = replies_.find(id);
    if (r != replies_.end() && r->second) out.push_back(*r->second);
  }
  return out;
}

}  // namespace robotalk
