#include "foxglove_messages.h"

#include "robotalk/error.h"
#include "scene_json.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <variant>

namespace robotalk::web::foxglove {
namespace {

using nlohmann::json;

// JSON Schemas written from Foxglove's published message definitions
// (foxglove-sdk schemas/jsonschema: field names and nesting as there; only
// the fields we fill are listed). Foxglove recognises its own types by the
// schema name, the rest by their fields.
json Object(json properties) {
  json required = json::array();
  for (auto it = properties.begin(); it != properties.end(); ++it) required.push_back(it.key());
  return {{"type", "object"}, {"properties", std::move(properties)}, {"required", std::move(required)}};
}
json Number() { return {{"type", "number"}}; }
json Integer() { return {{"type", "integer"}}; }
json String() { return {{"type", "string"}}; }
json Boolean() { return {{"type", "boolean"}}; }
json ArrayOf(json items) { return {{"type", "array"}, {"items", std::move(items)}}; }
json TimeSchema() { return Object({{"sec", Integer()}, {"nsec", Integer()}}); }
json Vector3Schema() { return Object({{"x", Number()}, {"y", Number()}, {"z", Number()}}); }
json QuaternionSchema() {
  return Object({{"x", Number()}, {"y", Number()}, {"z", Number()}, {"w", Number()}});
}
json ColorSchema() { return Object({{"r", Number()}, {"g", Number()}, {"b", Number()}, {"a", Number()}}); }
json PoseSchema() { return Object({{"position", Vector3Schema()}, {"orientation", QuaternionSchema()}}); }

SchemaInfo Make(std::string name, std::string title, json schema) {
  schema["title"] = title;
  schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
  return {std::move(name), schema.dump()};
}

SchemaInfo TransformsSchema() {
  const json transform = Object({{"timestamp", TimeSchema()},
                                 {"parent_frame_id", String()},
                                 {"child_frame_id", String()},
                                 {"translation", Vector3Schema()},
                                 {"rotation", QuaternionSchema()}});
  return Make("foxglove.FrameTransforms", "foxglove.FrameTransforms",
              Object({{"transforms", ArrayOf(transform)}}));
}

SchemaInfo SceneSchema() {
  const json cube = Object({{"pose", PoseSchema()}, {"size", Vector3Schema()}, {"color", ColorSchema()}});
  const json cylinder = Object({{"pose", PoseSchema()},
                                {"size", Vector3Schema()},
                                {"bottom_scale", Number()},
                                {"top_scale", Number()},
                                {"color", ColorSchema()}});
  json base64 = String();
  base64["contentEncoding"] = "base64";
  const json model = Object({{"pose", PoseSchema()},
                             {"scale", Vector3Schema()},
                             {"color", ColorSchema()},
                             {"override_color", Boolean()},
                             {"url", String()},
                             {"media_type", String()},
                             {"data", base64}});
  json entity = Object({{"timestamp", TimeSchema()},
                        {"frame_id", String()},
                        {"id", String()},
                        {"lifetime", TimeSchema()},
                        {"frame_locked", Boolean()},
                        {"metadata", ArrayOf(Object({{"key", String()}, {"value", String()}}))},
                        {"cubes", ArrayOf(cube)},
                        {"spheres", ArrayOf(cube)},
                        {"cylinders", ArrayOf(cylinder)},
                        {"models", ArrayOf(model)}});
  const json deletion = Object({{"timestamp", TimeSchema()}, {"type", Integer()}, {"id", String()}});
  return Make("foxglove.SceneUpdate", "foxglove.SceneUpdate",
              Object({{"deletions", ArrayOf(deletion)}, {"entities", ArrayOf(entity)}}));
}

SchemaInfo JointStateSchema() {
  return Make("robotalk.JointState", "robotalk.JointState: positions of every dof, in the model's order",
              Object({{"timestamp", TimeSchema()},
                      {"robot", String()},
                      {"name", ArrayOf(String())},
                      {"position", ArrayOf(Number())}}));
}

SchemaInfo BasePoseSchema() {
  return Make("foxglove.PoseInFrame", "foxglove.PoseInFrame",
              Object({{"timestamp", TimeSchema()}, {"frame_id", String()}, {"pose", PoseSchema()}}));
}

SchemaInfo StatusSchema() {
  return Make(
      "robotalk.RobotStatus",
      "robotalk.RobotStatus: the state sample's flags; base is x y theta v omega (m, rad, m/s, rad/s)",
      Object({{"timestamp", TimeSchema()},
              {"robot", String()},
              {"sample", Integer()},
              {"period", Number()},
              {"panic", Boolean()},
              {"moving", Boolean()},
              {"base", ArrayOf(Number())}}));
}

// Rounded to 1e-6 (µm, µrad), as the page's poses (scene_json.h): the text
// stays short, and a product of poses writes 0.3, not 0.30000000000000004.
double R6(double v) { return std::isfinite(v) ? std::round(v * 1e6) / 1e6 : 0.0; }
json Vec(const Eigen::Vector3d& v) { return {{"x", R6(v.x())}, {"y", R6(v.y())}, {"z", R6(v.z())}}; }
json Quat(const Eigen::Quaterniond& q) {
  return {{"x", R6(q.x())}, {"y", R6(q.y())}, {"z", R6(q.z())}, {"w", R6(q.w())}};
}

// A pose written by StatePoser::Pose: [x, y, z, qw, qx, qy, qz].
Eigen::Isometry3d PoseOf(const json& p, const char* what) {
  if (!p.is_array() || p.size() != 7)
    throw Error(std::string("foxglove: ") + what + " is not a 7-value pose");
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.translation() << p[0].get<double>(), p[1].get<double>(), p[2].get<double>();
  Eigen::Quaterniond q(p[3].get<double>(), p[4].get<double>(), p[5].get<double>(), p[6].get<double>());
  x.linear() = (q.norm() > 0 ? q.normalized() : Eigen::Quaterniond::Identity()).toRotationMatrix();
  return x;
}

json Transform(std::int64_t ns, const std::string& parent, const std::string& child,
               const Eigen::Isometry3d& x) {
  return {{"timestamp", TimeJson(ns)},
          {"parent_frame_id", parent},
          {"child_frame_id", child},
          {"translation", Vec(x.translation())},
          {"rotation", Quat(Eigen::Quaterniond(x.linear()))}};
}

json PoseJson(const Pose& p) { return {{"position", Vec(p.translation)}, {"orientation", Quat(p.rotation)}}; }
json ColorJson(const Eigen::Vector4d& c) {
  return {{"r", R6(c[0])}, {"g", R6(c[1])}, {"b", R6(c[2])}, {"a", R6(c[3])}};
}
const Eigen::Vector4d kInertiaColor(0.45, 0.6, 0.8, 0.7);
const Eigen::Vector4d kUrdfColor(0.72, 0.74, 0.78, 1.0);  // a shape without a material

json KeyValue(const std::string& key, const std::string& value) { return {{"key", key}, {"value", value}}; }

// An entity of link frame `frame` with no primitives yet.
json Entity(std::int64_t ns, const std::string& frame, json metadata) {
  return {{"timestamp", TimeJson(ns)}, {"frame_id", frame},        {"id", frame},
          {"lifetime", TimeJson(0)},   {"frame_locked", true},     {"metadata", std::move(metadata)},
          {"cubes", json::array()},    {"spheres", json::array()}, {"cylinders", json::array()},
          {"models", json::array()}};
}

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// The media types Foxglove's 3D panel loads models of; "" lets it guess from the URL.
std::string MediaType(const std::filesystem::path& file) {
  const std::string ext = Lower(file.extension().string());
  if (ext == ".stl") return "model/stl";
  if (ext == ".glb") return "model/gltf-binary";
  if (ext == ".gltf") return "model/gltf+json";
  if (ext == ".dae") return "model/vnd.collada+xml";
  if (ext == ".obj") return "model/obj";
  return "";
}

std::string Base64(const std::string& in) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < in.size(); i += 3) {
    std::uint32_t v = static_cast<std::uint8_t>(in[i]) << 16;
    if (i + 1 < in.size()) v |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(in[i + 1])) << 8;
    if (i + 2 < in.size()) v |= static_cast<std::uint8_t>(in[i + 2]);
    out += kDigits[(v >> 18) & 63];
    out += kDigits[(v >> 12) & 63];
    out += i + 1 < in.size() ? kDigits[(v >> 6) & 63] : '=';
    out += i + 2 < in.size() ? kDigits[v & 63] : '=';
  }
  return out;
}

// The foxglove.ModelPrimitive of a resolved mesh, or why there is none.
std::variant<json, std::string> Model(const UrdfShape& s, const MeshEntry& m, const MeshLinks& links,
                                      const std::optional<Eigen::Vector4d>& rgba) {
  std::string url, data;
  if (!links.embed) {
    url = links.url_base + m.url;
  } else if (Lower(m.file.extension().string()) == ".gltf") {
    url = "file://" + m.file.string();
  } else {
    std::error_code ec;
    const std::uintmax_t size = std::filesystem::file_size(m.file, ec);
    if (ec) return "cannot read " + m.file.string() + ": " + ec.message();
    if (size > links.max_embedded_bytes) {
      return m.file.string() + " is " + std::to_string(size) + " bytes, over the " +
             std::to_string(links.max_embedded_bytes) + "-byte limit of an embedded mesh";
    }
    std::ifstream in(m.file, std::ios::binary);
    std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (!in.good() && !in.eof()) return "cannot read " + m.file.string();
    data = Base64(bytes);
  }
  return json{{"pose", PoseJson(s.origin)},
              {"scale", Vec(s.size)},
              {"color", ColorJson(rgba.value_or(kUrdfColor))},
              {"override_color", rgba.has_value()},
              {"url", url},
              {"media_type", MediaType(m.file)},
              {"data", data}};
}

const json& Field(const json& pose, const char* name) {
  const auto it = pose.find(name);
  if (it == pose.end()) throw Error(std::string("foxglove: state pose has no '") + name + "'");
  return *it;
}

}  // namespace

std::string TopicName(const std::string& robot, Topic topic) {
  switch (topic) {
    case Topic::kTransforms:
      return "/" + robot + "/tf";
    case Topic::kScene:
      return "/" + robot + "/scene";
    case Topic::kJointStates:
      return "/" + robot + "/joint_states";
    case Topic::kBasePose:
      return "/" + robot + "/base_pose";
    case Topic::kStatus:
      return "/" + robot + "/status";
  }
  return "/" + robot;
}

const SchemaInfo& SchemaOf(Topic topic) {
  static const SchemaInfo schemas[] = {TransformsSchema(), SceneSchema(), JointStateSchema(),
                                       BasePoseSchema(), StatusSchema()};
  return schemas[static_cast<int>(topic)];
}

const SchemaInfo& RequestSchema() {
  static const SchemaInfo s = Make(
      "robotalk.Request", "robotalk.Request: one package on ROBOTALK/ROBOT/REQUEST (docs/protocol.md)",
      Object({{"client", String()},
              {"sequence", Integer()},
              {"send_time_us", Integer()},
              {"panic", Boolean()},
              {"mode", String()},
              {"queries", ArrayOf(Object({{"id", Integer()}, {"type", String()}, {"target", String()}}))},
              {"commands", ArrayOf(Object({{"id", Integer()},
                                           {"type", String()},
                                           {"target", String()},
                                           {"start", String()},
                                           {"values", ArrayOf(Number())}}))}}));
  return s;
}

const SchemaInfo& ReplySchema() {
  static const SchemaInfo s =
      Make("robotalk.ReplyBatch",
           "robotalk.ReplyBatch: one message on ROBOTALK/ROBOT/REPLY/CLIENT (docs/protocol.md)",
           Object({{"client", String()},
                   {"ack_sequence", Integer()},
                   {"replies", ArrayOf(Object({{"id", Integer()},
                                               {"signal", String()},
                                               {"message", String()},
                                               {"exec_time_us", Integer()},
                                               {"values", ArrayOf(Number())}}))}}));
  return s;
}

json TimeJson(std::int64_t ns) {
  if (ns < 0) ns = 0;
  return {{"sec", ns / 1'000'000'000}, {"nsec", ns % 1'000'000'000}};
}

RobotMessages::RobotMessages(std::shared_ptr<const RobotModel> model, std::optional<MeshCatalog> geometry)
    : model_(std::move(model)), geometry_(std::move(geometry)), dof_names_(DofNames(*model_)) {
  const std::string prefix = model_->name() + "/";
  std::set<std::string> link_names;
  for (const Link& l : model_->links()) {
    link_frames_.push_back(prefix + l.name);
    link_names.insert(l.name);
  }
  for (const ControlFrame& f : model_->frames())
    control_frames_.push_back(prefix + (link_names.count(f.name) ? "frame:" : "") + f.name);
}

std::string RobotMessages::LinkFrame(std::size_t l) const { return link_frames_.at(l); }
std::string RobotMessages::ControlFrameId(std::size_t f) const { return control_frames_.at(f); }

json RobotMessages::InertiaEntity(std::size_t l, std::int64_t time_ns, const std::string& note) const {
  const Link& link = model_->links()[l];
  json e = Entity(time_ns, link_frames_[l], {KeyValue("geometry", "inertia box"), KeyValue("note", note)});
  const InertiaBox box = EquivalentInertiaBox(link);
  e["cubes"].push_back({{"pose", {{"position", Vec(link.com)}, {"orientation", Quat(box.rotation)}}},
                        {"size", Vec(box.sides)},
                        {"color", ColorJson(kInertiaColor)}});
  auto sphere = [&](const Eigen::Vector3d& at) {  // joint centres, as the page draws its bones
    return json{{"pose", {{"position", Vec(at)}, {"orientation", Quat(Eigen::Quaterniond::Identity())}}},
                {"size", Vec(Eigen::Vector3d::Constant(0.03))},
                {"color", ColorJson({0.95, 0.7, 0.2, 1.0})}};
  };
  for (const Joint& j : model_->joints()) {
    if (static_cast<std::size_t>(j.parent_link) == l) e["spheres"].push_back(sphere(link.com + j.inboard));
    if (static_cast<std::size_t>(j.child_link) == l) e["spheres"].push_back(sphere(link.com + j.outboard));
  }
  return e;
}

json RobotMessages::UrdfEntity(std::size_t l, std::int64_t time_ns, const MeshLinks& links) const {
  const std::string& name = model_->links()[l].name;
  const MeshCatalog& g = *geometry_;
  if (std::find(g.links.begin(), g.links.end(), name) == g.links.end())
    return InertiaEntity(l, time_ns,
                         "link '" + name + "' is not in the --urdf file: its equivalent inertia box");
  bool collision = false, visual = false;
  std::optional<Eigen::Vector4d> link_rgba;  // a collision shape takes its link's first visual colour
  for (const UrdfShape& s : g.shapes) {
    if (s.link != name) continue;
    collision = collision || s.collision;
    visual = visual || !s.collision;
    if (!s.collision && s.rgba && !link_rgba) link_rgba = s.rgba;
  }
  json e = Entity(time_ns, link_frames_[l],
                  {KeyValue("geometry", collision ? "urdf collision"
                                        : visual  ? "urdf visual"
                                                  : "none")});
  std::string mesh_errors;
  for (const UrdfShape& s : g.shapes) {
    if (s.link != name || s.collision != collision) continue;
    const std::optional<Eigen::Vector4d> rgba = s.rgba ? s.rgba : link_rgba;
    const json color = ColorJson(rgba.value_or(kUrdfColor));
    const double r = s.size.x();
    switch (s.kind) {
      case UrdfShape::Kind::kBox:
        e["cubes"].push_back({{"pose", PoseJson(s.origin)}, {"size", Vec(s.size)}, {"color", color}});
        break;
      case UrdfShape::Kind::kCylinder:
        e["cylinders"].push_back({{"pose", PoseJson(s.origin)},
                                  {"size", Vec({2 * r, 2 * r, s.size.y()})},
                                  {"bottom_scale", 1.0},
                                  {"top_scale", 1.0},
                                  {"color", color}});
        break;
      case UrdfShape::Kind::kSphere:
        e["spheres"].push_back({{"pose", PoseJson(s.origin)},
                                {"size", Vec(Eigen::Vector3d::Constant(2 * r))},
                                {"color", color}});
        break;
      case UrdfShape::Kind::kMesh: {
        const MeshEntry* m = g.MeshOf(s);
        std::variant<json, std::string> model = std::string("not in the mesh catalog");
        if (m && !m->url.empty()) model = Model(s, *m, links, rgba);
        if (const json* j = std::get_if<json>(&model))
          e["models"].push_back(*j);
        else
          mesh_errors += (mesh_errors.empty() ? "" : "; ") + s.mesh + ": " +
                         (m && !m->error.empty() ? m->error : std::get<std::string>(model));
        break;
      }
    }
  }
  if (!mesh_errors.empty()) {  // the link is still seen: its inertia box beside the reason
    e["cubes"].push_back(InertiaEntity(l, time_ns, "")["cubes"][0]);
    e["metadata"].push_back(KeyValue("mesh", mesh_errors + " (drawn as its equivalent inertia box)"));
  }
  return e;
}

json RobotMessages::Scene(std::int64_t time_ns, const MeshLinks& links) const {
  json entities = json::array();
  for (std::size_t l = 0; l < model_->links().size(); ++l) {
    if (!geometry_) {
      entities.push_back(InertiaEntity(l, time_ns,
                                       "the robot's configuration carries no geometry; give robotalk-web "
                                       "or robotalk-logplay export --urdf ROBOT=PATH to see the URDF's"));
    } else if (!geometry_->error.empty() || !geometry_->geometry_error.empty()) {
      entities.push_back(InertiaEntity(
          l, time_ns,
          "the --urdf file's geometry could not be read: " + geometry_->error + geometry_->geometry_error));
    } else {
      entities.push_back(UrdfEntity(l, time_ns, links));
    }
  }
  // A new model replaces the robot's scene: every entity of this topic older
  // than this one goes (type 1 = all), so links the old model had do not stay.
  const json deletion = {{"timestamp", TimeJson(time_ns)}, {"type", 1}, {"id", ""}};
  return {{"deletions", json::array({deletion})}, {"entities", entities}};
}

RobotMessages::State RobotMessages::FromPose(const json& pose) const {
  State s;
  const double t = Field(pose, "t").get<double>();
  // In the wire's range (seconds back to microseconds may round past it, and
  // nanoseconds beyond it overflow an int64).
  s.time_ns = std::clamp<std::int64_t>(std::llround(std::clamp(t * 1e6, -9.3e15, 9.3e15)), -kMaxWireMicros,
                                       kMaxWireMicros) *
              1000;
  const json& links = Field(pose, "links");
  if (!links.is_array() || links.size() != model_->links().size()) {
    throw Error("foxglove: state pose of robot '" + model_->name() + "' has " + std::to_string(links.size()) +
                " links, its model " + std::to_string(model_->links().size()));
  }
  std::vector<Eigen::Isometry3d> world;
  world.reserve(links.size());
  for (const json& l : links) world.push_back(PoseOf(l, "a link pose"));
  json transforms = json::array();
  for (const RootLink& root : model_->roots()) {
    const auto l = static_cast<std::size_t>(root.link);
    transforms.push_back(Transform(s.time_ns, "world", link_frames_[l], world[l]));
  }
  for (const Joint& j : model_->joints()) {
    const auto p = static_cast<std::size_t>(j.parent_link), c = static_cast<std::size_t>(j.child_link);
    transforms.push_back(
        Transform(s.time_ns, link_frames_[p], link_frames_[c], world[p].inverse() * world[c]));
  }
  for (std::size_t f = 0; f < model_->frames().size(); ++f) {
    const ControlFrame& frame = model_->frames()[f];
    transforms.push_back(Transform(s.time_ns, link_frames_[static_cast<std::size_t>(frame.parent_link)],
                                   control_frames_[f], frame.pose_in_link.ToIsometry()));
  }
  s.transforms = {{"transforms", std::move(transforms)}};
  s.joint_states = {{"timestamp", TimeJson(s.time_ns)},
                    {"robot", model_->name()},
                    {"name", dof_names_},
                    {"position", Field(pose, "q")}};
  const Eigen::Isometry3d& root = world[static_cast<std::size_t>(model_->roots().front().link)];
  s.base_pose = {
      {"timestamp", TimeJson(s.time_ns)},
      {"frame_id", "world"},
      {"pose",
       {{"position", Vec(root.translation())}, {"orientation", Quat(Eigen::Quaterniond(root.linear()))}}}};
  s.status = {{"timestamp", TimeJson(s.time_ns)}, {"robot", model_->name()},
              {"sample", Field(pose, "sample")},  {"period", Field(pose, "period")},
              {"panic", Field(pose, "panic")},    {"moving", Field(pose, "moving")},
              {"base", Field(pose, "base")}};
  return s;
}

}  // namespace robotalk::web::foxglove
