// robotalk-bench-raw: the raw-LCM floors RoboTalk's figures are compared with
// (docs/performance.md). No RoboTalk code on the path: plain lcm_publish /
// lcm_handle on channels named like RoboTalk's ("ROBOTALK/rawecho/..." has the
// length of "ROBOTALK/pioneer/..."), messages of the same byte size.
//
//   robotalk-bench-raw echo     --url U [--duration S]            the echo server
//   robotalk-bench-raw ping     --url U --count N [--req B --rep B]  sequential round trips (us)
//   robotalk-bench-raw pipe     --url U --inflight K --count M [--cap S]  pipelined echo, msg/s
//   robotalk-bench-raw once     --url U                           open LCM, one round trip, exit
//   robotalk-bench-raw stream   --url U --count N [--period-us P --bytes B --slack-ns S]
//   robotalk-bench-raw watch    --url U --channel C --count N [--period-us P --timeout S]
//   robotalk-bench-raw sessions --url U --robot R --count K --seconds S [--load L ...]
//       K sessions, idle or under an exhaustion load (sessions_bench.cpp)
//   robotalk-bench-raw arrivals --url U --robot R --frames N [--timeout S] [--skip K]
//       the arrival log of a playback sequence at the server's side: each frame's
//       lag (arrival - first arrival - offset) and the hindsight minimum delay
//   robotalk-bench-raw sizes    encoded sizes of a BASE_POSE request and its reply
// Each prints one JSON line on stdout. Every loop is bounded in count and time.
#include "bench_util.h"
#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"
#include "robotalk/traffic_layout.h"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"
#include "robotalk_msgs/robot_state_t.hpp"
#include "sessions_bench.h"

#include <sys/prctl.h>
#include <lcm/lcm-cpp.hpp>

#include <cstring>
#include <map>
#include <random>

using namespace robotalk::bench;

namespace {

const char* kRequest = "ROBOTALK/rawecho/REQUEST";
const char* kState = "ROBOTALK/rawecho/STATE";
std::string ReplyChannelFor(std::uint64_t tag) {
  return std::string("ROBOTALK/rawecho/REPLY/") + robotalk::Hex64(tag);
}

// Request layout: tag (u64) | sequence (i64) | reply size (i32) | padding.
struct Head {
  std::uint64_t tag;
  std::int64_t seq;
  std::int32_t reply_size;
};

int BasePoseRequestSize() {
  robotalk_msgs::package_t p{};
  p.header.payload_type = robotalk_msgs::package_header_t::PAYLOAD_QUERIES;
  p.num_queries = 1;
  p.queries.resize(1);
  p.queries[0].target = "";
  return p.getEncodedSize();
}

int BasePoseReplySize() {
  robotalk_msgs::reply_package_t r{};
  r.num_replies = 1;
  r.replies.resize(1);
  r.replies[0].num_values = 5;
  r.replies[0].values.assign(5, 0.0);
  return r.getEncodedSize();
}

void CheckGood(lcm::LCM& lcm, const Args& a) {
  if (!lcm.good()) throw std::runtime_error("cannot open LCM '" + a.Str("url", "") + "'");
}

// Answers each request with a message of the size it asks for, on the
// requester's own reply channel (as the server answers on REPLY/<client>).
class Echoer {
 public:
  explicit Echoer(lcm::LCM& lcm) : lcm_(lcm), out_(65000, 0) {
    lcm_.subscribe(kRequest, &Echoer::OnRequest, this)->setQueueCapacity(10000);
  }
  std::int64_t echoed() const { return echoed_; }

 private:
  void OnRequest(const lcm::ReceiveBuffer* rb, const std::string&) {
    if (rb->data_size < sizeof(Head)) return;
    Head h;
    std::memcpy(&h, rb->data, sizeof h);
    const auto n = static_cast<std::size_t>(std::clamp<std::int32_t>(h.reply_size, sizeof(Head), 65000));
    std::memcpy(out_.data(), &h, sizeof h);
    lcm_.publish(ReplyChannelFor(h.tag), out_.data(), static_cast<unsigned>(n));
    ++echoed_;
  }
  lcm::LCM& lcm_;
  std::vector<std::uint8_t> out_;
  std::int64_t echoed_ = 0;
};

int Echo(const Args& a) {
  lcm::LCM lcm(a.Str("url", ""));
  CheckGood(lcm, a);
  Echoer echo(lcm);
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("duration", 3600) * 1e9);
  while (MonoNs() < end) lcm.handleTimeout(200);
  PrintJson({Field("echoed", static_cast<double>(echo.echoed()))});
  return 0;
}

// A client of the echo server: publishes requests and counts replies by sequence.
class Pinger {
 public:
  Pinger(lcm::LCM& lcm, int req, int rep) : lcm_(lcm), req_(static_cast<std::size_t>(req)) {
    std::random_device rd;
    tag_ = (std::uint64_t{rd()} << 32) | rd();
    head_ = {tag_, 0, rep};
    lcm_.subscribe(ReplyChannelFor(tag_), &Pinger::OnReply, this)->setQueueCapacity(10000);
    buf_.assign(std::max(req_, sizeof(Head)), 0);
  }
  std::int64_t Send() {
    ++head_.seq;
    std::memcpy(buf_.data(), &head_, sizeof head_);
    lcm_.publish(kRequest, buf_.data(), static_cast<unsigned>(buf_.size()));
    return head_.seq;
  }
  std::int64_t last_reply() const { return last_; }
  std::int64_t replies() const { return replies_; }

 private:
  void OnReply(const lcm::ReceiveBuffer* rb, const std::string&) {
    if (rb->data_size < sizeof(Head)) return;
    Head h;
    std::memcpy(&h, rb->data, sizeof h);
    last_ = h.seq;
    ++replies_;
  }
  lcm::LCM& lcm_;
  std::size_t req_;
  std::uint64_t tag_ = 0;
  Head head_{};
  std::vector<std::uint8_t> buf_;
  std::int64_t last_ = 0, replies_ = 0;
};

// Waits (bounded) until the reply to `seq` arrived; false on time-out.
bool AwaitReply(lcm::LCM& lcm, const Pinger& p, std::int64_t seq, double timeout_s) {
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(timeout_s * 1e9);
  while (p.last_reply() < seq) {
    const std::int64_t left_ms = (end - MonoNs()) / 1000000;
    if (left_ms <= 0) return false;
    lcm.handleTimeout(static_cast<int>(std::min<std::int64_t>(left_ms, 100)) + 1);
  }
  return true;
}

int Ping(const Args& a) {
  lcm::LCM lcm(a.Str("url", ""));
  CheckGood(lcm, a);
  const int req = static_cast<int>(a.Int("req", BasePoseRequestSize()));
  const int rep = static_cast<int>(a.Int("rep", BasePoseReplySize()));
  Pinger p(lcm, req, rep);
  const long count = a.Int("count", 1000), warmup = a.Int("warmup", 50);
  std::vector<double> rtt_us;
  long lost = 0;
  for (long i = 0; i < count + warmup; ++i) {
    const std::int64_t t0 = MonoNs();
    const bool ok = AwaitReply(lcm, p, p.Send(), 1.0);
    const std::int64_t t1 = MonoNs();
    if (!ok) ++lost;
    if (ok && i >= warmup) rtt_us.push_back(static_cast<double>(t1 - t0) / 1e3);
    if (a.Int("gap-us", 0) > 0) SleepUntilNs(t1 + a.Int("gap-us", 0) * 1000);
  }
  PrintJson({Summary("rtt_us", rtt_us), Field("lost", static_cast<double>(lost)), Field("req_bytes", req),
             Field("rep_bytes", rep)});
  return 0;
}

int Pipe(const Args& a) {
  lcm::LCM lcm(a.Str("url", ""));
  CheckGood(lcm, a);
  Pinger p(lcm, static_cast<int>(a.Int("req", 128)), static_cast<int>(a.Int("rep", 128)));
  const long inflight = a.Int("inflight", 100), count = a.Int("count", 20000);
  const std::int64_t t0 = MonoNs(), cap = t0 + static_cast<std::int64_t>(a.Num("cap", 60) * 1e9);
  long sent = 0;
  std::int64_t last_progress = t0, seen = 0;
  while (p.replies() < count && MonoNs() < cap) {
    while (sent < count && sent - p.replies() < inflight) {
      p.Send();
      ++sent;
    }
    lcm.handleTimeout(50);
    if (p.replies() != seen) {
      seen = p.replies();
      last_progress = MonoNs();
    } else if (MonoNs() - last_progress > 500000000) {
      sent = p.replies();  // raw UDP has no retransmission: refill a stalled window
      last_progress = MonoNs();
    }
  }
  const double secs = static_cast<double>(MonoNs() - t0) / 1e9;
  PrintJson({Field("per_s", static_cast<double>(p.replies()) / secs),
             Field("done", static_cast<double>(p.replies())), Field("seconds", secs),
             Field("timed_out", p.replies() < count ? 1 : 0)});
  return 0;
}

int Once(const Args& a) {
  lcm::LCM lcm(a.Str("url", ""));
  CheckGood(lcm, a);
  Pinger p(lcm, BasePoseRequestSize(), BasePoseReplySize());
  return AwaitReply(lcm, p, p.Send(), 2.0) ? 0 : 1;
}

int Stream(const Args& a) {
  if (a.Int("slack-ns", 0) > 0) prctl(PR_SET_TIMERSLACK, static_cast<unsigned long>(a.Int("slack-ns", 0)));
  lcm::LCM lcm(a.Str("url", ""));
  CheckGood(lcm, a);
  const long count = a.Int("count", 2000), period_ns = a.Int("period-us", 1000) * 1000;
  std::vector<std::uint8_t> buf(static_cast<std::size_t>(a.Int("bytes", 400)), 0);
  std::int64_t next = MonoNs() + 100000000;
  for (long i = 0; i < count; ++i) {
    SleepUntilNs(next);
    std::memcpy(buf.data(), &i, sizeof i);
    lcm.publish(kState, buf.data(), static_cast<unsigned>(buf.size()));
    next += period_ns;
  }
  PrintJson({Field("published", static_cast<double>(count))});
  return 0;
}

int Watch(const Args& a) {
  lcm::LCM lcm(a.Str("url", ""));
  CheckGood(lcm, a);
  const long count = a.Int("count", 2000);
  const double period_us = a.Num("period-us", 1000);
  std::vector<std::int64_t> arrivals;
  arrivals.reserve(static_cast<std::size_t>(count));
  lcm.subscribeFunction(
         a.Str("channel", kState),
         +[](const lcm::ReceiveBuffer*, const std::string&, std::vector<std::int64_t>* v) {
           v->push_back(MonoNs());
         },
         &arrivals)
      ->setQueueCapacity(10000);
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("timeout", 30) * 1e9);
  while (static_cast<long>(arrivals.size()) < count && MonoNs() < end) lcm.handleTimeout(100);
  std::vector<double> gap, dev;
  for (std::size_t i = 1; i < arrivals.size(); ++i) {
    gap.push_back(static_cast<double>(arrivals[i] - arrivals[i - 1]) / 1e3);
    dev.push_back(std::abs(gap.back() - period_us));
  }
  PrintJson({Summary("interarrival_us", gap), Summary("deviation_us", dev),
             Field("received", static_cast<double>(arrivals.size()))});
  return 0;
}

// The LCM URL that carries a RoboTalk server's `channel` for RoboTalk URL
// `url`: its lane in the split traffic layout, or the one URL.
std::string UrlOfChannel(const std::string& url, const std::string& channel) {
  const robotalk::TrafficUrl t = robotalk::ParseTrafficUrl(robotalk::ResolveLcmUrl(url));
  if (t.layout == robotalk::TrafficLayout::kSingle) return t.lcm_url;
  return robotalk::LaneUrl(t.lcm_url, robotalk::LaneOfChannel(channel));
}

// Logs the first arrival of every playback frame on the robot's REQUEST
// channel (a retransmission repeats the command id and is not counted).
class ArrivalLog {
 public:
  void On(const lcm::ReceiveBuffer*, const std::string&, const robotalk_msgs::package_t* p) {
    const std::int64_t now = MonoNs();
    if (p->header.mode != robotalk_msgs::package_header_t::MODE_PLAYBACK) return;
    for (const auto& c : p->commands) {
      if (seen_.count(c.id)) continue;
      seen_[c.id] = true;
      if (static_cast<long>(seen_.size()) <= skip) continue;  // a warm-up sequence's frame
      arrival_ns.push_back(now);
      offset_us.push_back(c.start_time_us);
      send_us.push_back(p->header.send_time_us);
    }
  }
  std::vector<std::int64_t> arrival_ns, offset_us, send_us;
  long skip = 0;  ///< the first `skip` frames are not logged

 private:
  std::map<std::int64_t, bool> seen_;
};

int Arrivals(const Args& a) {
  const std::string channel = robotalk::RequestChannel(a.Str("robot", "pioneer"));
  lcm::LCM lcm(UrlOfChannel(a.Str("url", ""), channel));
  CheckGood(lcm, a);
  ArrivalLog log;
  log.skip = a.Int("skip", 0);
  lcm.subscribe(channel, &ArrivalLog::On, &log)->setQueueCapacity(10000);
  const long frames = a.Int("frames", 40);
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("timeout", 60) * 1e9);
  while (static_cast<long>(log.arrival_ns.size()) < frames && MonoNs() < end) lcm.handleTimeout(100);
  std::int64_t first = log.arrival_ns.empty() ? 0 : log.arrival_ns.front();
  for (std::int64_t t : log.arrival_ns) first = std::min(first, t);
  std::vector<double> lags, transits, offsets;
  double worst = 0;
  for (std::size_t i = 0; i < log.arrival_ns.size(); ++i) {
    const double lag =
        static_cast<double>(log.arrival_ns[i] - first) / 1e6 - static_cast<double>(log.offset_us[i]) / 1e3;
    worst = std::max(worst, lag);
    lags.push_back(std::round(lag * 1e3) / 1e3);
    // arrival - the client's send time (ms, the clocks' offset included): a retransmission
    // carries its first copy's send time, so its resend wait shows here.
    transits.push_back(std::round(static_cast<double>(log.arrival_ns[i] / 1000 - log.send_us[i])) / 1e3);
    offsets.push_back(static_cast<double>(log.offset_us[i]) / 1e3);
  }
  PrintJson({Field("frames", static_cast<double>(log.arrival_ns.size())),
             Field("hindsight_min_s", worst / 1e3), Field("lag_ms", lags), Field("transit_ms", transits),
             Field("offset_ms", offsets)});
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: %s echo|ping|pipe|once|stream|watch|sessions|arrivals|sizes [--key value ...]\n",
                 argv[0]);
    return 2;
  }
  try {
    const std::string cmd = argv[1];
    const Args a(argc, argv, 2);
    if (cmd == "echo") return Echo(a);
    if (cmd == "ping") return Ping(a);
    if (cmd == "pipe") return Pipe(a);
    if (cmd == "once") return Once(a);
    if (cmd == "stream") return Stream(a);
    if (cmd == "watch") return Watch(a);
    if (cmd == "sessions") return Sessions(a);
    if (cmd == "arrivals") return Arrivals(a);
    if (cmd == "sizes") {
      PrintJson(
          {Field("base_pose_request", BasePoseRequestSize()), Field("base_pose_reply", BasePoseReplySize())});
      return 0;
    }
    std::fprintf(stderr, "robotalk-bench-raw: unknown sub-command '%s'\n", cmd.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-bench-raw: %s\n", e.what());
    return 1;
  }
}
