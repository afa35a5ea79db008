// Values of the client API in Python: Reply, PendingReply, Command,
// TimedCommand, StateSample, SequenceResult, AnnouncedRobot, and the text
// forms of commands (robotalk/sequence_file.h).
#include "bindings.h"
#include "robotalk/command_status.h"
#include "robotalk/log_writer.h"  // EscapeControls
#include "robotalk/sequence_file.h"

#include <pybind11/stl.h>

#include <cstdio>

namespace robotalk::python {

std::optional<Reply> PyPendingReply::Poll() {
  py::gil_scoped_release release;
  std::lock_guard lock(mu_);
  return pending_.Poll();
}

Reply PyPendingReply::Wait(std::optional<Duration> timeout) {
  if (auto r = WaitInterruptibly(pending_, timeout, &mu_)) return *r;
  throw NoReply(what_, id(), *timeout);
}

std::optional<Reply> PyPendingReply::WaitFor(Duration most) {
  return WaitInterruptibly(pending_, most, &mu_);
}

bool PyPendingReply::Done() {
  try {
    return Poll().has_value();
  } catch (const Error&) {
    return true;  // given up: wait() raises why
  }
}

namespace {

std::string Ms(Duration d) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f ms", Seconds(d) * 1e3);
  return text;
}

CommandType ParseType(const std::string& name) {
  if (auto t = ParseCommandType(name)) return *t;
  std::string known;
  for (const CommandTraits& row : kCommandTraits) known += std::string(known.empty() ? "" : ", ") + row.name;
  throw UsageError("unknown command type '" + name + "' (" + known + ")");
}

Command MakeCommand(const std::string& type, const std::string& target, py::handle values,
                    std::optional<double> start, py::handle velocities, py::handle accelerations) {
  Command c{.type = ParseType(type), .target = target};
  c.values = ToValues(values, "Command values");
  c.velocities = ToValues(velocities, "Command velocities");
  c.accelerations = ToValues(accelerations, "Command accelerations");
  if (start) c.start_time = StartTime::At(ToTimePoint(*start, "Command start"));
  return c;
}

py::object OptionalSeconds(const std::optional<TimePoint>& t) {
  return t ? py::object(py::float_(Seconds(*t))) : py::object(py::none());
}

}  // namespace

void BindValues(py::module_& m) {
  py::class_<Reply>(m, "Reply",
                    "The final reply to a command or query: its signal ('SUCCESS', 'MODIFIED', 'NA',\n"
                    "'BUSY', 'INTERRUPTED', 'ERROR', 'PANIC'), the server's message, when it ran on the\n"
                    "server clock and how late, and the values a query returns. A non-success signal is\n"
                    "not an exception: test reply.signal or reply.succeeded.")
      .def_property_readonly(
          "id", [](const Reply& r) { return r.id; }, "The command id.")
      .def_property_readonly("signal", [](const Reply& r) { return std::string(ToString(r.signal)); })
      .def_property_readonly(
          "succeeded", [](const Reply& r) { return Succeeded(r.signal); },
          "SUCCESS or MODIFIED: the command was carried out.")
      .def_property_readonly("message", [](const Reply& r) { return r.message; })
      .def_property_readonly(
          "exec_time", [](const Reply& r) { return Seconds(r.exec_time); },
          "When it ran, server clock seconds (as RobotClient.server_now()).")
      .def_property_readonly(
          "lateness", [](const Reply& r) { return Seconds(r.lateness); },
          "How late after its start time it ran, s.")
      .def_property_readonly(
          "values", [](const Reply& r) { return ToArray(r.values); },
          "A query's values (numpy); empty for a command.")
      .def("__repr__", [](const Reply& r) {
        std::string s = "<Reply " + std::to_string(r.id) + " " + std::string(ToString(r.signal));
        if (!r.message.empty()) s += " '" + EscapeControls(r.message) + "'";  // the server's text
        if (!r.values.empty()) s += " (" + std::to_string(r.values.size()) + " values)";
        return s + " late " + Ms(r.lateness) + ">";
      });

  py::class_<PyPendingReply>(m, "PendingReply",
                             "The reply of a non-blocking call (wait=False), like a future. The command\n"
                             "executes whether or not anybody waits. Waits release the GIL and honour\n"
                             "Ctrl-C (KeyboardInterrupt; nothing is sent to the robot).")
      .def_property_readonly("id", &PyPendingReply::id, "The command id.")
      .def("done", &PyPendingReply::Done, "The reply has arrived (or the client gave up on it).")
      .def("poll", &PyPendingReply::Poll,
           "The Reply if it has arrived, else None. Raises UnknownOutcomeError if the client gave up.")
      .def(
          "wait",
          [](PyPendingReply& p, py::object timeout) {
            return p.Wait(timeout.is_none()
                              ? std::nullopt
                              : std::optional<Duration>(ToNonNegativeDuration(timeout, "wait timeout")));
          },
          py::arg("timeout") = py::none(),
          "Waits for the Reply: at most `timeout` (seconds or timedelta; None: until it arrives\n"
          "or the client gives up retransmitting). Raises TimeoutError, UnknownOutcomeError.")
      .def(
          "result",
          [](PyPendingReply& p, py::object timeout) {
            return p.Wait(timeout.is_none()
                              ? std::nullopt
                              : std::optional<Duration>(ToNonNegativeDuration(timeout, "result timeout")));
          },
          py::arg("timeout") = py::none(), "Same as wait() (concurrent.futures.Future's name).")
      .def(
          "wait_for",
          [](PyPendingReply& p, py::object most) {
            return p.WaitFor(ToNonNegativeDuration(most, "wait_for"));
          },
          py::arg("most"), "Waits at most `most`; the Reply, or None when it has not arrived.")
      .def("__repr__", [](PyPendingReply& p) {
        return "<PendingReply " + std::to_string(p.id()) + " " + p.what() +
               (p.Done() ? " done>" : " pending>");
      });

  py::class_<Command>(m, "Command",
                      "A command as a value: its type ('GOTO', 'SETSPEED', 'JOINT_SETPOINT', 'JOINT_SPEED',\n"
                      "'JOINT_FORCE', 'FRAME_SETPOINT', 'STOP', 'PANIC_RESET'; any case), the joint or\n"
                      "control frame it targets, its values in SI units, and when it starts: `start` on\n"
                      "the server clock (seconds, from RobotClient.server_now()), None = at once.\n"
                      "velocities / accelerations: a waypoint's (interpolated packages; empty = the\n"
                      "server's choice). Command.parse('goto 1 0 0') reads the CLI's words.")
      .def(py::init(&MakeCommand), py::arg("type"), py::arg("target") = "", py::arg("values") = py::tuple(),
           py::arg("start") = py::none(), py::arg("velocities") = py::tuple(),
           py::arg("accelerations") = py::tuple())
      .def_static(
          "parse", [](const std::string& text) { return ParseCommandWords(SplitWords(text)); },
          py::arg("text"), "A command from the CLI's words ('joint_setpoint pan 0.5'). Raises UsageError.")
      .def_property_readonly("type", [](const Command& c) { return std::string(ToString(c.type)); })
      .def_property_readonly("target", [](const Command& c) { return c.target; })
      .def_property_readonly("values", [](const Command& c) { return ToArray(c.values); })
      .def_property_readonly("velocities", [](const Command& c) { return ToArray(c.velocities); })
      .def_property_readonly("accelerations", [](const Command& c) { return ToArray(c.accelerations); })
      .def_property_readonly(
          "start", [](const Command& c) { return OptionalSeconds(c.start_time.time()); },
          "Server-clock seconds, or None (at once).")
      .def("__str__", [](const Command& c) { return FormatCommandWords(c); })
      .def("__repr__", [](const Command& c) {
        return "<Command " + FormatCommandWords(c) +
               (c.start_time.is_now() ? "" : " " + ToString(c.start_time)) + ">";
      });

  py::class_<TimedCommand>(m, "TimedCommand",
                           "One frame of a sequence: a command and its offset (seconds after the\n"
                           "sequence's start; the command's own start is ignored).")
      .def(py::init([](py::object offset, Command c) {
             return TimedCommand{ToNonNegativeDuration(offset, "TimedCommand offset"), std::move(c)};
           }),
           py::arg("offset"), py::arg("command"))
      .def_property_readonly("offset", [](const TimedCommand& t) { return Seconds(t.offset); })
      .def_property_readonly("command", [](const TimedCommand& t) { return t.command; })
      .def("__repr__", [](const TimedCommand& t) {
        char offset[32];
        std::snprintf(offset, sizeof offset, "%.6f", Seconds(t.offset));
        return std::string("<TimedCommand ") + offset + " s " + FormatCommandWords(t.command) + ">";
      });

  m.def(
      "parse_sequence",
      [](const std::string& text, const std::string& source) {
        std::vector<TimedCommand> frames;
        for (const SequenceEntry& e : ParseSequence(text, source))
          frames.push_back({FromSeconds(e.offset_s), e.command});
        return frames;
      },
      py::arg("text"), py::arg("source") = "<string>",
      "The frames of a sequence file's text (docs/client.md, 'Sequence files'): one\n"
      "'<offset s> <command> [target] values...' per line. Raises UsageError naming the line.");

  m.def(
      "command_status_kind",
      [](const Reply& answer, CommandId id) {
        switch (CommandStatusOf(answer, id)) {
          case CommandStatusKind::kNotEnded:
            return "NOT_ENDED";
          case CommandStatusKind::kNotReceived:
            return "NOT_RECEIVED";
          case CommandStatusKind::kEnded:
            break;
        }
        return "ENDED";
      },
      py::arg("answer"), py::arg("id"),
      "What RobotClient.command_status(id)'s answer says became of command `id`: 'ENDED' (the\n"
      "answer is its own final reply, whatever the signal), 'NOT_ENDED' (BUSY: it waits or runs)\n"
      "or 'NOT_RECEIVED' (NA: this session never received it, or its reply left the cache). A\n"
      "command that ended BUSY or NA keeps its own reply: only this tells the two apart.");

  py::class_<StateSample>(m, "StateSample",
                          "One sample of a robot's broadcast state (the state stream): server time,\n"
                          "joint positions / velocities / efforts in dof order, base x y theta v omega,\n"
                          "control-frame poses (x y z qw qx qy qz each).")
      .def_property_readonly(
          "server_time", [](const StateSample& s) { return Seconds(s.server_time); },
          "When sampled, server clock seconds.")
      .def_property_readonly(
          "period", [](const StateSample& s) { return Seconds(s.period); }, "s")
      .def_property_readonly(
          "sample", [](const StateSample& s) { return s.sample; },
          "1, 2, 3 ... since the stream started (a gap: samples dropped).")
      .def_property_readonly("robot", [](const StateSample& s) { return s.robot; })
      .def_property_readonly("config_hash", [](const StateSample& s) { return s.config_hash; })
      .def_property_readonly("panic", [](const StateSample& s) { return s.panic; })
      .def_property_readonly("moving", [](const StateSample& s) { return s.moving; })
      .def_property_readonly("positions", [](const StateSample& s) { return ToArray(s.positions); })
      .def_property_readonly("velocities", [](const StateSample& s) { return ToArray(s.velocities); })
      .def_property_readonly("efforts", [](const StateSample& s) { return ToArray(s.efforts); })
      .def_property_readonly(
          "base",
          [](const StateSample& s) {
            return ToArray({s.base.x, s.base.y, s.base.theta, s.base.v, s.base.omega});
          },
          "x y theta v omega (m, m, rad, m/s, rad/s).")
      .def_property_readonly(
          "frame_poses",
          [](const StateSample& s) {
            py::array_t<double> a({static_cast<py::ssize_t>(s.frame_poses.size()), py::ssize_t{7}});
            auto v = a.mutable_unchecked<2>();
            for (std::size_t i = 0; i < s.frame_poses.size(); ++i)
              for (std::size_t k = 0; k < 7; ++k)
                v(static_cast<py::ssize_t>(i), static_cast<py::ssize_t>(k)) = s.frame_poses[i][k];
            return a;
          },
          "numpy (num_frames, 7).")
      .def("__repr__", [](const StateSample& s) {
        return "<StateSample '" + s.robot + "' #" + std::to_string(s.sample) + " at " +
               std::to_string(Seconds(s.server_time)) + " s, " + std::to_string(s.positions.size()) +
               " dofs" + (s.moving ? ", moving" : "") + (s.panic ? ", PANIC" : "") + ">";
      });

  py::class_<SequenceResult>(m, "SequenceResult", "What RobotClient.run_sequence() returns.")
      .def_property_readonly(
          "replies", [](const SequenceResult& r) { return r.replies; },
          "One Reply per frame, in the order given (id 0: none, stopped or unknown).")
      .def_property_readonly(
          "first_sent", [](const SequenceResult& r) { return Seconds(r.first_sent); },
          "Client clock seconds when the first frame left.")
      .def_property_readonly(
          "server_start", [](const SequenceResult& r) { return OptionalSeconds(r.server_start); },
          "Server time of offset 0 (delay, playback), or None.")
      .def_property_readonly(
          "playback_delay",
          [](const SequenceResult& r) -> py::object {
            return r.playback_delay ? py::object(py::float_(Seconds(*r.playback_delay)))
                                    : py::object(py::none());
          },
          "Playback: the delay the server chose, s.")
      .def_property_readonly("stopped", [](const SequenceResult& r) { return r.stopped; })
      .def_property_readonly("frames_sent", [](const SequenceResult& r) { return r.frames_sent; })
      .def_property_readonly(
          "queued",
          [](const SequenceResult& r) {
            std::vector<double> t;
            for (TimePoint q : r.queued) t.push_back(Seconds(q));
            return t;
          },
          "Stopped delay sequence: server start times still queued on the server.")
      .def_property_readonly(
          "unknown_outcomes", [](const SequenceResult& r) { return r.unknown_outcomes; },
          "(frame index, why) of each frame of unknown outcome.")
      .def("__repr__", [](const SequenceResult& r) {
        std::size_t ok = 0;
        for (const Reply& x : r.replies) ok += x.id != 0 && Succeeded(x.signal);
        return "<SequenceResult " + std::to_string(ok) + "/" + std::to_string(r.replies.size()) +
               " succeeded" + (r.stopped ? ", stopped" : "") + ">";
      });

  py::class_<AnnouncedRobot>(m, "AnnouncedRobot", "A robot a server announces (robotalk.robots()).")
      .def_property_readonly("name", [](const AnnouncedRobot& r) { return r.name; })
      .def_property_readonly("driver", [](const AnnouncedRobot& r) { return r.driver; })
      .def_property_readonly("config_hash", [](const AnnouncedRobot& r) { return r.config_hash; })
      .def_property_readonly("total_dofs", [](const AnnouncedRobot& r) { return r.total_dofs; })
      .def_property_readonly("base_type",
                             [](const AnnouncedRobot& r) { return std::string(ToString(r.base_type)); })
      .def_property_readonly("panic", [](const AnnouncedRobot& r) { return r.panic; })
      .def_property_readonly("num_clients", [](const AnnouncedRobot& r) { return r.num_clients; })
      .def_property_readonly("server_id", [](const AnnouncedRobot& r) { return r.server_id; })
      .def_property_readonly("url_hint", [](const AnnouncedRobot& r) { return r.url_hint; })
      .def_property_readonly(
          "server_key", [](const AnnouncedRobot& r) { return r.server_key; },
          "The keyed server's key that signed the announcement, '' when open.")
      .def("__repr__", [](const AnnouncedRobot& r) {
        return "<AnnouncedRobot '" + r.name + "' driver " + r.driver + ", " + std::to_string(r.total_dofs) +
               " dofs" + (r.panic ? ", PANIC" : "") + ">";
      });
}

}  // namespace robotalk::python
