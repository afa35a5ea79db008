#include "robotalk/simulation.h"

#include "daemon_pump.h"
#include "robotalk/config_message.h"
#include "state_encoding.h"

#include <map>

namespace robotalk {

SimulationResult RunSimulation(std::string robot_name, std::string driver_name,
                               std::unique_ptr<Driver> driver, const std::vector<SimulatedCommand>& commands,
                               const SimulationOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  ManualClock clock;
  // The server's own RobotDaemon and session layer, without the transport
  // and without threads: one local client speaking C++ requests.
  RobotDaemon daemon(robot_name, std::move(driver_name), std::move(driver), clock);
  RobotSessions sessions(daemon, ConfigHash(daemon.model()));
  const TimePoint t0 = clock.Now();
  constexpr std::int64_t kClient = 1;

  Request stream{.client_id = kClient, .sequence = 1, .send_time = t0, .mode = RequestMode::kDelay};
  stream.queries.push_back(Query{.id = 1, .type = QueryType::kStateStream, .period = options.sample_period});
  sessions.Handle(stream, t0);

  Request sequence{.client_id = kClient, .sequence = 2, .send_time = t0, .mode = RequestMode::kDelay};
  for (std::size_t i = 0; i < commands.size(); ++i) {
    Command c = commands[i].command;
    c.id = static_cast<CommandId>(i) + 2;
    c.start_time = StartTime::At(t0 + commands[i].offset);
    sequence.commands.push_back(std::move(c));
  }
  std::map<CommandId, Reply> replies;
  if (!commands.empty()) {
    for (Reply& r : sessions.Handle(sequence, t0).batch.replies) replies[r.id] = std::move(r);
  }

  SimulationResult result;
  DaemonOutput output;
  daemon.Preallocate(output);
  std::vector<ReplyBatch> batches;
  const auto collect = [&] {
    PumpOutput(daemon, sessions, output, batches);
    for (std::size_t i = 0; i < output.num_samples; ++i) {
      result.states.push_back(ToStateSample(robot_name, ConfigHash(daemon.model()), output.samples[i]));
    }
    for (ReplyBatch& b : batches) {
      for (Reply& r : b.replies) replies[r.id] = std::move(r);
    }
  };
  // From one deadline to the next (a driver period, a start time, a sample),
  // with no sleeping: simulated time runs as fast as the driver can step.
  for (TimePoint now = t0; now <= t0 + options.duration;) {
    const TimePoint next = daemon.RunOnce(now);
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
