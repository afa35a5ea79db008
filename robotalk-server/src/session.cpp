#include "session.h"

namespace robotalk {
namespace {

// A hash-map node: the value, the next pointer, the bucket slot pointing at
// it, and the allocator's header.
template <typename Value>
constexpr std::size_t kNodeBytes = sizeof(Value) + 3 * sizeof(void*);

// Heap bytes of a string beyond the in-place buffer (libstdc++ keeps 15).
std::size_t HeapBytes(const std::string& s) { return s.capacity() > 15 ? s.capacity() + 1 : 0; }

std::size_t PackageBytes(const std::vector<CommandId>& ids) {
  return kNodeBytes<std::pair<const std::int64_t, std::vector<CommandId>>> + sizeof(std::int64_t) +
         ids.capacity() * sizeof(CommandId);
}

}  // namespace

std::size_t ReplyCache::Bytes(const std::optional<Reply>& reply) {
  std::size_t n = kNodeBytes<std::pair<const CommandId, Entry>>;
  if (reply) n += HeapBytes(reply->message) + reply->values.capacity() * sizeof(double);
  return n;
}

void ReplyCache::RecordPackage(std::int64_t sequence, std::vector<CommandId> ids) {
  if (ids.empty() || packages_.count(sequence)) return;
  for (CommandId id : ids) {
    auto [it, added] = replies_.try_emplace(id);
    if (added) bytes_ += Bytes(std::nullopt);
    ++it->second.packages;  // a playback's id comes with each of its packages
    it->second.detached = false;
  }
  bytes_ += PackageBytes(ids);
  packages_.emplace(sequence, std::move(ids));
  order_.push_back(sequence);
  Evict();
}

void ReplyCache::RecordReply(const Reply& reply) {
  // Only replies to recorded packages are kept, so memory follows the bounds.
  auto it = replies_.find(reply.id);
  if (it == replies_.end()) return;
  if (it->second.detached) {  // sent, not kept: its package was forgotten
    Erase(it);
    return;
  }
  bytes_ -= Bytes(it->second.reply);
  it->second.reply = reply;
  it->second.reply->message.shrink_to_fit();
  bytes_ += Bytes(it->second.reply);
  Evict();
}

void ReplyCache::Evict() {
  while (!order_.empty() && (order_.size() > limits_.max_packages || bytes_ > limits_.max_bytes)) {
    EvictOldestPackage();
  }
  // Waiting items of forgotten packages: at most max_packages, and within
  // the byte budget even when no package is left.
  while (!detached_.empty() && (detached_.size() > limits_.max_packages || bytes_ > limits_.max_bytes)) {
    auto it = replies_.find(detached_.front());
    if (it != replies_.end() && it->second.detached) Erase(it);
    detached_.pop_front();
    bytes_ -= sizeof(CommandId);
  }
}

void ReplyCache::EvictOldestPackage() {
  const auto package = packages_.find(order_.front());
  order_.pop_front();
  for (CommandId id : package->second) {
    auto it = replies_.find(id);
    if (it == replies_.end() || it->second.detached || --it->second.packages > 0) continue;
    if (it->second.reply) {
      Erase(it);
    } else {  // still waiting: remember it was received
      it->second.detached = true;
      detached_.push_back(id);
      bytes_ += sizeof(CommandId);
    }
  }
  bytes_ -= PackageBytes(package->second);
  packages_.erase(package);
}

void ReplyCache::Erase(std::unordered_map<CommandId, Entry>::iterator it) {
  bytes_ -= Bytes(it->second.reply);
  replies_.erase(it);
}

std::vector<Reply> ReplyCache::RepliesFor(std::int64_t sequence) const {
  std::vector<Reply> out;
  auto p = packages_.find(sequence);
  if (p == packages_.end()) return out;
  for (CommandId id : p->second) {
    auto r = replies_.find(id);
    if (r != replies_.end() && r->second.reply) out.push_back(*r->second.reply);
  }
  return out;
}

void Session::Continue(Session&& previous) {
  const std::int64_t id = session_id;
  const bool is_live = live;
  const std::uint64_t opened = order;
  const Nonce nonce = hello_nonce;
  std::optional<Keyed> key = std::move(keyed);
  *this = std::move(previous);
  session_id = id;
  live = is_live;
  order = opened;
  hello_nonce = nonce;
  keyed = std::move(key);
}

}  // namespace robotalk
