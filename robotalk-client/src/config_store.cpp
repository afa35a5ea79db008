// Bounded store of robot descriptions (config_store.h).
#include "config_store.h"

#include <algorithm>

namespace robotalk::client {

bool ConfigStore::Has(std::uint64_t hash) const {
  return kept_.count(hash) != 0 ||
         std::any_of(unasked_.begin(), unasked_.end(), [&](const auto& e) { return e.first == hash; });
}

void ConfigStore::Add(std::uint64_t hash, Model model, std::size_t bytes) {
  if (Has(hash)) return;
  bytes_ += bytes;
  if (wanted_.erase(hash) != 0) {
    kept_.emplace(hash, Entry{std::move(model), bytes});
    return;
  }
  unasked_.emplace_back(hash, Entry{std::move(model), bytes});
  while (unasked_.size() > kUnasked) {
    bytes_ -= unasked_.front().second.bytes;
    unasked_.pop_front();
  }
}

ConfigStore::Model ConfigStore::Want(std::uint64_t hash) {
  if (auto it = kept_.find(hash); it != kept_.end()) return it->second.model;
  const auto it =
      std::find_if(unasked_.begin(), unasked_.end(), [&](const auto& e) { return e.first == hash; });
  if (it == unasked_.end()) {
    wanted_.insert(hash);
    return nullptr;
  }
  Model model = it->second.model;
  kept_.emplace(hash, std::move(it->second));
  unasked_.erase(it);
  return model;
}

}  // namespace robotalk::client
