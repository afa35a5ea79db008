// RobotClient in Python (docs/python.md): the C++ client (robot_client.h)
// with every blocking wait done with the GIL released and Ctrl-C honoured.
//
// The GIL: the ReadDaemon is a C++ thread that never touches Python, so it
// never waits for the GIL. A blocking call releases the GIL while it waits
// (WaitInterruptibly), waking every 50 ms to run Python's signal handlers; a
// reply wakes it at once. A KeyboardInterrupt during a blocking motion
// command or a sequence sends STOP (and waits for its reply) before it is
// raised, with a note saying so: the robot is never left moving because
// Python was interrupted. The state stream reaches Python through a
// StateQueue (state_queue.h), never by calling Python on the ReadDaemon.
#include "bindings.h"
#include "py_errors.h"
#include "robotalk/log_writer.h"  // EscapeControls
#include "robotalk/sequence_file.h"
#include "state_queue.h"

#include <pybind11/stl.h>

#include <future>
#include <memory>
#include <stop_token>
#include <thread>

namespace robotalk::python {
namespace {

const char* SourceName(TrustedServer::Source s) {
  switch (s) {
    case TrustedServer::Source::kNone:
      return "none";
    case TrustedServer::Source::kExplicit:
      return "explicit";
    case TrustedServer::Source::kPinned:
      return "pinned";
    case TrustedServer::Source::kPinnedNow:
      return "pinned_now";
  }
  return "?";
}

QueryType ParseQuery(const std::string& name) {
  if (auto t = ParseQueryType(name)) return *t;
  throw UsageError("unknown query type '" + name +
                   "' (JOINT_STATE, LINK_POSES, FRAME_POSES, BASE_POSE, CONFIG, CLOCK, COMMAND_STATUS, "
                   "SERVER_COUNTERS)");
}

CommandMode ParseMode(const std::string& name, const char* what) {
  if (auto m = ParseCommandMode(name)) return *m;
  throw UsageError(std::string(what) + ": unknown mode '" + name + "' (direct, delay, playback)");
}

std::optional<TimePoint> Start(std::optional<double> start) {
  if (!start) return std::nullopt;
  return ToTimePoint(*start, "start");
}

// Adds a note to the Python exception being raised (Python 3.11+).
void AddNote(const py::error_already_set& e, const std::string& note) {
  if (e.value() && py::hasattr(e.value(), "add_note")) e.value().attr("add_note")(note);
}

class PyRobotClient {
 public:
  explicit PyRobotClient(ClientOptions options) {
    py::gil_scoped_release release;
    client_ = std::make_shared<RobotClient>(std::move(options));
  }
  ~PyRobotClient() { Close(); }

  // The client for one call; it stays alive for the call even if another
  // thread closes this object meanwhile. Throws ClientError once closed.
  std::shared_ptr<RobotClient> Client(const char* call) const {
    if (!client_) throw ClientError(std::string("RobotClient.") + call + ": the client is closed");
    return client_;
  }

  void Close() {
    if (queue_) queue_->Close();
    std::shared_ptr<RobotClient> last = std::move(client_);
    py::gil_scoped_release release;  // the ReadDaemon joins; it never needs the GIL
    last.reset();
  }
  bool closed() const { return !client_; }

  void Connect(const std::string& robot) {
    auto c = Client("connect");
    py::gil_scoped_release release;
    c->Connect(robot);
  }

  // Sends `command` and waits for its final reply as RobotClient::Execute
  // does, interruptibly; a KeyboardInterrupt during a motion command sends STOP.
  Reply Execute(Command command, const char* call = "execute") {
    auto c = Client(call);
    Duration wait = c->options().timeout;
    if (auto at = command.start_time.time()) wait += std::max(Duration::zero(), *at - c->ServerNow());
    const bool motion = IsMotionCommand(command.type);
    const std::string what = Describe(command);
    PendingReply pending = [&] {
      py::gil_scoped_release release;
      return c->Send(std::move(command));
    }();
    try {
      if (auto r = WaitInterruptibly(pending, wait)) return *r;
    } catch (py::error_already_set& e) {
      if (motion) StopAfterInterrupt(*c, &e);
      throw;
    }
    throw NoReply(what, pending.id(), wait);
  }

  py::object Run(Command command, bool wait, const char* call = "execute") {
    if (wait) return py::cast(Execute(std::move(command), call));
    auto c = Client(call);
    const std::string what = Describe(command);
    PendingReply p = [&] {
      py::gil_scoped_release release;
      return c->Send(std::move(command));
    }();
    return py::cast(std::make_unique<PyPendingReply>(std::move(p), what));
  }

  py::object RunQuery(Query query, bool wait) {
    auto c = Client("query");
    const std::string what = std::string("query ") + ToString(query.type) +
                             (query.target.empty() ? "" : " '" + query.target + "'");
    PendingReply p = [&] {
      py::gil_scoped_release release;
      return c->SendQuery(std::move(query));
    }();
    if (!wait) return py::cast(std::make_unique<PyPendingReply>(std::move(p), what));
    const Duration timeout = c->options().timeout;
    if (auto r = WaitInterruptibly(p, timeout)) return py::cast(*r);
    throw NoReply(what, p.id(), timeout);
  }

  // A query's values; SignalError unless it succeeded.
  py::array_t<double> QueryValues(const std::string& type, const std::string& target) {
    const QueryType t = ParseQuery(type);
    Reply r = RunQuery(Query{.type = t, .target = target}, true).cast<Reply>();
    if (!Succeeded(r.signal)) {
      // Its text escaped (a traceback prints it); the reply keeps the server's.
      ThrowSignalError(
          EscapeControls(std::string(ToString(t)) + (target.empty() ? "" : " '" + target + "'") + ": " +
                         std::string(ToString(r.signal)) + (r.message.empty() ? "" : ": " + r.message)),
          py::cast(r));
    }
    return ToArray(r.values);
  }

  std::vector<std::unique_ptr<PyPendingReply>> SendBatch(std::vector<Command> commands,
                                                         const std::string& mode) {
    auto c = Client("send_batch");
    std::vector<std::string> what;
    for (const Command& x : commands) what.push_back(Describe(x));
    std::vector<PendingReply> sent = [&] {
      py::gil_scoped_release release;
      return c->SendBatch(std::move(commands), ParseMode(mode, "send_batch"));
    }();
    std::vector<std::unique_ptr<PyPendingReply>> out;
    for (std::size_t i = 0; i < sent.size(); ++i)
      out.push_back(std::make_unique<PyPendingReply>(std::move(sent[i]), what[i]));
    return out;
  }

  // RunSequence on a worker thread; this (Python's) thread waits with the GIL
  // released, waking every 50 ms for signals. Callbacks run on the worker
  // (holding the GIL). An interrupt or a callback's exception stops the
  // sequence and sends STOP, then is raised.
  SequenceResult RunSequence(std::vector<TimedCommand> frames, SequenceOptions options, py::object on_reply,
                             py::object on_progress, bool wait_until_given_up, bool collect_unknown) {
    auto c = Client("run_sequence");
    std::stop_source stop;
    std::exception_ptr callback_error;  // set by the worker, holding the GIL
    SequenceHooks hooks;
    hooks.stop = stop.get_token();
    hooks.wait_until_given_up = wait_until_given_up;
    hooks.collect_unknown_outcomes = collect_unknown;
    if (!on_reply.is_none()) {
      hooks.on_reply = [&](std::size_t index, const Reply& reply) {
        py::gil_scoped_acquire acquire;
        if (callback_error) return;
        try {
          on_reply(index, reply);
        } catch (...) {
          callback_error = std::current_exception();
          stop.request_stop();
        }
      };
    }
    if (!on_progress.is_none()) {
      hooks.on_progress = [&](const SequenceProgress& p) {
        py::gil_scoped_acquire acquire;
        if (callback_error) return;
        try {
          on_progress(p.answered, p.total, Seconds(p.elapsed), Seconds(p.duration));
        } catch (...) {
          callback_error = std::current_exception();
          stop.request_stop();
        }
      };
    }
    std::promise<SequenceResult> promise;
    std::future<SequenceResult> done = promise.get_future();
    std::thread worker([&] {
      try {
        promise.set_value(c->RunSequence(std::move(frames), options, hooks));
      } catch (...) {
        promise.set_exception(std::current_exception());
      }
    });
    std::exception_ptr interrupted;
    for (;;) {
      std::future_status status;
      {
        py::gil_scoped_release release;
        status = done.wait_for(kSignalCheckInterval);
      }
      if (status == std::future_status::ready) break;
      if (!interrupted && PyErr_CheckSignals() != 0) {
        try {
          throw py::error_already_set();
        } catch (...) {
          interrupted = std::current_exception();
        }
        stop.request_stop();
      }
    }
    {
      py::gil_scoped_release release;
      worker.join();
    }
    std::exception_ptr raised = interrupted ? interrupted : callback_error;
    if (raised) {
      try {
        std::rethrow_exception(raised);
      } catch (py::error_already_set& e) {
        StopAfterInterrupt(*c, &e);
        throw;
      } catch (...) {
        StopAfterInterrupt(*c, nullptr);
        throw;
      }
    }
    return done.get();
  }

  // Starts the state stream into a new queue (closing the previous one).
  py::tuple StartStream(py::object period, std::size_t capacity) {
    if (capacity < 1) throw UsageError("state_stream: queue_size must be at least 1");
    auto c = Client("state_stream");
    const Duration p = ToDuration(period, "state_stream period");
    auto queue = std::make_shared<StateQueue>(capacity);
    if (queue_) queue_->Close();
    queue_ = queue;
    Duration actual{};
    {
      py::gil_scoped_release release;
      // The ReadDaemon's callback: a copy into the queue, never Python.
      actual = c->StartStateStream(p, [queue](const StateSample& s) { queue->Push(s); });
    }
    return py::make_tuple(queue, Seconds(actual));
  }
  void StopStream() {
    if (queue_) queue_->Close();
    auto c = Client("stop_state_stream");
    py::gil_scoped_release release;
    c->StopStateStream();
  }

 private:
  // STOP after a Python exception interrupted a motion: sent and waited for
  // (GIL released, at most the client's timeout); the outcome is added to
  // the exception as a note.
  static void StopAfterInterrupt(RobotClient& c, const py::error_already_set* e) {
    std::string note;
    try {
      Reply r;
      {
        py::gil_scoped_release release;
        r = c.Stop();
      }
      note = "robotalk: sent STOP to '" + c.robot() +
             "' after the interrupt: " + std::string(ToString(r.signal));
    } catch (const std::exception& x) {
      note = std::string("robotalk: STOP after the interrupt failed: ") + x.what();
    }
    if (e) AddNote(*e, note);
  }

  std::shared_ptr<RobotClient> client_;
  std::shared_ptr<StateQueue> queue_;
};

ClientOptions MakeOptions(std::optional<std::string> url, std::optional<std::string> key,
                          std::optional<std::string> server_key, std::optional<std::string> known_servers,
                          py::object timeout, py::object connect_timeout, std::int64_t client_id) {
  ClientOptions o;
  o.lcm_url = url.value_or("");
  o.key_file = key.value_or("");
  o.server_key_file = server_key.value_or("");
  o.known_servers_file = known_servers.value_or("");
  o.timeout = ToNonNegativeDuration(timeout, "timeout");
  o.connect_timeout = ToNonNegativeDuration(connect_timeout, "connect_timeout");
  o.client_id = client_id;
  return o;
}

}  // namespace

void BindClient(py::module_& m) {
  py::class_<StateQueue, std::shared_ptr<StateQueue>>(
      m, "_StateQueue", "The bounded queue between the ReadDaemon and Python (state_queue.h).")
      .def(
          "get",
          [](StateQueue& q, py::object timeout) -> std::optional<StateSample> {
            // In slices, so that Ctrl-C reaches a main thread iterating the stream.
            return WaitInSlices<StateSample>(
                timeout.is_none() ? std::nullopt
                                  : std::optional<Duration>(ToNonNegativeDuration(timeout, "get")),
                [&](Duration slice) { return q.Pop(slice); }, [&] { return q.closed(); });
          },
          py::arg("timeout") = py::none())
      .def("close", &StateQueue::Close)
      .def_property_readonly("closed", &StateQueue::closed)
      .def_property_readonly("dropped", &StateQueue::dropped)
      .def_property_readonly("received", &StateQueue::received)
      .def_property_readonly("capacity", &StateQueue::capacity)
      .def("__len__", &StateQueue::size);

  py::class_<PyRobotClient>(
      m, "_RobotClient",
      "The C++ RobotClient (robotalk/robot_client.h); robotalk.RobotClient adds the Python layer.")
      .def(py::init([](std::optional<std::string> url, std::optional<std::string> key,
                       std::optional<std::string> server_key, std::optional<std::string> known_servers,
                       py::object timeout, py::object connect_timeout, std::int64_t client_id) {
             return std::make_unique<PyRobotClient>(
                 MakeOptions(url, key, server_key, known_servers, timeout, connect_timeout, client_id));
           }),
           py::arg("url") = py::none(), py::kw_only(), py::arg("key") = py::none(),
           py::arg("server_key") = py::none(), py::arg("known_servers") = py::none(),
           py::arg("timeout") = 5.0, py::arg("connect_timeout") = 5.0, py::arg("client_id") = 0)
      .def("connect", &PyRobotClient::Connect, py::arg("robot"),
           "Connects to `robot`: clock sync and its configuration. Raises TimeoutError when no\n"
           "server offers it within connect_timeout, ClientError when already connected.")
      .def("close", &PyRobotClient::Close,
           "Stops the client (its ReadDaemon) and the state stream. Sends nothing: a moving robot\n"
           "is stopped by the server's watchdog. Idempotent.")
      .def_property_readonly("closed", &PyRobotClient::closed)
      .def_property_readonly(
          "connected",
          [](const PyRobotClient& p) { return !p.closed() && p.Client("connected")->connected(); })
      .def_property_readonly("robot", [](const PyRobotClient& p) { return p.Client("robot")->robot(); })
      .def_property_readonly("client_id",
                             [](const PyRobotClient& p) { return p.Client("client_id")->client_id(); })
      .def_property_readonly(
          "model",
          [](const PyRobotClient& p) { return std::make_shared<RobotModel>(p.Client("model")->model()); },
          "The connected robot's description (a RobotModel).")
      .def(
          "reload_model",
          [](PyRobotClient& p) {
            auto c = p.Client("reload_model");
            py::gil_scoped_release release;
            return std::make_shared<RobotModel>(c->ReloadModel());
          },
          "Reads the configuration again (CONFIG query) and returns it.")
      .def(
          "server_now", [](const PyRobotClient& p) { return Seconds(p.Client("server_now")->ServerNow()); },
          "The server clock now (estimated), seconds: add a delay for a command's `start`.")
      .def_property_readonly(
          "clock_offset",
          [](const PyRobotClient& p) { return Seconds(p.Client("clock_offset")->clock_offset()); },
          "server - client clock, s.")
      .def_property_readonly(
          "clock_round_trip",
          [](const PyRobotClient& p) { return Seconds(p.Client("clock_round_trip")->clock_round_trip()); },
          "Round trip of the clock sample in use, s.")
      .def(
          "sync_clock",
          [](PyRobotClient& p, int rounds) {
            auto c = p.Client("sync_clock");
            py::gil_scoped_release release;
            c->SyncClock(rounds);
          },
          py::arg("rounds") = 8, "Runs more CLOCK round trips (keeps the best sample overall).")
      .def(
          "execute", [](PyRobotClient& p, Command c, bool wait) { return p.Run(std::move(c), wait); },
          py::arg("command"), py::kw_only(), py::arg("wait") = true,
          "Sends a Command; wait=True blocks for its final Reply, wait=False returns a PendingReply.")
      .def(
          "query",
          [](PyRobotClient& p, const std::string& type, const std::string& target, bool wait) {
            return p.RunQuery(Query{.type = ParseQuery(type), .target = target}, wait);
          },
          py::arg("type"), py::arg("target") = "", py::kw_only(), py::arg("wait") = true,
          "A query ('JOINT_STATE', 'LINK_POSES', 'FRAME_POSES', 'BASE_POSE', 'CLOCK', 'CONFIG',\n"
          "'SERVER_COUNTERS'); the Reply (or a PendingReply with wait=False).")
      .def("_query_values", &PyRobotClient::QueryValues, py::arg("type"), py::arg("target") = "")
      .def(
          "command_status",
          [](PyRobotClient& p, CommandId id) {
            return p.RunQuery(Query{.type = QueryType::kCommandStatus, .about = id}, true);
          },
          py::arg("id"),
          "What became of command `id` of this session: its final reply once it ended, BUSY while\n"
          "it waits or runs, NA when the session never received it.")
      .def(
          "server_counters",
          [](PyRobotClient& p) { return p.RunQuery(Query{.type = QueryType::kServerCounters}, true); },
          "The server's refusal counters (values; the message names them).")
      .def(
          "send_trajectory",
          [](PyRobotClient& p, const std::string& target, std::vector<double> times,
             std::vector<std::vector<double>> positions,
             std::optional<std::vector<std::vector<double>>> velocities,
             std::optional<std::vector<std::vector<double>>> accelerations, const std::string& interpolation,
             const std::string& mode, std::optional<double> start, py::object delay, bool frame) {
            auto c = p.Client("send_trajectory");
            const auto kind = ParseInterpolation(interpolation);
            if (!kind) {
              throw UsageError("send_trajectory: unknown interpolation '" + interpolation +
                               "' (step, linear, cubic, quintic)");
            }
            const auto rows = [&](const std::optional<std::vector<std::vector<double>>>& v,
                                  const char* what) {
              if (v && v->size() != times.size()) {
                throw UsageError(std::string("send_trajectory: ") + what + " has " +
                                 std::to_string(v->size()) + " rows for " + std::to_string(times.size()) +
                                 " times");
              }
            };
            if (positions.size() != times.size()) {
              throw UsageError("send_trajectory: positions has " + std::to_string(positions.size()) +
                               " rows for " + std::to_string(times.size()) + " times");
            }
            rows(velocities, "velocities");
            rows(accelerations, "accelerations");
            std::vector<TrajectoryPoint> points;
            for (std::size_t i = 0; i < times.size(); ++i) {
              points.push_back(TrajectoryPoint{
                  .time_from_start = ToDuration(
                      py::float_(times[i]), ("send_trajectory: times[" + std::to_string(i) + "]").c_str()),
                  .positions = positions[i],
                  .velocities = velocities ? (*velocities)[i] : std::vector<double>{},
                  .accelerations = accelerations ? (*accelerations)[i] : std::vector<double>{}});
            }
            const TrajectoryOptions options{.mode = ParseMode(mode, "send_trajectory"),
                                            .interpolation = *kind,
                                            .start = Start(start),
                                            .delay = ToNonNegativeDuration(delay, "delay")};
            std::vector<PendingReply> sent;
            {
              py::gil_scoped_release release;
              sent = frame ? c->SendTrajectory(FrameTrajectory{target, std::move(points)}, options)
                           : c->SendTrajectory(JointTrajectory{target, std::move(points)}, options);
            }
            std::vector<std::unique_ptr<PyPendingReply>> out;
            for (std::size_t i = 0; i < sent.size(); ++i) {
              out.push_back(std::make_unique<PyPendingReply>(
                  std::move(sent[i]), std::string(frame ? "FRAME_SETPOINT '" : "JOINT_SETPOINT '") + target +
                                          "' point " + std::to_string(i)));
            }
            return out;
          },
          py::arg("target"), py::arg("times"), py::arg("positions"), py::kw_only(),
          py::arg("velocities") = py::none(), py::arg("accelerations") = py::none(),
          py::arg("interpolation") = "cubic", py::arg("mode") = "delay", py::arg("start") = py::none(),
          py::arg("delay") = 0.1, py::arg("frame") = false,
          "A trajectory (issue 22): a joint's (or, frame=True, a control frame's) points at `times`\n"
          "(seconds from its start), one row of positions each (a frame: x y z qw qx qy qz),\n"
          "optional velocity and acceleration rows; the server interpolates ('step', 'linear',\n"
          "'cubic', 'quintic') and splices a newer one in. 'delay' mode starts at `start` (server\n"
          "time) or `delay` s from now; 'playback' lets the server choose. A PendingReply per point,\n"
          "answered when the trajectory passes it (docs/protocol.md, Trajectories).")
      .def("send_batch", &PyRobotClient::SendBatch, py::arg("commands"), py::arg("mode") = "direct",
           "Several commands in ONE package ('direct', or 'delay' for commands stamped ahead);\n"
           "a PendingReply each.")
      .def(
          "panic",
          [](PyRobotClient& p) {
            auto c = p.Client("panic");
            py::gil_scoped_release release;
            c->Panic();
          },
          "Panic: every command of every client is refused (PANIC) until reset_panic().\n"
          "Raises TimeoutError when unanswered, PanicRefusedError when the server refused it.")
      .def(
          "reset_panic",
          [](PyRobotClient& p) {
            return p.Execute(Command{.type = CommandType::kPanicReset}, "reset_panic");
          },
          "PANIC_RESET; its Reply.")
      .def(
          "set_joint",
          [](PyRobotClient& p, const std::string& joint, py::handle v, std::optional<double> start,
             bool wait) {
            return p.Run(Command{.type = CommandType::kJointSetPoint,
                                 .start_time = Start(start),
                                 .target = joint,
                                 .values = ToValues(v, "set_joint positions")},
                         wait, "set_joint");
          },
          py::arg("joint"), py::arg("positions"), py::arg("start") = py::none(), py::kw_only(),
          py::arg("wait") = true, "JOINT_SETPOINT: one position per dof of `joint` (rad | m).")
      .def(
          "joint_speed",
          [](PyRobotClient& p, const std::string& joint, py::handle v, std::optional<double> start,
             bool wait) {
            return p.Run(Command{.type = CommandType::kJointSpeed,
                                 .start_time = Start(start),
                                 .target = joint,
                                 .values = ToValues(v, "joint_speed velocities")},
                         wait, "joint_speed");
          },
          py::arg("joint"), py::arg("velocities"), py::arg("start") = py::none(), py::kw_only(),
          py::arg("wait") = true, "JOINT_SPEED: one velocity per dof (rad/s | m/s).")
      .def(
          "joint_force",
          [](PyRobotClient& p, const std::string& joint, py::handle v, std::optional<double> start,
             bool wait) {
            return p.Run(Command{.type = CommandType::kJointForce,
                                 .start_time = Start(start),
                                 .target = joint,
                                 .values = ToValues(v, "joint_force efforts")},
                         wait, "joint_force");
          },
          py::arg("joint"), py::arg("efforts"), py::arg("start") = py::none(), py::kw_only(),
          py::arg("wait") = true, "JOINT_FORCE: one effort per dof (N m | N).")
      .def(
          "frame_setpoint",
          [](PyRobotClient& p, const std::string& frame, py::handle pose, std::optional<double> start,
             bool wait) {
            return p.Run(Command{.type = CommandType::kFrameSetPoint,
                                 .start_time = Start(start),
                                 .target = frame,
                                 .values = ToValues(pose, "frame_setpoint pose")},
                         wait, "frame_setpoint");
          },
          py::arg("frame"), py::arg("pose"), py::arg("start") = py::none(), py::kw_only(),
          py::arg("wait") = true, "FRAME_SETPOINT: a control frame's world pose x y z qw qx qy qz.")
      .def(
          "goto",
          [](PyRobotClient& p, double x, double y, double theta, std::optional<double> start, bool wait) {
            return p.Run(
                Command{.type = CommandType::kGoto, .start_time = Start(start), .values = {x, y, theta}},
                wait, "goto");
          },
          py::arg("x"), py::arg("y"), py::arg("theta"), py::arg("start") = py::none(), py::kw_only(),
          py::arg("wait") = true,
          "GOTO: drive the base to (x, y, theta) in the world (m, m, rad); the Reply comes when it\n"
          "arrives. Ctrl-C while it waits sends STOP, then raises KeyboardInterrupt.")
      .def(
          "set_speed",
          [](PyRobotClient& p, double v, double omega, std::optional<double> start, bool wait) {
            return p.Run(
                Command{.type = CommandType::kSetSpeed, .start_time = Start(start), .values = {v, omega}},
                wait, "set_speed");
          },
          py::arg("v"), py::arg("omega"), py::arg("start") = py::none(), py::kw_only(),
          py::arg("wait") = true,
          "SETSPEED: base forward speed v (m/s) and turn rate omega (rad/s), until changed.")
      .def(
          "stop",
          [](PyRobotClient& p, std::optional<double> start, bool wait) {
            return p.Run(Command{.type = CommandType::kStop, .start_time = Start(start)}, wait, "stop");
          },
          py::arg("start") = py::none(), py::kw_only(), py::arg("wait") = true, "STOP every motion.")
      .def("_run_sequence",
           [](PyRobotClient& p, std::vector<TimedCommand> frames, const std::string& mode, py::object delay,
              bool paced, std::size_t batch, py::object on_reply, py::object on_progress,
              bool wait_until_given_up, bool collect_unknown) {
             SequenceOptions o{.mode = ParseMode(mode, "run_sequence"),
                               .delay = ToNonNegativeDuration(delay, "delay"),
                               .paced = paced,
                               .batch = batch};
             return p.RunSequence(std::move(frames), o, on_reply, on_progress, wait_until_given_up,
                                  collect_unknown);
           })
      .def("_start_state_stream", &PyRobotClient::StartStream, py::arg("period"), py::arg("queue_size"))
      .def("_stop_state_stream", &PyRobotClient::StopStream)
      .def(
          "stats",
          [](const PyRobotClient& p) {
            const ClientStats s = p.Client("stats")->stats();
            py::dict d;
            d["packages_sent"] = s.packages_sent;
            d["retransmissions"] = s.retransmissions;
            d["heartbeats"] = s.heartbeats;
            d["replies_filed"] = s.replies_filed;
            d["replies_ignored"] = s.replies_ignored;
            d["malformed_packages"] = s.malformed_packages;
            d["gave_up"] = s.gave_up;
            d["sessions_opened"] = s.sessions_opened;
            d["sessions_lost"] = s.sessions_lost;
            d["replies_refused"] = s.replies_refused;
            d["broadcasts_refused"] = s.broadcasts_refused;
            d["servers_refused"] = s.servers_refused;
            d["configs_cached"] = s.configs_cached;
            d["config_bytes_cached"] = s.config_bytes_cached;
            return d;
          },
          "The client's counters (a dict: packages_sent, retransmissions, sessions_lost, ...).")
      .def(
          "trusted_server",
          [](const PyRobotClient& p) {
            const TrustedServer t = p.Client("trusted_server")->trusted_server();
            py::dict d;
            d["source"] = SourceName(t.source);
            d["key"] = t.key;
            d["fingerprint"] = t.fingerprint;
            d["file"] = t.file;
            return d;
          },
          "Keyed mode: the server key this client trusts and why ({'source': 'none' | 'explicit' |\n"
          "'pinned' | 'pinned_now', 'key', 'fingerprint', 'file'}).");

  m.def(
      "_robots",
      [](std::optional<std::string> url, py::object listen) {
        ClientOptions o;
        o.lcm_url = url.value_or("");
        const Duration d = ToNonNegativeDuration(listen, "robots listen");
        py::gil_scoped_release release;
        std::size_t unlisted = 0;
        std::vector<AnnouncedRobot> robots = ListRobots(o, d, &unlisted);
        return std::make_pair(std::move(robots), unlisted);
      },
      py::arg("url") = py::none(), py::arg("listen") = 1.5);
}

}  // namespace robotalk::python
