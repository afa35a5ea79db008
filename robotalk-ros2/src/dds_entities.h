// A thin C++ layer over Eclipse Cyclone DDS's C API for what robotalk-ros2
// needs: a participant in a domain, and writers and readers of ROS 2 topics
// with the names, QoS and data representation rmw_cyclonedds_cpp uses, so a
// ROS 2 node (Humble, Jazzy) matches them as it matches another node's
// (docs/interop.md, "ROS 2", cites where each rule comes from):
// - topic "/x" is DDS topic "rt/x" (DdsTopicName);
// - type names are "<pkg>::msg::dds_::<Type>_" (the IDL's modules do that);
// - XCDR1 (plain CDR) only; no XTypes type information (idlc -t);
// - QoS as rmw_cyclonedds_cpp's create_readwrite_qos maps a ROS profile:
//   history keep-last(depth), reliable or best effort, volatile or
//   transient-local (with a durability service of the same history), no
//   auto-dispose.
//
// Thread safety: Cyclone's entities are thread-safe; Write may be called from
// any thread. A reader's callback runs on a Cyclone thread (one at a time per
// reader) and must not throw (a throw is caught and counted).
// Errors: constructors and Write throw DdsError naming the topic and
// Cyclone's reason.
#pragma once

#include "robotalk/error.h"

#include <dds/dds.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>

namespace robotalk::ros2 {

class DdsError : public Error {
 public:
  using Error::Error;
};

/// A ROS 2 QoS profile (the parts the bridge sets; deadline, lifespan and
/// liveliness stay at the defaults, as in rclcpp's profiles).
struct RosQos {
  bool reliable = true;
  bool transient_local = false;
  int depth = 10;
};
/// rclcpp::QoS(10) / SystemDefaultsQoS: joint_states, odom, joint_trajectory.
inline constexpr RosQos kDefaultQos{};
/// tf2_ros::DynamicBroadcasterQoS: QoS(100).
inline constexpr RosQos kTfQos{true, false, 100};
/// tf2_ros::StaticBroadcasterQoS and robot_state_publisher's
/// robot_description publisher: QoS(1).transient_local().
inline constexpr RosQos kLatchedQos{true, true, 1};
/// A reader that takes any writer, reliable or best effort (cmd_vel from
/// teleop tools of either kind).
inline constexpr RosQos kBestEffortReaderQos{false, false, 10};

/// The DDS topic of a ROS 2 topic name: "rt" + the fully qualified name
/// ("/tf" or "tf" -> "rt/tf").
std::string DdsTopicName(const std::string& ros_topic);

/// Cyclone's configuration text that binds DDS to one network interface
/// (name or address) with multicast allowed on it: what --dds-interface gives.
std::string InterfaceConfig(const std::string& interface);

class DdsParticipant {
 public:
  /// Joins DDS domain `domain` (ROS_DOMAIN_ID). `config`: Cyclone XML
  /// (InterfaceConfig) or "" for CYCLONEDDS_URI / Cyclone's defaults.
  DdsParticipant(std::uint32_t domain, const std::string& config);
  ~DdsParticipant();
  DdsParticipant(const DdsParticipant&) = delete;
  DdsParticipant& operator=(const DdsParticipant&) = delete;
  dds_entity_t handle() const { return participant_; }

 private:
  dds_entity_t participant_ = 0;
};

class DdsWriter {
 public:
  DdsWriter(const DdsParticipant& participant, const dds_topic_descriptor_t& type,
            const std::string& ros_topic, RosQos qos);
  ~DdsWriter();
  DdsWriter(const DdsWriter&) = delete;
  DdsWriter& operator=(const DdsWriter&) = delete;
  /// Serialises and sends `sample` (of the writer's type). Throws DdsError.
  void Write(const void* sample);
  /// Readers matched now (tests, diagnostics).
  int matched_readers() const;
  const std::string& topic() const { return topic_; }

 private:
  std::string topic_;
  dds_entity_t topic_entity_ = 0;
  dds_entity_t writer_ = 0;
};

class DdsReader {
 public:
  /// Called with each valid sample (a pointer to the IDL's C struct), on a
  /// Cyclone thread.
  using OnSample = std::function<void(const void* sample)>;
  DdsReader(const DdsParticipant& participant, const dds_topic_descriptor_t& type,
            const std::string& ros_topic, RosQos qos, OnSample on_sample);
  /// Deletes the reader; Cyclone waits for a callback in progress.
  ~DdsReader();
  DdsReader(const DdsReader&) = delete;
  DdsReader& operator=(const DdsReader&) = delete;
  const std::string& topic() const { return topic_; }
  /// Callbacks that threw (the exception is dropped: it must not cross Cyclone's C code).
  std::uint64_t callback_failures() const { return failures_.load(); }

 private:
  static void OnDataAvailable(dds_entity_t reader, void* self);

  std::string topic_;
  OnSample on_sample_;
  dds_entity_t topic_entity_ = 0;
  dds_entity_t reader_ = 0;
  std::atomic<std::uint64_t> failures_{0};
};

}  // namespace robotalk::ros2
