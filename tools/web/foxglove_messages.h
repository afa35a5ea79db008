// What robotalk-web's Foxglove endpoint (foxglove_endpoint.h) and
// `robotalk-logplay export --mcap` (tools/logplay/mcap_export.h) publish,
// as JSON messages with JSON Schemas (docs/interop.md): one set of channels per
// robot, built here once so that a recorded session plays back in Foxglove
// exactly as it showed live.
//
//   /ROBOT/tf            foxglove.FrameTransforms  world -> root link, parent link -> child
//                                                   link per joint, link -> control frame
//   /ROBOT/scene         foxglove.SceneUpdate      one entity per link, locked to the link's
//                                                   frame: with the robot's URDF (--urdf) its
//                                                   <collision> shapes (its <visual> ones when
//                                                   it has none) as cubes, cylinders, spheres
//                                                   and models (meshes), in the <visual>
//                                                   material's colour; without one its
//                                                   equivalent inertia box and spheres at its
//                                                   joint centres. Each entity's metadata says
//                                                   which ("geometry"). Sent when the model is
//                                                   known and to each new subscriber, never
//                                                   with a state; it deletes the topic's older
//                                                   entities
//   /ROBOT/joint_states  robotalk.JointState       dof names and positions (rad | m)
//   /ROBOT/base_pose     foxglove.PoseInFrame      the first root link's pose in "world"
//   /ROBOT/status        robotalk.RobotStatus      sample, panic, moving, base x y θ v ω
//
// Frame ids are "ROBOT/LINK" and "ROBOT/FRAME" (a control frame that shares
// a link's name is "ROBOT/frame:FRAME"), so several robots share one scene.
// Times are {"sec", "nsec"} on the server clock (the sample's), as Foxglove's
// JSON schemas write a time.
//
// Thread safety: pure functions; a RobotMessages is immutable after
// construction. Errors: FromPose throws robotalk::Error naming the field when
// a pose object lacks one or has the wrong number of links (another model's).
#pragma once

#include "mesh_catalog.h"
#include "robotalk/robot_model.h"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace robotalk::web::foxglove {

/// The per-robot channels, in advertising order.
enum class Topic { kTransforms, kScene, kJointStates, kBasePose, kStatus };
inline constexpr std::array<Topic, 5> kRobotTopics = {Topic::kTransforms, Topic::kScene, Topic::kJointStates,
                                                      Topic::kBasePose, Topic::kStatus};

/// A message type as both Foxglove's WebSocket protocol and MCAP describe it:
/// encoding "json", schema encoding "jsonschema".
struct SchemaInfo {
  std::string name;    ///< "foxglove.FrameTransforms", "robotalk.JointState", ...
  std::string schema;  ///< the JSON Schema, as text
};

/// "/ROBOT/tf", "/ROBOT/scene", ...
std::string TopicName(const std::string& robot, Topic topic);
const SchemaInfo& SchemaOf(Topic topic);
/// The raw RoboTalk traffic of a recorded session (MCAP only): one package
/// (robotalk.Request) and one reply batch (robotalk.ReplyBatch) as JSON.
const SchemaInfo& RequestSchema();
const SchemaInfo& ReplySchema();

/// {"sec", "nsec"} of `ns` nanoseconds (negative times clamp to 0).
nlohmann::json TimeJson(std::int64_t ns);

/// How a scene refers to a mesh file of the robot's MeshCatalog.
struct MeshLinks {
  /// Live: the model's `url` is url_base + the catalog's url
  /// ("http://HOST:PORT", where robotalk-web serves it).
  std::string url_base;
  /// MCAP: the file's bytes go in the model's `data` (base64), so that the
  /// recording plays back anywhere; a .gltf, which names files beside it,
  /// is referred to as file://PATH instead.
  bool embed = false;
  /// The largest mesh file embedded (a recording holds each once per
  /// scene): a larger one is drawn as its link's inertia box, the scene's
  /// metadata saying why, rather than growing the file without bound.
  std::uintmax_t max_embedded_bytes = std::uintmax_t{32} << 20;
};

/// One robot's messages for one model.
class RobotMessages {
 public:
  /// `geometry`: the robot's URDF as ResolveMeshes read it; none: the scene
  /// shows equivalent inertia boxes (the configuration carries no geometry).
  explicit RobotMessages(std::shared_ptr<const RobotModel> model, std::optional<MeshCatalog> geometry = {});

  const RobotModel& model() const { return *model_; }
  /// The frame id of link `l`, of control frame `f`.
  std::string LinkFrame(std::size_t l) const;
  std::string ControlFrameId(std::size_t f) const;

  /// The foxglove.SceneUpdate of the model, stamped `time_ns`. Reads the
  /// mesh files when `links.embed`.
  nlohmann::json Scene(std::int64_t time_ns, const MeshLinks& links = {}) const;

  struct State {
    std::int64_t time_ns = 0;  ///< the sample's server time
    nlohmann::json transforms, joint_states, base_pose, status;
  };
  /// The messages of one state, from a StatePoser::Pose() object
  /// ({"t", "sample", "panic", "moving", "period", "base", "q", "links"}).
  State FromPose(const nlohmann::json& pose) const;

 private:
  nlohmann::json InertiaEntity(std::size_t l, std::int64_t time_ns, const std::string& note) const;
  nlohmann::json UrdfEntity(std::size_t l, std::int64_t time_ns, const MeshLinks& links) const;

  std::shared_ptr<const RobotModel> model_;
  std::optional<MeshCatalog> geometry_;
  std::vector<std::string> link_frames_, control_frames_, dof_names_;
};

}  // namespace robotalk::web::foxglove
