#include "foxglove_messages.h"

#include "robotalk/error.h"
#include "scene_json.h"

#include <Eigen/Geometry>

#include <cmath>
#include <set>

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
  json entity = Object({{"timestamp", TimeSchema()},
                        {"frame_id", String()},
                        {"id", String()},
                        {"lifetime", TimeSchema()},
                        {"frame_locked", Boolean()},
                        {"cubes", ArrayOf(cube)},
                        {"spheres", ArrayOf(cube)}});
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

RobotMessages::RobotMessages(std::shared_ptr<const RobotModel> model)
    : model_(std::move(model)), dof_names_(DofNames(*model_)) {
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

json RobotMessages::Scene(std::int64_t time_ns) const {
  const json body_color = {{"r", 0.45}, {"g", 0.6}, {"b", 0.8}, {"a", 0.7}};
  const json joint_color = {{"r", 0.95}, {"g", 0.7}, {"b", 0.2}, {"a", 1.0}};
  std::vector<json> spheres(model_->links().size(), json::array());
  const double r = 0.03;
  auto sphere = [&](const Eigen::Vector3d& at) {
    return json{{"pose", {{"position", Vec(at)}, {"orientation", Quat(Eigen::Quaterniond::Identity())}}},
                {"size", Vec(Eigen::Vector3d::Constant(r))},
                {"color", joint_color}};
  };
  for (const Joint& j : model_->joints()) {  // joint centres, as the page draws its bones
    spheres[static_cast<std::size_t>(j.parent_link)].push_back(
        sphere(model_->link(j.parent_link).com + j.inboard));
    spheres[static_cast<std::size_t>(j.child_link)].push_back(
        sphere(model_->link(j.child_link).com + j.outboard));
  }
  json entities = json::array();
  for (std::size_t l = 0; l < model_->links().size(); ++l) {
    const Link& link = model_->links()[l];
    const InertiaBox box = EquivalentInertiaBox(link);
    const json cube = {{"pose", {{"position", Vec(link.com)}, {"orientation", Quat(box.rotation)}}},
                       {"size", Vec(box.sides)},
                       {"color", body_color}};
    entities.push_back({{"timestamp", TimeJson(time_ns)},
                        {"frame_id", link_frames_[l]},
                        {"id", link_frames_[l]},
                        {"lifetime", TimeJson(0)},
                        {"frame_locked", true},
                        {"cubes", json::array({cube})},
                        {"spheres", spheres[l]}});
  }
  // A new model replaces the robot's scene: every entity of this topic older
  // than this one goes (type 1 = all), so links the old model had do not stay.
  const json deletion = {{"timestamp", TimeJson(time_ns)}, {"type", 1}, {"id", ""}};
  return {{"deletions", json::array({deletion})}, {"entities", entities}};
}

RobotMessages::State RobotMessages::FromPose(const json& pose) const {
  State s;
  const double t = Field(pose, "t").get<double>();
  s.time_ns = static_cast<std::int64_t>(std::llround(t * 1e6)) * 1000;
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
