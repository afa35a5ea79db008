// robotalk-logplay export: CSV files with named joint columns (export.h).
#include "export.h"

#include "logplay.h"
#include "robotalk/channels.h"
#include "robotalk/config_message.h"
#include "robotalk/sequence_file.h"  // FormatNumber

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <set>

namespace robotalk::logplay {
namespace {

std::vector<DofColumn> Columns(const RobotModel& model) {
  std::vector<DofColumn> columns;
  for (const Joint& j : model.joints()) {
    for (std::size_t d = 0; d < j.dofs.size(); ++d) {
      // A multi-dof joint (planar, free) names its dofs joint.0, joint.1, ...
      columns.push_back({j.dofs.size() == 1 ? j.name : j.name + "." + std::to_string(d),
                         j.dofs[d].type == DofType::kPrismatic ? "m" : "rad"});
    }
  }
  return columns;
}

std::vector<DofColumn> Unnamed(std::size_t n) {
  std::vector<DofColumn> columns;
  for (std::size_t i = 0; i < n; ++i) columns.push_back({"q" + std::to_string(i), ""});
  return columns;
}

void WriteCommands(const SessionLog& log, std::ostream& out) {
  out << "client,robot,sequence,mode,id,type,target,start_us,send_time_us,log_time_us,signal,exec_time_us,"
         "values\n";
  for (const LoggedCommand& c : log.commands()) {
    out << Hex64(static_cast<std::uint64_t>(c.client_id)) << ',' << c.robot << ',' << c.sequence << ','
        << (c.panic ? "panic" : ModeName(c.mode)) << ',' << c.command.id << ','
        << (c.panic ? "PANIC" : ToString(c.command.type)) << ',' << c.command.target << ',' << c.start_us
        << ',' << c.send_time_us << ',' << c.log_time_us << ','
        << (c.reply ? std::string(ToString(c.reply->signal)) : "") << ','
        << (c.reply ? std::to_string(ToWireMicros(c.reply->exec_time)) : "") << ',';
    for (std::size_t i = 0; i < c.command.values.size(); ++i)
      out << (i ? " " : "") << FormatNumber(c.command.values[i]);
    out << "\n";
  }
}

}  // namespace

void LoggedConfigs::Add(const std::string& channel, std::span<const std::uint8_t> bytes) {
  const std::optional<std::string> robot = RobotOfConfigChannel(channel);
  if (!robot) return;
  try {
    std::vector<DofColumn> columns = Columns(DecodeConfig(bytes));
    auto& configs = robots_[*robot];
    std::erase(configs, columns);
    configs.push_back(std::move(columns));
  } catch (const std::exception&) {
    ++undecodable_;  // a log holds whatever was on the bus
  }
}

const std::vector<DofColumn>* LoggedConfigs::Find(const std::string& robot, std::size_t num_dofs) const {
  const auto it = robots_.find(robot);
  if (it == robots_.end()) return nullptr;
  for (auto c = it->second.rbegin(); c != it->second.rend(); ++c) {
    if (c->size() == num_dofs) return &*c;
  }
  return nullptr;
}

LoggedConfigs ReadConfigs(const std::string& path) {
  LcmLogReader file = OpenLog(path);  // its damage is said by ReadLog, which export runs too
  LoggedConfigs configs;
  while (const LcmLogEvent* e = file.Next()) configs.Add(e->channel, e->data);
  return configs;
}

std::vector<std::string> ExportCsv(const SessionLog& log, const LoggedConfigs& configs,
                                   const std::string& dir, std::ostream& warnings) {
  std::filesystem::create_directories(dir);
  const std::string commands_path = dir + "/commands.csv", state_path = dir + "/state.csv",
                    joints_path = dir + "/joints.csv";
  std::ofstream commands(commands_path), state(state_path), joints(joints_path);
  if (!commands || !state || !joints) throw LogError("cannot write CSV files in '" + dir + "'");
  WriteCommands(log, commands);

  // The joint columns: the union over robots (and configurations), in order
  // of first appearance; a robot's row fills the columns of its own dofs.
  std::vector<std::string> names;
  std::map<std::string, std::size_t> column_of;
  std::map<std::pair<std::string, std::size_t>, std::vector<std::size_t>> layout;  // (robot, dofs) -> columns
  joints << "robot,dof,column,unit,named_from\n";
  for (const StateSample& s : log.states()) {
    auto [it, fresh] = layout.try_emplace({s.robot, s.position.size()});
    if (!fresh) continue;
    const std::vector<DofColumn>* named = configs.Find(s.robot, s.position.size());
    if (!named && !s.position.empty()) {
      warnings << "robotalk-logplay: export: the log holds no configuration (ROBOTALK/" << s.robot
               << "/CONFIG) of robot '" << s.robot << "' with " << s.position.size()
               << " dofs: its joints are named q0..q" << s.position.size() - 1
               << " (record from before the clients connect to log it)\n";
    }
    const std::vector<DofColumn> columns = named ? *named : Unnamed(s.position.size());
    for (std::size_t d = 0; d < columns.size(); ++d) {
      auto [c, added] = column_of.try_emplace(columns[d].name, names.size());
      if (added) names.push_back(columns[d].name);
      it->second.push_back(c->second);
      joints << s.robot << ',' << d << ',' << columns[d].name << ',' << columns[d].unit << ','
             << (named ? "config" : "none") << "\n";
    }
  }
  state << "robot,log_time_us,server_time_us,panic,moving,x,y,theta,v,omega";
  for (const std::string& n : names) state << ',' << n;
  state << "\n";
  std::vector<std::string> cells(names.size());
  for (const StateSample& s : log.states()) {
    state << s.robot << ',' << s.log_time_us << ',' << s.server_time_us << ',' << s.panic << ',' << s.moving;
    for (double b : s.base) state << ',' << FormatNumber(b);
    std::fill(cells.begin(), cells.end(), std::string());
    const std::vector<std::size_t>& columns = layout.at({s.robot, s.position.size()});
    for (std::size_t d = 0; d < s.position.size(); ++d) cells[columns[d]] = FormatNumber(s.position[d]);
    for (const std::string& c : cells) state << ',' << c;
    state << "\n";
  }
  if (!commands || !state || !joints) throw LogError("cannot write CSV files in '" + dir + "'");
  return {commands_path, state_path, joints_path};
}

}  // namespace robotalk::logplay
