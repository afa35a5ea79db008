#include "sequence_window.h"

namespace robotalk {

bool SequenceWindow::Observe(std::int64_t sequence) {
  if (sequence <= contiguous_ || sequence < highest_ - kWindow) return false;
  if (!ahead_.insert(sequence).second) return false;
  if (sequence > highest_) highest_ = sequence;
  // Advance the contiguous prefix; also forget gaps that fell out of the window.
  while (!ahead_.empty() && (*ahead_.begin() == contiguous_ + 1 || *ahead_.begin() < highest_ - kWindow)) {
    contiguous_ = *ahead_.begin();
    ahead_.erase(ahead_.begin());
  }
  return true;
}

}  // namespace robotalk
