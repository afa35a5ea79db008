// `robotalk-logplay record`: one LCM log of every lane of a RoboTalk URL.
// lcm-logger hears one LCM URL; with the split traffic layout
// (robotalk/traffic_layout.h) requests and replies travel on other ports, so
// the recorder opens the URL with every lane and writes what it hears through
// LCM's own log API, in the file format lcm-logger writes.
#include "logplay.h"

#include "interrupt.h"
#include "robotalk/routed_lcm_transport.h"

#include <lcm/lcm-cpp.hpp>

#include <chrono>
#include <cstdio>
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
  auto sub = transport->Subscribe(
      options.channels, [&](const std::string& channel, std::span<const std::uint8_t> bytes) {
        if (channel == "LCM_SELF_TEST") return;  // each LCM instance's own start-up probe
        lcm::LogEvent event{};
        // Wall-clock microseconds at dispatch (lcm-logger stamps LCM's receive
        // time; the difference is this thread's dispatch delay, microseconds).
        event.timestamp = std::chrono::duration_cast<std::chrono::microseconds>(
                              std::chrono::system_clock::now().time_since_epoch())
                              .count();
        event.channel = channel;
        event.datalen = static_cast<std::int32_t>(bytes.size());
        event.data = const_cast<std::uint8_t*>(bytes.data());  // LCM's API is not const; it only reads
        if (file.writeEvent(&event) != 0) {
          if (write_error.empty()) write_error = "record: writing '" + options.output + "' failed";
          return;
        }
        ++result.events;
        result.bytes += bytes.size();
      });
  progress << "robotalk-logplay: recording " << transport->url()
           << (dynamic_cast<RoutedLcmTransport*>(transport.get()) ? " (every lane of the split layout)" : "")
           << " to " << options.output << "\n";
  const SteadyClock clock;
  const TimePoint start = clock.Now();
  TimePoint last_flush = start;
  while (!cli::Interrupter::Signal() && write_error.empty()) {
    const TimePoint now = clock.Now();
    if (options.duration > Duration(0) && now - start >= options.duration) break;
    Duration wait = std::chrono::milliseconds(100);
    if (options.duration > Duration(0)) wait = std::min<Duration>(wait, options.duration - (now - start));
    transport->HandleFor(wait);
    if (clock.Now() - last_flush >= std::chrono::seconds(1)) {  // a killed recorder loses at most 1 s
      std::fflush(file.getFilePtr());
      last_flush = clock.Now();
    }
  }
  sub.reset();
  std::fflush(file.getFilePtr());
  if (!write_error.empty()) throw LogError(write_error);
  result.signal = cli::Interrupter::Signal();
  return result;
}

}  // namespace robotalk::logplay
