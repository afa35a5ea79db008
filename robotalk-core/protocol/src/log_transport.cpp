#include "robotalk/log_transport.h"

#include "subscription_table.h"

#include "robotalk/error.h"
#include "robotalk/lcm_log.h"

#include <algorithm>
#include <memory>
#include <optional>
#include <thread>
#include <vector>

namespace robotalk {
namespace {

struct Event {
  std::int64_t timestamp_us = 0;
  std::string channel;
  std::vector<std::uint8_t> bytes;
};

}  // namespace

namespace internal {

class LogCore {
 public:
  explicit LogCore(LogTransportOptions options)
      : options_(std::move(options)),
        log_(Open(options_.path)),
        clock_(options_.clock ? *options_.clock : steady_) {
    if (!(options_.speed > 0)) {
      throw TransportError("LogTransport '" + options_.path + "': speed " + std::to_string(options_.speed) +
                           " is not positive");
    }
    ReadNext();
  }

  static std::unique_ptr<LcmLogReader> Open(const std::string& path) {
    try {
      return std::make_unique<LcmLogReader>(path);
    } catch (const Error& e) {
      throw TransportError("LogTransport: cannot read the LCM log '" + path + "' (" + e.what() + ")");
    }
  }

  // A damaged stretch of the file is skipped by the reader (LcmLogReader::damage()).
  void ReadNext() {
    const LcmLogEvent* e = log_->Next();
    if (e == nullptr) {
      next_.reset();
      return;
    }
    ++read_;
    next_ = Event{e->timestamp_us, e->channel, e->data};
  }

  // When the pending event is due on the clock (paced mode).
  TimePoint DueTime() {
    if (!start_) {
      start_ = clock_.Now();
      first_us_ = next_->timestamp_us;
    }
    const double offset_s = static_cast<double>(next_->timestamp_us - first_us_) * 1e-6 / options_.speed;
    return *start_ + FromSeconds(std::max(offset_s, 0.0));
  }

  const LogTransportOptions options_;
  std::unique_ptr<LcmLogReader> log_;
  SteadyClock steady_;
  const Clock& clock_;
  std::optional<Event> next_;  // the first event not yet dispatched
  std::optional<TimePoint> start_;
  std::int64_t first_us_ = 0;
  std::size_t read_ = 0;
  std::int64_t received_us_ = 0;  // the dispatched event's timestamp (HandleFor() thread)
  const std::shared_ptr<SubscriptionTable> subs_ = std::make_shared<SubscriptionTable>();
};

}  // namespace internal

LogTransport::LogTransport(LogTransportOptions options)
    : impl_(std::make_shared<internal::LogCore>(std::move(options))) {}
LogTransport::~LogTransport() = default;

void LogTransport::Publish(const std::string& channel, std::span<const std::uint8_t>) {
  throw TransportError("log transport is read-only: cannot publish on '" + channel + "' (" + url() + ")");
}

std::unique_ptr<Subscription> LogTransport::Subscribe(const std::string& channel_regex, Handler handler) {
  return SubscriptionTable::Subscribe(impl_->subs_, "LogTransport", channel_regex, std::move(handler));
}

int LogTransport::HandleFor(Duration timeout) {
  internal::LogCore& d = *impl_;
  if (d.options_.paced && d.next_) {
    // Wait (bounded by `timeout`, in real time) for the next event to fall due.
    const auto real_deadline = std::chrono::steady_clock::now() + timeout;
    for (int i = 0; i < 100000; ++i) {
      const Duration left = d.DueTime() - d.clock_.Now();
      if (left <= Duration(0)) break;
      const auto real_left = real_deadline - std::chrono::steady_clock::now();
      if (real_left <= real_left.zero()) return 0;
      std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(
          real_left, std::min<Duration>(left, std::chrono::milliseconds(10))));
    }
  }
  int dispatched = 0;
  for (std::size_t n = 0; d.next_ && n < d.options_.max_per_call; ++n) {
    if (d.options_.paced && d.DueTime() > d.clock_.Now()) break;
    const Event event = std::move(*d.next_);
    d.ReadNext();
    const auto matching = d.subs_->Matching(event.channel);
    if (matching.empty()) continue;
    ++dispatched;
    d.received_us_ = event.timestamp_us;
    // An exception leaves the rest of the log to the next call.
    SubscriptionTable::Dispatch(matching, event.channel, event.bytes);
  }
  return dispatched;
}

std::string LogTransport::url() const { return "file://" + impl_->options_.path; }

WallTime LogTransport::ReceiveTime() const {
  return WallTime(std::chrono::microseconds(impl_->received_us_));
}

bool LogTransport::done() const { return !impl_->next_; }

std::size_t LogTransport::events_read() const { return impl_->read_; }

}  // namespace robotalk
