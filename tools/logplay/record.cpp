// `robotalk-logplay record`: one LCM log of every lane of a RoboTalk URL.
// lcm-logger hears one LCM URL; with the split traffic layout
// (robotalk/traffic_layout.h) requests and replies travel on other ports, so
// the recorder opens the URL with every lane and writes what it hears through
// LCM's own log API, in the file format lcm-logger writes: each event stamped
// with LCM's receive time (Transport::ReceiveTime) and written in receipt
// order (ReceiptOrder), not in the order the lanes were dispatched.
#include "logplay.h"

#include "interrupt.h"
#include "receipt_order.h"
#include "robotalk/routed_lcm_transport.h"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ostream>

namespace robotalk::logplay {

RecordResult Record(const RecordOptions& options, std::ostream& progress) {
  lcm::LogFile file(options.output, "w");
  if (!file.good()) throw LogError("record: cannot write '" + options.output + "'");
  // Every lane: a regex the lane rules cannot place is subscribed on all 66.
  const std::unique_ptr<Transport> transport =
      OpenLcmTransport(options.url, OpenLcmOptions{.all_lanes = true});
  RecordResult result;
  std::string write_error;
  // Written in receipt order, stamped with the receive time (ReceiptOrder).
  ReceiptOrder order;
  const auto write = [&](const ReceiptOrder::Event& e) {
    if (!write_error.empty()) return;
    lcm::LogEvent event{};
    event.timestamp = e.received_us;  // as lcm-logger: LCM's receive time
    event.channel = e.channel;
    event.datalen = static_cast<std::int32_t>(e.bytes.size());
    event.data = const_cast<std::uint8_t*>(e.bytes.data());  // LCM's API is not const; it only reads
    errno = 0;  // so that the message names this write's error, not an earlier one
    if (file.writeEvent(&event) != 0) {
      write_error = "record: writing '" + options.output + "' failed: " + std::strerror(errno ? errno : EIO);
      return;
    }
    ++result.events;
    result.bytes += e.bytes.size();
  };
  // The stdio buffer's writes fail here, not in writeEvent (a full disk:
  // "wrote 2 events" and nothing on disk, before this was checked).
  const auto flush = [&] {
    if (!write_error.empty()) return;
    errno = 0;
    if (std::fflush(file.getFilePtr()) != 0 || std::ferror(file.getFilePtr()))
      write_error = "record: writing '" + options.output + "' failed: " + std::strerror(errno ? errno : EIO);
  };
  auto sub = transport->Subscribe(
      options.channels, [&](const std::string& channel, std::span<const std::uint8_t> bytes) {
        if (channel == "LCM_SELF_TEST") return;  // each LCM instance's own start-up probe
        order.Add(transport->ReceiveTime().time_since_epoch().count(), channel, bytes);
      });
  progress << "robotalk-logplay: recording " << transport->url()
           << (transport->traffic_layout() == TrafficLayout::kSplit ? " (every lane of the split layout)"
                                                                    : "")
           << " to " << options.output << "\n";
  const SteadyClock clock;
  const TimePoint start = clock.Now();
  // A killed recorder loses at most 1.25 s (docs/logplay.md): an event is
  // held 0.25 s, released by the first iteration after that (they are at
  // most 0.1 s apart) and on disk at the next flush, at most 0.75 s later
  // (the wait ends when a flush is due): 1.1 s, and time to spare for
  // scheduling. (It flushed every 1 s, checked only after a 0.1 s wait: up
  // to 1.35 s.)
  const Duration flush_period = std::chrono::milliseconds(750);
  TimePoint next_flush = start + flush_period;
  while (!cli::Interrupter::Signal() && write_error.empty()) {
    const TimePoint now = clock.Now();
    if (options.duration > Duration(0) && now - start >= options.duration) break;
    Duration wait = std::clamp<Duration>(next_flush - now, Duration(0), std::chrono::milliseconds(100));
    if (options.duration > Duration(0)) wait = std::min<Duration>(wait, options.duration - (now - start));
    transport->HandleFor(wait);
    order.Release(std::chrono::duration_cast<std::chrono::microseconds>(
                      std::chrono::system_clock::now().time_since_epoch())
                      .count(),
                  write);
    if (clock.Now() >= next_flush) {
      flush();
      next_flush = clock.Now() + flush_period;
    }
  }
  sub.reset();
  order.ReleaseAll(write);
  result.late = order.late();
  result.early = order.early();
  result.early_bytes = order.early_bytes();
  flush();
  if (!write_error.empty()) throw LogError(write_error);
  result.signal = cli::Interrupter::Signal();
  return result;
}

}  // namespace robotalk::logplay
