#include "robotalk/lcm_transport.h"

#include "robotalk/log_writer.h"

#include <fcntl.h>
#include <lcm/lcm.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <cstdio>
#include <exception>
#include <mutex>
#include <string>
#include <vector>

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

// LCM writes why it cannot start (a bad URL in lcm_create; "LCM self test
// failed" in the first lcm_subscribe, where it starts receiving) to stderr
// itself, with fprintf: a stderr that takes nothing (a full pipe, a terminal
// stopped with Ctrl-S) held the program's start for ever. Only then, while
// the call runs, descriptor 2 is a non-blocking pipe of its own (64 KiB;
// past that LCM's writes fail, never wait); Take() puts stderr back and
// returns what was written, for the caller to say through LogWriter (or in
// its error). Anything another thread wrote to stderr meanwhile is taken too
// (said after, not lost). A stderr that takes a line now is left alone (the
// dup2 is the whole process's: other threads' lines must not be taken for
// LCM's), and so is one it cannot set up, and a closed one (a process
// started with '2>&-'; the pipe's descriptors are kept above 2, so a closed 0
// or 1 is never taken either: review14, LCM's own descriptor took 2 while it
// started and the capture then put its pipe over it).
class StderrCapture {
 public:
  StderrCapture() {
    if (::fcntl(2, F_GETFD) == -1) return;  // closed: LCM's lines go nowhere, as any other
    pollfd out{2, POLLOUT, 0};
    if (::poll(&out, 1, 0) == 1 && out.revents == POLLOUT) return;  // stderr takes a line now
    int p[2];
    if (::pipe2(p, O_CLOEXEC | O_NONBLOCK) != 0) return;
    for (int& fd : p) fd = AboveStdio(fd);
    if (p[0] < 0 || p[1] < 0) {
      for (const int fd : p)
        if (fd >= 0) ::close(fd);
      return;
    }
    std::fflush(stderr);
    saved_ = ::fcntl(2, F_DUPFD_CLOEXEC, 3);
    if (saved_ < 0 || ::dup2(p[1], 2) < 0) {
      if (saved_ >= 0) ::close(saved_);
      saved_ = -1;
      ::close(p[0]);
      ::close(p[1]);
      return;
    }
    ::close(p[1]);
    read_ = p[0];
  }
  ~StderrCapture() { Take(); }
  StderrCapture(const StderrCapture&) = delete;
  StderrCapture& operator=(const StderrCapture&) = delete;

  // `fd` moved to a descriptor above 2 (closed, -1 when it cannot be).
  static int AboveStdio(int fd) {
    if (fd > 2) return fd;
    const int moved = ::fcntl(fd, F_DUPFD_CLOEXEC, 3);
    ::close(fd);
    return moved;
  }

  std::string Take() {
    if (saved_ < 0) return "";
    std::fflush(stderr);
    ::dup2(saved_, 2);
    ::close(saved_);
    saved_ = -1;
    std::string text;
    char buf[4096];
    for (ssize_t n; (n = ::read(read_, buf, sizeof buf)) > 0;) text.append(buf, static_cast<std::size_t>(n));
    ::close(read_);
    return text;
  }

 private:
  int saved_ = -1, read_ = -1;
};

// LCM's lines, one by one, trimmed; empty ones dropped.
std::vector<std::string> LinesOf(const std::string& text) {
  std::vector<std::string> lines;
  for (std::string& line : SplitLines(text)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) lines.push_back(std::move(line));
  }
  return lines;
}

// Runs `call` (an LCM function that may write to stderr) under a
// StderrCapture, one at a time (another's would save this one's pipe as
// stderr); returns LCM's lines.
// One for every capture (a static inside the template would be one per
// call site: two captures at once save each other's pipe as stderr).
std::mutex capture_mu;

template <class Call>
std::vector<std::string> WithLcmStderr(const Call& call) {
  const std::lock_guard lock(capture_mu);
  StderrCapture capture;
  call();
  return LinesOf(capture.Take());
}

// LCM's lines from a call that succeeded: through the process's writer of stderr.
void SayLcmLines(std::vector<std::string> said) {
  if (said.empty()) return;
  for (std::string& line : said) line = "LCM: " + line;
  LogWriter::Stderr().Write(said);
}

// LCM's lines from a call that failed, as the end of its error.
std::string LcmSaid(const std::vector<std::string>& said) {
  std::string why;
  for (const std::string& line : said) why += (why.empty() ? "" : "; ") + line;
  return why.empty() ? "" : ": LCM says: " + EscapeControls(why);
}

}  // namespace

namespace internal {

class LcmCore {
 public:
  explicit LcmCore(const LcmTransportOptions& options)
      : options_(options), url_(LcmTransport::EffectiveUrl(options)) {
    const std::vector<std::string> said =
        WithLcmStderr([&] { lcm_ = lcm_create(url_.empty() ? nullptr : url_.c_str()); });
    if (lcm_ == nullptr) {
      throw TransportError("LcmTransport: LCM could not start on " +
                           (url_.empty() ? std::string("its default URL") : "'" + url_ + "'") +
                           " (bad URL, or no route for its multicast group?)" + LcmSaid(said));
    }
    SayLcmLines(said);
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
  lcm_subscription_t* sub = nullptr;
  const std::vector<std::string> said = WithLcmStderr(
      [&] { sub = lcm_subscribe(impl_->lcm_, channel_regex.c_str(), &OnLcmMessage, entry.get()); });
  if (sub == nullptr) {
    throw TransportError("LcmTransport: cannot subscribe '" + channel_regex + "' on " + url() +
                         LcmSaid(said));
  }
  SayLcmLines(said);
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
