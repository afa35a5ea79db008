#include "robotalk/simulation.h"

#include "robot_service.h"
#include "robotalk/protocol_codec.h"

#include <map>

namespace robotalk {

SimulationResult RunSimulation(std::string robot_name, std::string driver_name,
                               std::unique_ptr<Driver> driver, const std::vector<SimulatedCommand>& commands,
                               const SimulationOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  ManualClock clock;
  RobotService service(std::move(robot_name), std::move(driver_name), std::move(driver), clock);
  const TimePoint t0 = clock.Now();
  constexpr std::int64_t kClient = 1;  // the one, local, client

  // The state stream, then the whole sequence as one delay-mode package.
  const auto header = [&](std::int64_t sequence, std::int8_t payload_type, std::int32_t size) {
    robotalk_msgs::package_header_t h{};
    h.protocol_version = kProtocolVersion;
    h.client_id = kClient;
    h.sequence = sequence;
    h.send_time_us = ToWireMicros(t0);
    h.payload_type = payload_type;
    h.payload_size = size;
    h.mode = robotalk_msgs::package_header_t::MODE_DELAY;
    return h;
  };
  robotalk_msgs::package_t stream{};
  stream.header = header(1, robotalk_msgs::package_header_t::PAYLOAD_QUERIES, 1);
  stream.queries.push_back(
      ToWire(Query{.id = 1, .type = QueryType::kStateStream, .period = options.sample_period}));
  stream.num_queries = 1;
  service.HandlePackage(stream, t0);

  robotalk_msgs::package_t sequence{};
  sequence.header = header(2, robotalk_msgs::package_header_t::PAYLOAD_COMMANDS,
                           static_cast<std::int32_t>(commands.size()));
  for (std::size_t i = 0; i < commands.size(); ++i) {
    Command c = commands[i].command;
    c.id = static_cast<CommandId>(i) + 2;
    c.start_time = t0 + commands[i].offset;
    sequence.commands.push_back(ToWire(c));
  }
  sequence.num_commands = static_cast<std::int32_t>(sequence.commands.size());

  std::map<CommandId, Reply> replies;
  std::vector<OutgoingReplies> outgoing;
  SimulationResult result;
  const auto collect = [&] {
    outgoing.clear();
    service.TakeReplies(outgoing);
    for (auto& o : outgoing) {
      for (auto& r : o.replies) replies[r.id] = std::move(r);
    }
    service.TakeStates(result.states);
  };
  if (!commands.empty()) {
    for (const auto& r : service.HandlePackage(sequence, t0).package.replies) replies[r.id] = FromWire(r);
  }
  // From one deadline to the next (a driver period or a start time), with no
  // sleeping: simulated time runs as fast as the driver can step.
  for (TimePoint now = t0; now <= t0 + options.duration;) {
    const TimePoint next = service.RunOnce(now);
    collect();
    now = std::max(next, now + Duration(1));
    clock.Set(now);
  }
  collect();
  for (std::size_t i = 0; i < commands.size(); ++i) {
    auto it = replies.find(static_cast<CommandId>(i) + 2);
    Reply r;
    if (it != replies.end()) {
      r = it->second;
    } else {
      r.id = static_cast<CommandId>(i) + 2;
      r.signal = Signal::kInterrupted;
      r.message = "still running when the simulation ended";
    }
    result.replies.push_back(std::move(r));
  }
  result.wall_time = std::chrono::steady_clock::now() - wall_start;
  return result;
}

}  // namespace robotalk
