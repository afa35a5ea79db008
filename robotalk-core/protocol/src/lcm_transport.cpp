#include "robotalk/lcm_transport.h"

#include <lcm/lcm.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <exception>
#include <mutex>

namespace robotalk {

Subscription::~Subscription() = default;
Transport::~Transport() = default;

WallTime Transport::ReceiveTime() const {
  return std::chrono::time_point_cast<std::chrono::microseconds>(std::chrono::system_clock::now());
}

namespace {

// What LCM's C callback needs: the handler and where to store its exception.
// The handler is a shared_ptr so that a handler destroying its own
// Subscription (and with it this entry) does not destroy the function while
// it runs.
struct Entry {
  std::shared_ptr<const Transport::Handler> handler;
  std::exception_ptr* error = nullptr;  // owned by the transport's Impl
  std::int64_t* received_us = nullptr;  // owned by the transport's Impl
};

// Never lets an exception cross LCM's C stack: it is stored and rethrown by
// HandleFor() after lcm_handle_timeout() has returned.
extern "C" void OnLcmMessage(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  auto* entry = static_cast<Entry*>(user);
  std::exception_ptr* error = entry->error;
  if (*error) return;  // an earlier handler of this message failed
  *entry->received_us = rbuf->recv_utime;
  const std::shared_ptr<const Transport::Handler> handler = entry->handler;
  try {
    (*handler)(channel,
               std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(rbuf->data), rbuf->data_size));
  } catch (...) {
    *error = std::current_exception();
  }
}

}  // namespace

namespace internal {

class LcmCore {
 public:
  explicit LcmCore(const LcmTransportOptions& options)
      : options_(options), url_(LcmTransport::EffectiveUrl(options)) {
    lcm_ = lcm_create(url_.empty() ? nullptr : url_.c_str());
    if (lcm_ == nullptr) {
      throw TransportError("LcmTransport: LCM could not start on " +
                           (url_.empty() ? std::string("its default URL") : "'" + url_ + "'") +
                           " (bad URL, or no route for its multicast group?)");
    }
  }
  ~LcmCore() { lcm_destroy(lcm_); }

  lcm_t* lcm_ = nullptr;
  const LcmTransportOptions options_;
  const std::string url_;
  std::exception_ptr error_;      // only touched by the HandleFor() thread
  std::int64_t received_us_ = 0;  // the dispatched message's recv_utime (HandleFor() thread)
};

}  // namespace internal

namespace {

class LcmSubscription final : public Subscription {
 public:
  LcmSubscription(std::weak_ptr<internal::LcmCore> owner, lcm_subscription_t* sub,
                  std::unique_ptr<Entry> entry)
      : owner_(std::move(owner)), sub_(sub), entry_(std::move(entry)) {}
  ~LcmSubscription() override {
    // Inside the handler's own callback LCM defers the removal; either way it
    // never calls this entry again.
    if (auto owner = owner_.lock()) lcm_unsubscribe(owner->lcm_, sub_);
  }

 private:
  std::weak_ptr<internal::LcmCore> owner_;
  lcm_subscription_t* sub_;
  std::unique_ptr<Entry> entry_;
};

}  // namespace

LcmTransport::LcmTransport(LcmTransportOptions options)
    : impl_(std::make_shared<internal::LcmCore>(options)) {}
LcmTransport::~LcmTransport() = default;

std::string LcmTransport::EffectiveUrl(const LcmTransportOptions& options) {
  std::string url = options.url;
  if (options.recv_buf_size <= 0 || url.rfind("udpm://", 0) != 0) return url;
  if (url.find("recv_buf_size=") != std::string::npos) return url;
  url += (url.find('?') == std::string::npos ? "?" : "&");
  return url + "recv_buf_size=" + std::to_string(options.recv_buf_size);
}

void LcmTransport::Publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  if (bytes.size() > static_cast<std::size_t>(UINT_MAX) ||
      lcm_publish(impl_->lcm_, channel.c_str(), bytes.data(), static_cast<unsigned>(bytes.size())) != 0) {
    throw TransportError("LcmTransport: publishing " + std::to_string(bytes.size()) + " bytes on '" +
                         channel + "' via " + url() + " failed");
  }
}

std::unique_ptr<Subscription> LcmTransport::Subscribe(const std::string& channel_regex, Handler handler) {
  auto entry = std::make_unique<Entry>();
  entry->handler = std::make_shared<const Handler>(std::move(handler));
  entry->error = &impl_->error_;
  entry->received_us = &impl_->received_us_;
  lcm_subscription_t* sub = lcm_subscribe(impl_->lcm_, channel_regex.c_str(), &OnLcmMessage, entry.get());
  if (sub == nullptr) {
    throw TransportError("LcmTransport: cannot subscribe '" + channel_regex + "' on " + url());
  }
  lcm_subscription_set_queue_capacity(sub, impl_->options_.queue_capacity);
  return std::make_unique<LcmSubscription>(impl_, sub, std::move(entry));
}

int LcmTransport::HandleFor(Duration timeout) {
  impl_->error_ = nullptr;
  int handled = 0;
  auto millis = std::chrono::ceil<std::chrono::milliseconds>(std::max(timeout, Duration(0))).count();
  int wait_ms = static_cast<int>(std::min<long long>(millis, INT_MAX));
  // The first message may take up to `timeout`; the rest only what is waiting.
  // Bounded: a handler that keeps publishing to itself cannot keep us here.
  for (int round = 0; round < 100000; ++round) {
    const int r = lcm_handle_timeout(impl_->lcm_, wait_ms);
    if (impl_->error_) {
      std::exception_ptr error = impl_->error_;
      impl_->error_ = nullptr;
      std::rethrow_exception(error);
    }
    if (r < 0) throw TransportError("LcmTransport: receiving on " + url() + " failed");
    if (r == 0) break;
    ++handled;
    wait_ms = 0;
  }
  return handled;
}

int LcmTransport::fileno() const { return lcm_get_fileno(impl_->lcm_); }

WallTime LcmTransport::ReceiveTime() const {
  return WallTime(std::chrono::microseconds(impl_->received_us_));
}

std::string LcmTransport::url() const { return impl_->url_.empty() ? "(LCM default)" : impl_->url_; }

}  // namespace robotalk
