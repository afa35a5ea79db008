#include "robotalk/routed_lcm_transport.h"

#include "robotalk/forwarding_transport.h"

#include <sys/epoll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace robotalk {
namespace {

constexpr const char* kLcmDefaultUrl = "udpm://239.255.76.67:7667?ttl=0";

// One regex subscribed on several lanes.
class MultiLaneSubscription final : public Subscription {
 public:
  explicit MultiLaneSubscription(std::vector<std::unique_ptr<Subscription>> parts)
      : parts_(std::move(parts)) {}

 private:
  std::vector<std::unique_ptr<Subscription>> parts_;
};

// The LcmTransport a SingleUdpmTransport owns, a base so that it is
// constructed before the ForwardingTransport that refers to it.
struct OwnedLcmTransport {
  explicit OwnedLcmTransport(LcmTransportOptions options) : lcm(std::move(options)) {}
  LcmTransport lcm;
};

// A udpm LcmTransport of the single layout that says so in its url(), so that
// what a server prints and announces is a URL its clients can use as is.
class SingleUdpmTransport final : private OwnedLcmTransport, public ForwardingTransport {
 public:
  SingleUdpmTransport(LcmTransportOptions options, std::string url)
      : OwnedLcmTransport(std::move(options)), ForwardingTransport(lcm), url_(std::move(url)) {}
  std::string url() const override { return url_; }

 private:
  const std::string url_;
};

}  // namespace

RoutedLcmTransport::RoutedLcmTransport(std::string lcm_url, OpenLcmOptions options)
    : lcm_url_(std::move(lcm_url)), options_(std::move(options)) {
  LaneUrl(lcm_url_, kLaneCount - 1);  // throws now for a URL that cannot be split
  epoll_fd_ = ::epoll_create1(EPOLL_CLOEXEC);
  if (epoll_fd_ < 0) {
    throw TransportError("RoutedLcmTransport: epoll_create1 failed for " + lcm_url_ + ": " +
                         std::strerror(errno));
  }
}

RoutedLcmTransport::~RoutedLcmTransport() {
  for (auto& lane : lanes_) lane.store(nullptr);
  for (auto& owned : owned_) owned.reset();
  ::close(epoll_fd_);
}

LcmTransport& RoutedLcmTransport::Lane(int lane) {
  if (LcmTransport* t = lanes_[static_cast<std::size_t>(lane)].load(std::memory_order_acquire)) return *t;
  std::lock_guard lock(mu_);
  auto& owned = owned_[static_cast<std::size_t>(lane)];
  if (!owned) {
    LcmTransportOptions o = options_.lane;
    o.url = LaneUrl(lcm_url_, lane);
    owned = std::make_unique<LcmTransport>(o);
    lanes_[static_cast<std::size_t>(lane)].store(owned.get(), std::memory_order_release);
  }
  return *owned;
}

void RoutedLcmTransport::StartReceiving(int lane) {
  auto& receiving = receiving_[static_cast<std::size_t>(lane)];
  if (receiving.load(std::memory_order_acquire)) return;
  std::lock_guard lock(mu_);
  if (receiving.load(std::memory_order_relaxed)) return;
  // LCM creates the lane's receive socket and thread here (and on subscribe).
  const int fd = owned_[static_cast<std::size_t>(lane)]->fileno();
  if (fd < 0) throw TransportError("RoutedLcmTransport: LCM cannot receive on " + LaneUrl(lcm_url_, lane));
  epoll_event ev{};
  ev.events = EPOLLIN;
  ev.data.u32 = static_cast<std::uint32_t>(lane);
  if (::epoll_ctl(epoll_fd_, EPOLL_CTL_ADD, fd, &ev) != 0) {
    throw TransportError("RoutedLcmTransport: epoll_ctl failed for " + LaneUrl(lcm_url_, lane) + ": " +
                         std::strerror(errno));
  }
  receiving.store(true, std::memory_order_release);
}

void RoutedLcmTransport::Publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  Lane(LaneOfChannel(channel)).Publish(channel, bytes);
}

std::unique_ptr<Subscription> RoutedLcmTransport::Subscribe(const std::string& channel_regex,
                                                            Handler handler) {
  const std::optional<int> known = LaneOfSubscription(channel_regex);
  if (known || !options_.all_lanes) {
    const int lane = known.value_or(kMainLane);
    auto sub = Lane(lane).Subscribe(channel_regex, std::move(handler));
    StartReceiving(lane);
    return sub;
  }
  // One handler shared by every lane: dispatch is on one thread, one lane at
  // a time, so it is never called twice at once.
  auto shared = std::make_shared<Handler>(std::move(handler));
  std::vector<std::unique_ptr<Subscription>> parts;
  parts.reserve(kLaneCount);
  for (int lane = 0; lane < kLaneCount; ++lane) {
    parts.push_back(Lane(lane).Subscribe(
        channel_regex, [shared](const std::string& channel, std::span<const std::uint8_t> bytes) {
          (*shared)(channel, bytes);
        }));
    StartReceiving(lane);
  }
  return std::make_unique<MultiLaneSubscription>(std::move(parts));
}

int RoutedLcmTransport::DispatchLane(int lane) {
  LcmTransport* t = lanes_[static_cast<std::size_t>(lane)].load(std::memory_order_acquire);
  if (!t) return 0;
  dispatching_ = t;
  const int n = t->HandleFor(Duration(0));
  dispatching_ = nullptr;
  return n;
}

WallTime RoutedLcmTransport::ReceiveTime() const {
  return dispatching_ ? dispatching_->ReceiveTime() : Transport::ReceiveTime();
}

int RoutedLcmTransport::HandleFor(Duration timeout) {
  const auto millis = std::chrono::ceil<std::chrono::milliseconds>(std::max(timeout, Duration(0))).count();
  int wait_ms = static_cast<int>(std::min<long long>(millis, INT_MAX));
  epoll_event events[kLaneCount];
  int handled = 0;
  // The first message may take up to `timeout`; then only what is waiting.
  // Bounded like LcmTransport::HandleFor.
  for (int round = 0; round < 1000; ++round) {
    const int n = ::epoll_wait(epoll_fd_, events, kLaneCount, wait_ms);
    if (n < 0) {
      if (errno == EINTR) break;
      throw TransportError("RoutedLcmTransport: epoll_wait failed on " + lcm_url_ + ": " +
                           std::strerror(errno));
    }
    if (n == 0) break;
    for (int i = 0; i < n; ++i) handled += DispatchLane(static_cast<int>(events[i].data.u32));
    wait_ms = 0;
  }
  return handled;
}

int RoutedLcmTransport::fileno() const { return epoll_fd_; }

std::string RoutedLcmTransport::url() const { return lcm_url_; }

bool RoutedLcmTransport::Receives(int lane) const {
  return lane >= 0 && lane < kLaneCount && receiving_[static_cast<std::size_t>(lane)].load();
}

std::string ResolveLcmUrl(const std::string& url) {
  if (!url.empty()) return url;
  const char* env = std::getenv("LCM_DEFAULT_URL");
  return (env != nullptr && *env != '\0') ? std::string(env) : std::string(kLcmDefaultUrl);
}

std::string MainLcmUrl(const std::string& url) { return ParseTrafficUrl(ResolveLcmUrl(url)).lcm_url; }

std::unique_ptr<Transport> OpenLcmTransport(const std::string& url, const OpenLcmOptions& options) {
  const TrafficUrl parsed = ParseTrafficUrl(ResolveLcmUrl(url));
  if (parsed.layout == TrafficLayout::kSplit) {
    return std::make_unique<RoutedLcmTransport>(parsed.lcm_url, options);
  }
  LcmTransportOptions o = options.lane;
  o.url = parsed.lcm_url;
  if (parsed.lcm_url.starts_with("udpm://")) {
    const std::string lcm_url = LcmTransport::EffectiveUrl(o);
    return std::make_unique<SingleUdpmTransport>(
        o, lcm_url + (lcm_url.find('?') == std::string::npos ? "?" : "&") + "traffic=single");
  }
  return std::make_unique<LcmTransport>(o);
}

}  // namespace robotalk
