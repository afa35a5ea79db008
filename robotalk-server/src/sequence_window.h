// Which package sequence numbers of one client the server has already seen,
// so a retransmitted or duplicated package is never executed twice. Pure.
#pragma once

#include <cstdint>
#include <set>

namespace robotalk {

class SequenceWindow {
 public:
  /// Records `sequence`; returns true the first time it is seen, false for a
  /// duplicate. Numbers more than kWindow below the highest seen count as
  /// duplicates (too old to be a legitimate first copy).
  bool Observe(std::int64_t sequence);
  std::int64_t highest() const { return highest_; }

  static constexpr std::int64_t kWindow = 4096;

 private:
  std::int64_t contiguous_ = 0;  // every sequence <= this has been seen
  std::int64_t highest_ = 0;
  std::set<std::int64_t> ahead_;  // seen sequences > contiguous_ + 1
};

}  // namespace robotalk
