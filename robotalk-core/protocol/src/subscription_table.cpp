#include "subscription_table.h"

#include <algorithm>

namespace robotalk {

class TableSubscription final : public Subscription {
 public:
  TableSubscription(std::weak_ptr<SubscriptionTable> table, std::shared_ptr<SubscriptionTable::Entry> entry)
      : table_(std::move(table)), entry_(std::move(entry)) {}
  ~TableSubscription() override {
    entry_->active = false;
    if (auto table = table_.lock()) {
      std::lock_guard lock(table->mu_);
      std::erase(table->entries_, entry_);
    }
  }

 private:
  std::weak_ptr<SubscriptionTable> table_;
  std::shared_ptr<SubscriptionTable::Entry> entry_;
};

std::unique_ptr<Subscription> SubscriptionTable::Subscribe(const std::shared_ptr<SubscriptionTable>& table,
                                                           const char* owner,
                                                           const std::string& channel_regex,
                                                           Transport::Handler handler) {
  auto entry = std::make_shared<Entry>();
  try {
    entry->regex = std::regex(channel_regex, std::regex::extended);
  } catch (const std::regex_error& e) {
    throw TransportError(std::string(owner) + ": bad channel regex '" + channel_regex + "': " + e.what());
  }
  entry->handler = std::move(handler);
  {
    std::lock_guard lock(table->mu_);
    table->entries_.push_back(entry);
  }
  return std::make_unique<TableSubscription>(table, std::move(entry));
}

bool SubscriptionTable::Wants(const std::string& channel) const {
  std::lock_guard lock(mu_);
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const auto& e) { return std::regex_match(channel, e->regex); });
}

SubscriptionTable::Matches SubscriptionTable::Matching(const std::string& channel) const {
  std::lock_guard lock(mu_);
  Matches out;
  for (const auto& e : entries_) {
    if (std::regex_match(channel, e->regex)) out.push_back(e);
  }
  return out;
}

void SubscriptionTable::Dispatch(const Matches& matches, const std::string& channel,
                                 std::span<const std::uint8_t> bytes) {
  for (const auto& e : matches) {
    if (e->active) e->handler(channel, bytes);  // `matches` keeps the handler alive while it runs
  }
}

}  // namespace robotalk
