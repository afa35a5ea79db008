#include "dds_entities.h"

#include "robotalk/log_writer.h"

#include <dds/ddsrt/log.h>

#include <memory>
#include <mutex>
#include <string>
#include <string_view>

namespace robotalk::ros2 {

namespace {

std::string Reason(dds_return_t rc) { return dds_strretcode(rc); }

using QosPtr = std::unique_ptr<dds_qos_t, decltype(&dds_delete_qos)>;

// rmw_cyclonedds_cpp/src/rmw_node.cpp, create_readwrite_qos (Humble, Jazzy):
// the same history, reliability and durability mapping, auto-dispose off; and
// serdata.cpp's sertype allows XCDR1 only.
QosPtr MakeQos(RosQos ros) {
  QosPtr qos(dds_create_qos(), &dds_delete_qos);
  dds_qset_writer_data_lifecycle(qos.get(), false);
  dds_qset_history(qos.get(), DDS_HISTORY_KEEP_LAST, ros.depth);
  if (ros.reliable) {
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_RELIABLE, DDS_INFINITY);
  } else {
    dds_qset_reliability(qos.get(), DDS_RELIABILITY_BEST_EFFORT, 0);
  }
  if (ros.transient_local) {
    dds_qset_durability(qos.get(), DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_durability_service(qos.get(), DDS_SECS(0), DDS_HISTORY_KEEP_LAST, ros.depth,
                                DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED, DDS_LENGTH_UNLIMITED);
  } else {
    dds_qset_durability(qos.get(), DDS_DURABILITY_VOLATILE);
  }
  const dds_data_representation_id_t xcdr1 = DDS_DATA_REPRESENTATION_XCDR1;
  dds_qset_data_representation(qos.get(), 1, &xcdr1);
  return qos;
}

dds_entity_t CreateTopic(const DdsParticipant& participant, const dds_topic_descriptor_t& type,
                         const std::string& topic) {
  const dds_entity_t t = dds_create_topic(participant.handle(), &type, topic.c_str(), nullptr, nullptr);
  if (t < 0) {
    throw DdsError("DDS topic '" + topic + "' (" + type.m_typename + "): " + Reason(t));
  }
  return t;
}

}  // namespace

std::string DdsTopicName(const std::string& ros_topic) {
  return ros_topic.starts_with('/') ? "rt" + ros_topic : "rt/" + ros_topic;
}

std::string InterfaceConfig(const std::string& interface) {
  const bool address = !interface.empty() && std::isdigit(static_cast<unsigned char>(interface[0]));
  return "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface " +
         std::string(address ? "address" : "name") + "=\"" + interface +
         "\" multicast=\"true\"/></Interfaces></General></Domain></CycloneDDS>";
}

// Cyclone DDS's own lines (its configuration errors and warnings) through
// the process's one writer of stderr, as the bridge's: its default sink
// writes to stderr directly, and one that takes nothing held the bridge for
// ever (an error never ended it).
namespace {
void SayDds(void*, const dds_log_data_t* data) {
  std::string_view text(data->message, data->size);
  if (data->hdrsize <= text.size()) text.remove_prefix(data->hdrsize);  // its time and thread
  while (!text.empty() && text.back() == '\n') text.remove_suffix(1);
  LogWriter::Stderr().Write("Cyclone DDS: " + std::string(text));
}
}  // namespace

DdsParticipant::DdsParticipant(std::uint32_t domain, const std::string& config) {
  static std::once_flag sink;
  std::call_once(sink, [] { dds_set_log_sink(SayDds, nullptr); });
  if (!config.empty()) {
    const dds_entity_t d = dds_create_domain(domain, config.c_str());
    if (d < 0) throw DdsError("DDS domain " + std::to_string(domain) + " config: " + Reason(d));
  }
  participant_ = dds_create_participant(domain, nullptr, nullptr);
  if (participant_ < 0) {
    throw DdsError("cannot join DDS domain " + std::to_string(domain) + ": " + Reason(participant_) +
                   " (check CYCLONEDDS_URI and the network interface)");
  }
}

DdsParticipant::~DdsParticipant() { dds_delete(participant_); }

DdsWriter::DdsWriter(const DdsParticipant& participant, const dds_topic_descriptor_t& type,
                     const std::string& ros_topic, RosQos qos)
    : topic_(DdsTopicName(ros_topic)) {
  topic_entity_ = CreateTopic(participant, type, topic_);
  writer_ = dds_create_writer(participant.handle(), topic_entity_, MakeQos(qos).get(), nullptr);
  if (writer_ < 0) throw DdsError("DDS writer of '" + topic_ + "': " + Reason(writer_));
}

DdsWriter::~DdsWriter() {
  dds_delete(writer_);
  dds_delete(topic_entity_);
}

void DdsWriter::Write(const void* sample) {
  const dds_return_t rc = dds_write(writer_, sample);
  if (rc < 0) throw DdsError("DDS write on '" + topic_ + "': " + Reason(rc));
}

int DdsWriter::matched_readers() const {
  dds_publication_matched_status_t status{};
  if (dds_get_publication_matched_status(writer_, &status) < 0) return 0;
  return static_cast<int>(status.current_count);
}

DdsReader::DdsReader(const DdsParticipant& participant, const dds_topic_descriptor_t& type,
                     const std::string& ros_topic, RosQos qos, OnSample on_sample)
    : topic_(DdsTopicName(ros_topic)), on_sample_(std::move(on_sample)) {
  topic_entity_ = CreateTopic(participant, type, topic_);
  std::unique_ptr<dds_listener_t, decltype(&dds_delete_listener)> listener(dds_create_listener(this),
                                                                           &dds_delete_listener);
  dds_lset_data_available(listener.get(), &DdsReader::OnDataAvailable);
  reader_ = dds_create_reader(participant.handle(), topic_entity_, MakeQos(qos).get(), listener.get());
  if (reader_ < 0) {
    dds_delete(topic_entity_);
    throw DdsError("DDS reader of '" + topic_ + "': " + Reason(reader_));
  }
}

DdsReader::~DdsReader() {
  dds_delete(reader_);
  dds_delete(topic_entity_);
}

void DdsReader::OnDataAvailable(dds_entity_t reader, void* arg) {
  auto* self = static_cast<DdsReader*>(arg);
  void* samples[1] = {nullptr};
  dds_sample_info_t infos[1];
  for (;;) {
    const dds_return_t n = dds_take(reader, samples, infos, 1, 1);
    if (n <= 0) break;
    if (infos[0].valid_data) {
      try {
        self->on_sample_(samples[0]);
      } catch (...) {  // nothing crosses Cyclone's C code
        self->failures_.fetch_add(1);
      }
    }
    dds_return_loan(reader, samples, n);
    samples[0] = nullptr;
  }
}

}  // namespace robotalk::ros2
