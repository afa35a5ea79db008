#include "sequence_window.h"

#include <algorithm>

namespace robotalk {

SequenceWindow::Verdict SequenceWindow::Check(std::int64_t sequence) const {
  if (sequence <= 0) return Verdict::kDuplicate;
  if (!started_) return Verdict::kNew;
  if (sequence > highest_) {
    // Unseen numbers this one would add: (highest_, sequence), computed without overflow.
    const std::int64_t added = sequence - 1 - highest_;
    return added > kMaxUnseen - unseen_ ? Verdict::kTooManyGaps : Verdict::kNew;
  }
  if (sequence <= floor_) return Verdict::kDuplicate;
  // The first gap ending at or after `sequence`: does it contain it?
  const auto it = std::lower_bound(gaps_.begin(), gaps_.end(), sequence,
                                   [](const auto& gap, std::int64_t s) { return gap.second < s; });
  return it != gaps_.end() && it->first <= sequence ? Verdict::kNew : Verdict::kDuplicate;
}

SequenceWindow::Verdict SequenceWindow::Observe(std::int64_t sequence) {
  const Verdict v = Check(sequence);
  if (v != Verdict::kNew) return v;
  if (!started_) {
    started_ = true;
    const std::int64_t lead = std::min(sequence - 1, kLead);
    floor_ = sequence - 1 - lead;
    if (lead > 0) gaps_.push_back({sequence - lead, sequence - 1});
    unseen_ = lead;
    highest_ = sequence;
    return v;
  }
  if (sequence > highest_) {
    if (sequence > highest_ + 1) gaps_.push_back({highest_ + 1, sequence - 1});
    unseen_ += sequence - 1 - highest_;
    highest_ = sequence;
    return v;
  }
  auto it = std::lower_bound(gaps_.begin(), gaps_.end(), sequence,
                             [](const auto& gap, std::int64_t s) { return gap.second < s; });
  --unseen_;
  if (it->first == sequence && it->second == sequence) {
    gaps_.erase(it);
  } else if (it->first == sequence) {
    ++it->first;
  } else if (it->second == sequence) {
    --it->second;
  } else {
    const std::int64_t last = it->second;
    it->second = sequence - 1;
    gaps_.insert(it + 1, {sequence + 1, last});
  }
  floor_ = gaps_.empty() ? highest_ : gaps_.front().first - 1;
  return v;
}

}  // namespace robotalk
