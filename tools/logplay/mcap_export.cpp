// robotalk-logplay export --mcap: the session as Foxglove channels (mcap_export.h).
#include "mcap_export.h"

#include "foxglove_messages.h"
#include "json_text.h"
#include "logplay.h"
#include "mcap_writer.h"
#include "robotalk/channels.h"
#include "robotalk/config_message.h"
#include "robotalk/request.h"
#include "scene_json.h"
#include "web_options.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>

namespace robotalk::logplay {
namespace {

namespace fg = web::foxglove;
using nlohmann::json;

std::int64_t Micros(TimePoint t) { return ToWireMicros(t); }

std::string StartText(const StartTime& s) {
  if (s.is_at()) return "at " + std::to_string(Micros(*s.time())) + " us";
  if (s.is_after()) return "after " + std::to_string(ToWireMicros(*s.offset())) + " us";
  return "now";
}

json RequestJson(const Request& r) {
  json queries = json::array();
  for (const Query& q : r.queries)
    queries.push_back({{"id", q.id}, {"type", ToString(q.type)}, {"target", q.target}});
  json commands = json::array();
  for (const Command& c : r.commands) {
    commands.push_back({{"id", c.id},
                        {"type", ToString(c.type)},
                        {"target", c.target},
                        {"start", StartText(c.start_time)},
                        {"values", c.values}});
  }
  return {{"client", Hex64(static_cast<std::uint64_t>(r.client_id))},
          {"sequence", r.sequence},
          {"send_time_us", Micros(r.send_time)},
          {"panic", r.panic},
          {"mode", ModeName(r.mode)},
          {"queries", queries},
          {"commands", commands}};
}

json ReplyJson(const ReplyBatch& b) {
  json replies = json::array();
  for (const Reply& r : b.replies) {
    replies.push_back({{"id", r.id},
                       {"signal", std::string(ToString(r.signal))},
                       {"message", r.message},
                       {"exec_time_us", Micros(r.exec_time)},
                       {"values", r.values}});
  }
  return {{"client", Hex64(static_cast<std::uint64_t>(b.client_id))},
          {"ack_sequence", b.ack_sequence},
          {"replies", replies}};
}

// One robot as the live bridge sees it: its model, poser and messages.
struct Robot {
  std::shared_ptr<const RobotModel> model;
  std::unique_ptr<web::StatePoser> poser;
  std::unique_ptr<fg::RobotMessages> messages;
  std::uint64_t config_hash = 0;
};

class Exporter {
 public:
  Exporter(const std::string& path, std::map<std::string, web::MeshCatalog> geometry)
      : mcap_(path), geometry_(std::move(geometry)) {}

  void Event(const std::string& channel, std::int64_t log_us, std::span<const std::uint8_t> bytes) {
    const std::optional<ChannelParts> parts = ParseChannel(channel);
    if (!parts) return;
    const std::uint64_t log_ns =
        static_cast<std::uint64_t>(std::clamp<std::int64_t>(log_us, 0, kMaxWireMicros)) * 1000;
    try {
      if (log_us > kMaxWireMicros)  // would wrap around as nanoseconds
        throw ProtocolError("log timestamp " + std::to_string(log_us) + " us is out of range");
      switch (parts->kind) {
        case ChannelKind::kConfig:
          Config(parts->robot, log_ns, bytes);
          break;
        case ChannelKind::kState:
          State(parts->robot, log_ns, bytes);
          break;
        case ChannelKind::kRequest:
          Put("/" + parts->robot + "/requests", fg::RequestSchema(), log_ns, log_ns,
              RequestJson(DecodeRequest(bytes)));
          break;
        case ChannelKind::kReply:
          Put("/" + parts->robot + "/replies", fg::ReplySchema(), log_ns, log_ns,
              ReplyJson(DecodeReplyBatch(bytes)));
          break;
        default:
          break;
      }
    } catch (const LogError&) {
      throw;
    } catch (const Error& e) {  // a message that does not decode: counted, named once per channel
      ++result.undecodable;
      if (undecodable_channels_.insert(channel).second) warnings_.push_back(channel + ": " + e.what());
    }
  }

  void Close() {
    mcap_.Close();
    result.messages = mcap_.messages();
    result.bytes = mcap_.bytes_written();
  }

  McapExportResult result;
  std::vector<std::string> warnings_;

 private:
  void Config(const std::string& robot, std::uint64_t log_ns, std::span<const std::uint8_t> bytes) {
    const std::uint64_t hash = DecodeConfigHash(bytes);
    Robot& r = robots_[robot];
    if (r.model && r.config_hash == hash) return;  // the same description again (another client connected)
    r.model = std::make_shared<const RobotModel>(DecodeConfig(bytes));
    r.poser = std::make_unique<web::StatePoser>(*r.model);
    const auto urdf = geometry_.find(robot);
    r.messages = std::make_unique<fg::RobotMessages>(
        r.model, urdf == geometry_.end() ? std::nullopt : std::optional<web::MeshCatalog>(urdf->second));
    r.config_hash = hash;
    Put(fg::TopicName(robot, fg::Topic::kScene), fg::SchemaOf(fg::Topic::kScene), log_ns, log_ns,
        r.messages->Scene(static_cast<std::int64_t>(log_ns), {.embed = true}));
  }

  void State(const std::string& robot, std::uint64_t log_ns, std::span<const std::uint8_t> bytes) {
    const robotalk::StateSample s = DecodeStateSample(bytes);
    const auto it = robots_.find(robot);
    if (it == robots_.end() || !it->second.model ||
        s.positions.size() != static_cast<std::size_t>(it->second.model->num_dofs())) {
      if (result.unposed++ == 0)
        warnings_.push_back("robot '" + robot +
                            "': STATE before (or unlike) its logged configuration is not posed");
      return;
    }
    const Robot& r = it->second;
    const fg::RobotMessages::State st = r.messages->FromPose(r.poser->Pose(s));
    const auto publish = static_cast<std::uint64_t>(std::max<std::int64_t>(0, st.time_ns));
    Put(fg::TopicName(robot, fg::Topic::kTransforms), fg::SchemaOf(fg::Topic::kTransforms), log_ns, publish,
        st.transforms);
    Put(fg::TopicName(robot, fg::Topic::kJointStates), fg::SchemaOf(fg::Topic::kJointStates), log_ns, publish,
        st.joint_states);
    Put(fg::TopicName(robot, fg::Topic::kBasePose), fg::SchemaOf(fg::Topic::kBasePose), log_ns, publish,
        st.base_pose);
    Put(fg::TopicName(robot, fg::Topic::kStatus), fg::SchemaOf(fg::Topic::kStatus), log_ns, publish,
        st.status);
  }

  void Put(const std::string& topic, const fg::SchemaInfo& schema, std::uint64_t log_ns,
           std::uint64_t publish_ns, const json& message) {
    auto [it, added] = channels_.try_emplace(topic, 0);
    if (added)
      it->second = mcap_.AddChannel(mcap_.AddSchema(schema.name, "jsonschema", schema.schema), topic, "json");
    mcap_.Write(it->second, log_ns, publish_ns, JsonText(message));
  }

  McapWriter mcap_;
  const std::map<std::string, web::MeshCatalog> geometry_;
  std::map<std::string, Robot> robots_;
  std::map<std::string, std::uint16_t> channels_;
  std::set<std::string> undecodable_channels_;
};

}  // namespace

McapGeometry ParseGeometryOptions(const std::vector<std::string>& urdf,
                                  const std::vector<std::string>& package_paths,
                                  const std::string& ros_package_path) {
  McapGeometry g;
  for (const std::string& v : urdf) {
    auto [robot, path] = web::ParseUrdfOption(v);
    if (!std::filesystem::is_regular_file(path)) throw Error("--urdf " + v + ": no such file");
    g.urdf[robot] = path;
  }
  for (const std::string& v : package_paths) web::AppendPackagePaths(v, g.package_paths);
  if (!ros_package_path.empty()) web::AppendPackagePaths(ros_package_path, g.package_paths);
  return g;
}

McapExportResult ExportMcap(const std::string& log_path, const std::string& mcap_path, std::ostream& warnings,
                            const McapGeometry& geometry) {
  LcmLogReader file = OpenLog(log_path);
  std::map<std::string, web::MeshCatalog> catalogs;
  for (const auto& [robot, path] : geometry.urdf) {
    web::MeshCatalog& c = catalogs[robot] = web::ResolveMeshes(robot, path, geometry.package_paths);
    if (!c.error.empty() || !c.geometry_error.empty())
      warnings << "robotalk-logplay: --urdf " << robot << ": " << c.error << c.geometry_error
               << " (the scene shows its inertia boxes)\n";
    std::size_t told = 0;
    for (const web::MeshEntry& m : c.meshes)
      if (!m.error.empty() && ++told <= 5)
        warnings << "robotalk-logplay: " << robot << ": link '" << m.link << "': mesh " << m.uri << ": "
                 << m.error << "\n";
    if (told > 0)
      warnings << "robotalk-logplay: " << robot << ": " << told << " of " << c.meshes.size()
               << " meshes not resolved; their links show their inertia boxes\n";
  }
  std::unique_ptr<Exporter> exporter;
  try {
    exporter = std::make_unique<Exporter>(mcap_path, std::move(catalogs));
  } catch (const Error& e) {
    throw LogError(std::string("export --mcap: ") + e.what());
  }
  while (const LcmLogEvent* e = file.Next()) {
    ++exporter->result.events;
    exporter->result.log_bytes += e->data.size();
    exporter->Event(e->channel, e->timestamp_us, e->data);
  }
  // A log's channel and robot names are anyone's bytes: the warnings naming
  // them are written Printable (as SessionLog shows them).
  for (const std::string& d : file.damage())
    warnings << "robotalk-logplay: damaged log: " << Printable(d) << "\n";
  try {
    exporter->Close();
  } catch (const Error& e) {
    throw LogError(std::string("export --mcap: ") + e.what());
  }
  for (const std::string& w : exporter->warnings_) warnings << "robotalk-logplay: " << Printable(w) << "\n";
  if (exporter->result.unposed > 0)
    warnings << "robotalk-logplay: " << exporter->result.unposed
             << " STATE samples not posed (no configuration logged before them)\n";
  return exporter->result;
}

}  // namespace robotalk::logplay
