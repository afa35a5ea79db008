// robotalk-logplay's reading side as functions returning plain Python data
// (docs/python.md, "Logs"): the SessionLog, Timeline and LoggedConfigs of
// tools/logplay, never a second decoder.
#include "bindings.h"
#include "export.h"
#include "logplay.h"
#include "robotalk/sequence_file.h"

#include <pybind11/stl.h>

#include <limits>
#include <map>
#include <variant>

namespace robotalk::python {
namespace {

namespace lp = logplay;

double UnixSeconds(std::int64_t us) { return static_cast<double>(us) * 1e-6; }

lp::SessionLog Read(const std::string& path) {
  py::gil_scoped_release release;
  return lp::ReadLog(path);
}

py::object OptionalReply(const std::optional<Reply>& r) { return r ? py::cast(*r) : py::object(py::none()); }

py::dict Info(const std::string& path) {
  const lp::SessionLog log = Read(path);
  py::dict out;
  out["path"] = path;
  out["events"] = log.events();
  out["first_time"] = UnixSeconds(log.first_us());
  out["last_time"] = UnixSeconds(log.last_us());
  // What was not used (an entry that does not decode, a damaged stretch of the file), as `info` says it.
  out["rejected"] = log.rejected();
  out["rejections"] = log.rejections();
  py::dict channels;
  for (const auto& [name, s] : log.channels()) {
    py::dict c;
    c["messages"] = s.messages;
    c["bytes"] = s.bytes;
    c["first_time"] = UnixSeconds(s.first_us);
    c["last_time"] = UnixSeconds(s.last_us);
    c["undecodable"] = s.undecodable;
    channels[Text(name)] = c;  // anyone's channel name: maybe not UTF-8
  }
  out["channels"] = channels;
  out["servers"] = log.servers();
  py::list robots;
  for (const lp::LoggedRobot& r : log.robots()) {
    py::dict d;
    d["name"] = r.name;
    d["driver"] = r.driver;
    d["server_id"] = r.server_id;
    d["config_hash"] = r.config_hash;
    d["total_dofs"] = r.total_dofs;
    d["panic_seen"] = r.panic_seen;
    robots.append(d);
  }
  out["robots"] = robots;
  py::list clients;
  for (const auto& [id, c] : log.clients()) {
    py::dict d;
    d["id"] = c.id;
    d["robot"] = c.robot;
    d["packages"] = c.packages;
    d["retransmissions"] = c.retransmissions;
    d["heartbeats"] = c.heartbeats;
    d["queries"] = c.queries;
    d["panics"] = c.panics;
    d["hellos"] = c.hellos;
    d["hellos_refused"] = c.hellos_refused;
    std::vector<std::string> modes;
    for (RequestMode mode : c.modes) modes.emplace_back(lp::ModeName(mode));
    d["modes"] = modes;
    d["first_time"] = UnixSeconds(c.first_log_us);
    d["last_time"] = UnixSeconds(c.last_log_us);
    d["clock_offset"] =
        c.clock_offset_us ? py::object(py::float_(UnixSeconds(*c.clock_offset_us))) : py::none();
    clients.append(d);
  }
  out["clients"] = clients;
  py::list commands;
  for (const lp::LoggedCommand& c : log.commands()) {
    py::dict d;
    d["client"] = c.client_id;
    d["robot"] = c.robot;
    d["sequence"] = c.sequence;
    d["panic"] = c.panic;
    d["mode"] = lp::ModeName(c.mode);
    d["command"] = c.command;
    d["start_us"] = c.start_us;
    d["send_time_us"] = c.send_time_us;
    d["log_time"] = UnixSeconds(c.log_time_us);
    d["reply"] = OptionalReply(c.reply);
    commands.append(d);
  }
  out["commands"] = commands;
  return out;
}

// The STATE samples of one robot as arrays (a robot's dof count may change
// with its configuration: only the samples of the newest count are kept).
py::dict States(const std::string& path, std::optional<std::string> robot) {
  const lp::SessionLog log = Read(path);
  std::string name;
  if (robot) {
    name = *robot;
  } else {
    std::map<std::string, int> seen;
    for (const lp::StateSample& s : log.states()) ++seen[s.robot];
    if (seen.size() > 1) {
      std::string all;
      for (const auto& [r, n] : seen) all += (all.empty() ? "" : ", ") + r;
      throw lp::LogError("log_states('" + path + "'): the log has the state of several robots (" + all +
                         "): say which with robot=");
    }
    if (!seen.empty()) name = seen.begin()->first;
  }
  std::vector<const lp::StateSample*> samples;
  for (const lp::StateSample& s : log.states()) {
    if (s.robot == name) samples.push_back(&s);
  }
  if (samples.empty()) {
    throw lp::LogError("log_states('" + path + "'): no STATE samples" +
                       (name.empty() ? std::string() : " of robot '" + name + "'") +
                       " (record the state stream: robotalk watch, or a client's state_stream)");
  }
  const std::size_t dofs = samples.back()->position.size();
  std::erase_if(samples, [&](const lp::StateSample* s) { return s->position.size() != dofs; });
  const auto n = static_cast<py::ssize_t>(samples.size());
  py::array_t<double> log_time(n), server_time(n), positions({n, static_cast<py::ssize_t>(dofs)}),
      base({n, py::ssize_t{5}});
  py::array_t<bool> moving(n), panic(n);
  auto p = positions.mutable_unchecked<2>();
  auto b = base.mutable_unchecked<2>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const lp::StateSample& s = *samples[static_cast<std::size_t>(i)];
    log_time.mutable_at(i) = UnixSeconds(s.log_time_us);
    server_time.mutable_at(i) = UnixSeconds(s.server_time_us);
    moving.mutable_at(i) = s.moving;
    panic.mutable_at(i) = s.panic;
    for (std::size_t k = 0; k < dofs; ++k) p(i, static_cast<py::ssize_t>(k)) = s.position[k];
    for (std::size_t k = 0; k < 5 && k < s.base.size(); ++k) b(i, static_cast<py::ssize_t>(k)) = s.base[k];
  }
  std::vector<std::string> names, units;
  const lp::LoggedConfigs configs = [&] {
    py::gil_scoped_release release;
    return lp::ReadConfigs(path);
  }();
  if (const auto* columns = configs.Find(name, dofs)) {
    for (const lp::DofColumn& c : *columns) {
      names.push_back(c.name);
      units.push_back(c.unit);
    }
  } else {
    for (std::size_t k = 0; k < dofs; ++k) {
      names.push_back("q" + std::to_string(k));
      units.emplace_back();
    }
  }
  py::dict out;
  out["robot"] = name;
  out["log_time"] = log_time;
  out["server_time"] = server_time;
  out["positions"] = positions;
  out["base"] = base;
  out["moving"] = moving;
  out["panic"] = panic;
  out["joint_names"] = names;
  out["units"] = units;
  out["names_from_log"] = configs.Find(name, dofs) != nullptr;
  return out;
}

std::vector<TimedCommand> Extract(const std::string& path,
                                  std::optional<std::variant<std::int64_t, std::string>> client,
                                  const std::string& robot, std::map<std::string, std::string> rename,
                                  std::pair<double, double> window, double speed) {
  lp::Selection sel{.robot = robot};
  if (client) {
    if (const auto* id = std::get_if<std::int64_t>(&*client)) {
      sel.client_id = *id;
    } else {
      sel.client_id = lp::ParseClientId(std::get<std::string>(*client));
    }
  }
  if (!sel.client_id && sel.robot.empty()) throw UsageError("extract: give client= or robot=");
  if (!(speed > 0)) throw UsageError("extract: speed must be positive, got " + std::to_string(speed));
  if (!(window.first >= 0 && window.second > window.first)) {
    throw UsageError("extract: window (" + std::to_string(window.first) + ", " +
                     std::to_string(window.second) + "): need 0 <= start < end");
  }
  const lp::SessionLog log = Read(path);
  const lp::Timeline t = log.MakeTimeline(sel);
  return lp::ToFrames(
      t, {.rename = std::move(rename), .from_s = window.first, .to_s = window.second, .speed = speed});
}

}  // namespace

void BindLogs(py::module_& m) {
  m.def("log_info", &Info, py::arg("path"),
        "What `robotalk-logplay info` reports, as plain data: events, time span (UNIX seconds),\n"
        "channels, servers, robots, clients (their packages, retransmissions, modes, clock\n"
        "offset) and every recorded command (client, mode, Command, its logged Reply or None);\n"
        "rejected: what was not used (undecodable entries, damaged stretches of the file, each\n"
        "naming where), the first 20 of `rejections`.\n"
        "Raises LogError when the file cannot be opened.");
  m.def("log_states", &States, py::arg("path"), py::arg("robot") = py::none(),
        "The recorded state stream of one robot as numpy arrays: log_time and server_time (n,),\n"
        "positions (n, dofs), base (n, 5: x y theta v omega), moving and panic (n,), and the\n"
        "joint_names / units of the columns (from the logged configuration, else q0, q1, ...).");
  m.def("extract", &Extract, py::arg("path"), py::kw_only(), py::arg("client") = py::none(),
        py::arg("robot") = "", py::arg("rename") = std::map<std::string, std::string>{},
        py::arg("window") = std::make_pair(0.0, std::numeric_limits<double>::infinity()),
        py::arg("speed") = 1.0,
        "What `robotalk-logplay extract` writes, as TimedCommands: the commands of one client\n"
        "(client=id) or every client of one robot (robot=name) on the recovered server-clock\n"
        "timeline, renamed (rename={'old': 'new'}), windowed (window=(start_s, end_s), re-based)\n"
        "and scaled (speed=2: twice as fast). Play them with RobotClient.run_sequence().\n"
        "Raises LogError.");
  m.def("format_sequence", &lp::FormatSequence, py::arg("frames"), py::arg("header") = "",
        "A sequence file's text (`robotalk send --file` plays it) for TimedCommands: their set-points'\n"
        "interpolation line, then each command as robotalk send takes it (values exact, a waypoint's\n"
        "velocities and accelerations). Raises LogError for a target that is not one word, or for\n"
        "set-points of two interpolations.");
}

}  // namespace robotalk::python
