#include "config_codec.h"

#include "robotalk/broadcast_signature.h"

#include "robotalk/error.h"
#include "robotalk/transport.h"
#include "wire_scanner.h"

#include <algorithm>
#include <cinttypes>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

namespace robotalk {
namespace {

namespace msgs = robotalk_msgs;

constexpr std::int32_t kFormatVersion = 1;
// LCM prefixes every encoded message with its 8-byte type fingerprint.
constexpr std::size_t kFingerprintSize = 8;
// header.hash follows the fingerprint and header.format_version (int32).
constexpr std::size_t kHashOffset = kFingerprintSize + 4;
constexpr std::size_t kHashSize = 8;
// An LCM string is an int32 length (including the trailing NUL), the bytes, a NUL.
constexpr std::uint64_t kFnvOffsetBasis = 0xcbf29ce484222325ULL;
constexpr std::uint64_t kFnvPrime = 0x100000001b3ULL;

std::string Hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "0x%016" PRIx64, v);
  return buf;
}

std::string Quote(std::string_view s) { return "'" + std::string(s) + "'"; }

std::string Element(const char* block, std::size_t i) {
  return std::string(block) + "[" + std::to_string(i) + "]";
}

[[noreturn]] void Protocol(const char* function, const std::string& what) {
  throw ProtocolError(std::string(function) + ": " + what);
}

std::uint64_t Fnv1a64(const std::uint8_t* data, std::size_t size) {
  std::uint64_t h = kFnvOffsetBasis;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= kFnvPrime;
  }
  return h;
}

// --- Message -> bytes -------------------------------------------------------

// EncodeMessage (transport.h): sizes and counts must already agree with the
// vectors (the generated encoder indexes the vectors by the count fields) and
// names must hold no NUL byte (it measures strings with strlen but sizes them
// with size()); ToMessage makes both so.

// The hash definition (docs/configuration_message.md): FNV-1a 64 over the
// whole encoding, fingerprint included, with the 8 bytes of header.hash zero.
std::uint64_t HashOfEncoding(std::vector<std::uint8_t> bytes) {
  std::memset(bytes.data() + kHashOffset, 0, kHashSize);
  return Fnv1a64(bytes.data(), bytes.size());
}

struct Offsets {
  std::int64_t links, joints, frames, roots;
};

// Byte offsets of the four count fields, from the generated types' sizes of
// everything before them. Uses the vectors, which the caller has checked
// against the counts.
Offsets BlockOffsets(const msgs::robot_config_t& msg) {
  Offsets o{};
  std::int64_t pos = static_cast<std::int64_t>(kFingerprintSize) + msg.header._getEncodedSizeNoHash() +
                     kLcmStringOverhead + static_cast<std::int64_t>(msg.robot_name.size());
  o.links = pos;
  pos += 4;
  for (const auto& l : msg.links) pos += l._getEncodedSizeNoHash();
  o.joints = pos;
  pos += 4;
  for (const auto& j : msg.joints) pos += j._getEncodedSizeNoHash();
  o.frames = pos;
  pos += 4;
  for (const auto& f : msg.frames) pos += f._getEncodedSizeNoHash();
  o.roots = pos;
  return o;
}

void CheckName(const std::string& name, const std::string& what) {
  if (name.find('\0') != std::string::npos) {
    throw ModelError("ToMessage: " + what + " " + Quote(name.c_str()) +
                     "... contains a NUL byte, which an LCM string cannot carry");
  }
}

void Put(double (&out)[3], const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

void PutQuaternion(double (&out)[4], const Eigen::Quaterniond& q) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

// --- Bytes -> message: a bounded pre-scan ----------------------------------
//
// LCM's generated _decodeNoHash trusts every count: it resizes a vector to a
// hostile num_links of 2^31 before noticing the bytes ran out, and a negative
// string length or num_dofs throws std::length_error. So DecodeConfig first
// walks the bytes with this scanner, which mirrors robot_config_t.lcm, checks
// each count against the bytes left (count * smallest element size) and each
// string's length and terminator, and only then lets LCM decode. Allocation is
// thereby bounded by a small multiple of the input size.

// Fixed parts of the element types, from robotalk_msgs/*.lcm. The name string
// comes first in link_t, joint_t and control_frame_t.
constexpr std::int64_t kJointBeforeNumDofs = 4 + 4 + 8 * (3 + 3 + 4) + 1;  // links, geometry, servo_types
constexpr std::int64_t kJointAfterDofs = 4 + 8 + 8;                        // mimic leader, multiplier, offset

struct ElementSizes {
  std::int64_t link_fixed, dof, frame_fixed, root, header;
};

const ElementSizes& Sizes() {
  static const ElementSizes sizes = [] {
    ElementSizes s{};
    s.link_fixed = msgs::link_t{}._getEncodedSizeNoHash() - kLcmStringOverhead;
    s.dof = msgs::dof_t{}._getEncodedSizeNoHash();
    s.frame_fixed = msgs::control_frame_t{}._getEncodedSizeNoHash() - kLcmStringOverhead;
    s.root = msgs::root_link_t{}._getEncodedSizeNoHash();
    s.header = msgs::config_header_t{}._getEncodedSizeNoHash();
    // The scanner hard-codes joint_t's layout around its dof array; a change
    // of joint_t.lcm without a change here is a programming error.
    if (msgs::joint_t{}._getEncodedSizeNoHash() !=
        kLcmStringOverhead + kJointBeforeNumDofs + 1 + kJointAfterDofs) {
      std::fprintf(stderr, "robotalk: config_codec.cpp scanner is out of date with joint_t.lcm\n");
      std::abort();
    }
    return s;
  }();
  return sizes;
}

void CheckFingerprint(WireScanner& s) {
  const std::int64_t fingerprint = s.Int64("fingerprint");
  if (fingerprint != msgs::robot_config_t::getHash()) {
    s.Fail("fingerprint", Hex(static_cast<std::uint64_t>(fingerprint)) + " is not robot_config_t's " +
                              Hex(static_cast<std::uint64_t>(msgs::robot_config_t::getHash())));
  }
}

// Walks a whole robot_config_t; returns its length. Throws ProtocolError.
std::size_t ScanConfig(std::span<const std::uint8_t> bytes) {
  const ElementSizes& z = Sizes();
  WireScanner s("DecodeConfig", bytes);
  CheckFingerprint(s);
  s.Skip(z.header, "header");
  s.String("robot_name");

  const std::int32_t num_links = s.Count("num_links", kLcmStringOverhead + z.link_fixed);
  for (std::int32_t i = 0; i < num_links; ++i) {
    s.SetContext(Element("links", static_cast<std::size_t>(i)));
    s.String("name");
    s.Skip(z.link_fixed, "mass, com, inertia");
  }
  s.SetContext({});
  const std::int32_t num_joints =
      s.Count("num_joints", kLcmStringOverhead + kJointBeforeNumDofs + 1 + kJointAfterDofs);
  for (std::int32_t i = 0; i < num_joints; ++i) {
    s.SetContext(Element("joints", static_cast<std::size_t>(i)));
    s.String("name");
    s.Skip(kJointBeforeNumDofs, "links, geometry, servo_types");
    const std::int8_t num_dofs = s.Int8("num_dofs");
    if (num_dofs < 0 || num_dofs > kMaxDofsPerJoint) {
      s.Fail("num_dofs", std::to_string(num_dofs) + " is outside 0.." + std::to_string(kMaxDofsPerJoint));
    }
    s.Skip(num_dofs * z.dof, "dofs");
    s.Skip(kJointAfterDofs, "mimic");
  }
  s.SetContext({});
  const std::int32_t num_frames = s.Count("num_frames", kLcmStringOverhead + z.frame_fixed);
  for (std::int32_t i = 0; i < num_frames; ++i) {
    s.SetContext(Element("frames", static_cast<std::size_t>(i)));
    s.String("name");
    s.Skip(z.frame_fixed, "parent_link, pose, servo_types");
  }
  s.SetContext({});
  const std::int32_t num_roots = s.Count("num_roots", z.root);
  s.Skip(num_roots * z.root, "roots");
  if (s.left() != 0) {
    s.Fail("end", std::to_string(s.left()) + " trailing bytes after the " + std::to_string(s.pos()) +
                      "-byte message");
  }
  return s.pos();
}

// --- Message checks ----------------------------------------------------------

constexpr const char* kFrom = "FromMessage";

void CheckCount(const char* block, std::int32_t header_count, std::int32_t count, std::size_t size) {
  const std::string field = std::string("num_") + block;
  if (count < 0) Protocol(kFrom, field + " = " + std::to_string(count) + " is negative");
  if (static_cast<std::size_t>(count) != size) {
    Protocol(kFrom, field + " = " + std::to_string(count) + " but " + block + " has " + std::to_string(size) +
                        " elements");
  }
  if (header_count != count) {
    Protocol(kFrom, "header." + field + " = " + std::to_string(header_count) + " but " + field + " = " +
                        std::to_string(count));
  }
}

void CheckOffset(const char* field, std::int32_t header_value, std::int64_t actual) {
  if (header_value != actual) {
    Protocol(kFrom, std::string("header.") + field + " = " + std::to_string(header_value) +
                        " but the block starts at byte " + std::to_string(actual));
  }
}

void CheckWireName(const std::string& name, const std::string& field) {
  if (name.find('\0') != std::string::npos) Protocol(kFrom, field + " contains a NUL byte");
}

void CheckIndex(std::int32_t index, std::size_t size, const std::string& field, const char* block) {
  if (index < 0 || static_cast<std::size_t>(index) >= size) {
    Protocol(kFrom, field + " = " + std::to_string(index) + " is not an index into " + block + " (size " +
                        std::to_string(size) + ")");
  }
}

void CheckServo(std::int8_t bits, const std::string& field) {
  if ((static_cast<std::uint8_t>(bits) & ~0x7u) != 0) {
    Protocol(kFrom,
             field + " = " + std::to_string(bits) + " has bits outside SERVO_SETPOINT|SPEED|FORCE (0..7)");
  }
}

Eigen::Vector3d Vec3(const double (&v)[3]) { return {v[0], v[1], v[2]}; }
Eigen::Quaterniond Quat(const double (&q)[4]) { return {q[0], q[1], q[2], q[3]}; }  // w x y z

// Structure, counts, offsets and hash: everything about the message as a
// message, before any of it is trusted.
void CheckEnvelope(const msgs::robot_config_t& msg) {
  const msgs::config_header_t& h = msg.header;
  if (h.format_version != kFormatVersion) {
    Protocol(kFrom, "header.format_version = " + std::to_string(h.format_version) +
                        " is not supported (this build reads " + std::to_string(kFormatVersion) + ")");
  }
  CheckCount("links", h.num_links, msg.num_links, msg.links.size());
  CheckCount("joints", h.num_joints, msg.num_joints, msg.joints.size());
  CheckCount("frames", h.num_frames, msg.num_frames, msg.frames.size());
  CheckCount("roots", h.num_roots, msg.num_roots, msg.roots.size());

  CheckWireName(msg.robot_name, "robot_name");
  std::int64_t total_dofs = 0;
  for (std::size_t i = 0; i < msg.links.size(); ++i)
    CheckWireName(msg.links[i].name, Element("links", i) + ".name");
  for (std::size_t i = 0; i < msg.joints.size(); ++i) {
    const msgs::joint_t& j = msg.joints[i];
    const std::string what = Element("joints", i);
    CheckWireName(j.name, what + ".name");
    if (j.num_dofs < 0 || j.num_dofs > kMaxDofsPerJoint) {
      Protocol(kFrom, what + ".num_dofs = " + std::to_string(j.num_dofs) + " is outside 0.." +
                          std::to_string(kMaxDofsPerJoint));
    }
    if (static_cast<std::size_t>(j.num_dofs) != j.dofs.size()) {
      Protocol(kFrom, what + ".num_dofs = " + std::to_string(j.num_dofs) + " but dofs has " +
                          std::to_string(j.dofs.size()) + " elements");
    }
    total_dofs += j.num_dofs;
  }
  for (std::size_t i = 0; i < msg.frames.size(); ++i)
    CheckWireName(msg.frames[i].name, Element("frames", i) + ".name");
  if (h.total_dofs != total_dofs) {
    Protocol(kFrom, "header.total_dofs = " + std::to_string(h.total_dofs) + " but the joints have " +
                        std::to_string(total_dofs) + " dofs");
  }

  const Offsets o = BlockOffsets(msg);
  CheckOffset("link_block_offset", h.link_block_offset, o.links);
  CheckOffset("joint_block_offset", h.joint_block_offset, o.joints);
  CheckOffset("frame_block_offset", h.frame_block_offset, o.frames);
  CheckOffset("root_block_offset", h.root_block_offset, o.roots);

  const std::uint64_t hash = HashOfEncoding(EncodeMessage(msg));
  if (static_cast<std::uint64_t>(h.hash) != hash) {
    Protocol(kFrom, "header.hash = " + Hex(static_cast<std::uint64_t>(h.hash)) +
                        " but the message hashes to " + Hex(hash));
  }
}

}  // namespace

robotalk_msgs::robot_config_t ToMessage(const RobotModel& model) {
  msgs::robot_config_t msg{};
  CheckName(model.name(), "robot name");
  msg.robot_name = model.name();

  for (const Link& link : model.links()) {
    CheckName(link.name, "link name");
    msgs::link_t& m = msg.links.emplace_back();
    m.name = link.name;
    m.mass = link.mass;
    Put(m.com, link.com);
    // Upper triangle; RobotModel guarantees exact symmetry.
    const Eigen::Matrix3d& I = link.inertia;
    const double inertia[6] = {I(0, 0), I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2)};
    std::copy(std::begin(inertia), std::end(inertia), std::begin(m.inertia));
  }

  for (const Joint& joint : model.joints()) {
    CheckName(joint.name, "joint name");
    msgs::joint_t& m = msg.joints.emplace_back();
    m.name = joint.name;
    m.parent_link = joint.parent_link;
    m.child_link = joint.child_link;
    Put(m.inboard, joint.inboard);
    Put(m.outboard, joint.outboard);
    PutQuaternion(m.rest, joint.rest);
    m.servo_types = static_cast<std::int8_t>(joint.servo_types.bits());
    m.num_dofs = static_cast<std::int8_t>(joint.dofs.size());
    for (const Dof& dof : joint.dofs) {
      msgs::dof_t& d = m.dofs.emplace_back();
      d.type = static_cast<std::int8_t>(dof.type);
      Put(d.axis, dof.axis);
      d.lower = dof.limits.lower;
      d.upper = dof.limits.upper;
      d.velocity = dof.limits.velocity;
      d.effort = dof.limits.effort;
    }
    // Without a mimic the fields hold the identity mapping, so the encoding
    // (and the hash) of a model is unique.
    const Mimic mimic = joint.mimic.value_or(Mimic{});
    m.mimic_leader = joint.mimic ? mimic.leader_joint : -1;
    m.mimic_multiplier = mimic.multiplier;
    m.mimic_offset = mimic.offset;
  }

  for (const ControlFrame& frame : model.frames()) {
    CheckName(frame.name, "control frame name");
    msgs::control_frame_t& m = msg.frames.emplace_back();
    m.name = frame.name;
    m.parent_link = frame.parent_link;
    Put(m.position, frame.pose_in_link.translation);
    PutQuaternion(m.orientation, frame.pose_in_link.rotation);
    m.servo_types = static_cast<std::int8_t>(frame.servo_types.bits());
  }

  for (const RootLink& root : model.roots()) {
    msgs::root_link_t& m = msg.roots.emplace_back();
    m.link = root.link;
    Put(m.position, root.pose_in_world.translation);
    PutQuaternion(m.orientation, root.pose_in_world.rotation);
    m.base_type = static_cast<std::int8_t>(root.base);
  }

  msg.num_links = static_cast<std::int32_t>(msg.links.size());
  msg.num_joints = static_cast<std::int32_t>(msg.joints.size());
  msg.num_frames = static_cast<std::int32_t>(msg.frames.size());
  msg.num_roots = static_cast<std::int32_t>(msg.roots.size());

  msgs::config_header_t& h = msg.header;
  h.format_version = kFormatVersion;
  h.total_dofs = model.num_dofs();
  h.num_links = msg.num_links;
  h.num_joints = msg.num_joints;
  h.num_frames = msg.num_frames;
  h.num_roots = msg.num_roots;
  const Offsets o = BlockOffsets(msg);
  if (o.roots > INT32_MAX)
    throw ModelError("ToMessage: robot " + Quote(model.name()) + " is too big to encode");
  h.link_block_offset = static_cast<std::int32_t>(o.links);
  h.joint_block_offset = static_cast<std::int32_t>(o.joints);
  h.frame_block_offset = static_cast<std::int32_t>(o.frames);
  h.root_block_offset = static_cast<std::int32_t>(o.roots);
  h.hash = 0;
  h.hash = static_cast<std::int64_t>(HashOfEncoding(EncodeMessage(msg)));
  return msg;
}

RobotModel FromMessage(const robotalk_msgs::robot_config_t& msg) {
  CheckEnvelope(msg);

  const std::size_t num_links = msg.links.size();
  const std::size_t num_joints = msg.joints.size();
  std::vector<Link> links;
  links.reserve(num_links);
  for (const msgs::link_t& m : msg.links) {
    Link& l = links.emplace_back();
    l.name = m.name;
    l.mass = m.mass;
    l.com = Vec3(m.com);
    const double* I = m.inertia;    // ixx ixy ixz iyy iyz izz
    l.inertia << I[0], I[1], I[2],  //
        I[1], I[3], I[4],           //
        I[2], I[4], I[5];
  }

  std::vector<Joint> joints;
  joints.reserve(num_joints);
  for (std::size_t i = 0; i < num_joints; ++i) {
    const msgs::joint_t& m = msg.joints[i];
    const std::string what = Element("joints", i);
    CheckIndex(m.parent_link, num_links, what + ".parent_link", "links");
    CheckIndex(m.child_link, num_links, what + ".child_link", "links");
    CheckServo(m.servo_types, what + ".servo_types");
    Joint& j = joints.emplace_back();
    j.name = m.name;
    j.parent_link = m.parent_link;
    j.child_link = m.child_link;
    j.inboard = Vec3(m.inboard);
    j.outboard = Vec3(m.outboard);
    j.rest = Quat(m.rest);
    j.servo_types = ServoTypes::FromBits(static_cast<std::uint8_t>(m.servo_types));
    for (std::size_t k = 0; k < m.dofs.size(); ++k) {
      const msgs::dof_t& d = m.dofs[k];
      if (d.type != msgs::dof_t::REVOLUTE && d.type != msgs::dof_t::PRISMATIC) {
        Protocol(kFrom, what + ".dofs[" + std::to_string(k) + "].type = " + std::to_string(d.type) +
                            " is neither REVOLUTE (0) nor PRISMATIC (1)");
      }
      j.dofs.push_back(
          Dof{.type = static_cast<DofType>(d.type),
              .axis = Vec3(d.axis),
              .limits = {.lower = d.lower, .upper = d.upper, .velocity = d.velocity, .effort = d.effort}});
    }
    if (m.mimic_leader == -1) {
      if (m.mimic_multiplier != 1.0 || m.mimic_offset != 0.0) {
        Protocol(kFrom,
                 what +
                     ": mimic_leader = -1 (no mimic) needs mimic_multiplier = 1 and mimic_offset = 0, has " +
                     std::to_string(m.mimic_multiplier) + " and " + std::to_string(m.mimic_offset));
      }
    } else {
      CheckIndex(m.mimic_leader, num_joints, what + ".mimic_leader", "joints (or -1)");
      j.mimic =
          Mimic{.leader_joint = m.mimic_leader, .multiplier = m.mimic_multiplier, .offset = m.mimic_offset};
    }
  }

  std::vector<ControlFrame> frames;
  frames.reserve(msg.frames.size());
  for (std::size_t i = 0; i < msg.frames.size(); ++i) {
    const msgs::control_frame_t& m = msg.frames[i];
    const std::string what = Element("frames", i);
    CheckIndex(m.parent_link, num_links, what + ".parent_link", "links");
    CheckServo(m.servo_types, what + ".servo_types");
    frames.push_back(
        ControlFrame{.name = m.name,
                     .parent_link = m.parent_link,
                     .pose_in_link = {Vec3(m.position), Quat(m.orientation)},
                     .servo_types = ServoTypes::FromBits(static_cast<std::uint8_t>(m.servo_types))});
  }

  std::vector<RootLink> roots;
  roots.reserve(msg.roots.size());
  for (std::size_t i = 0; i < msg.roots.size(); ++i) {
    const msgs::root_link_t& m = msg.roots[i];
    const std::string what = Element("roots", i);
    CheckIndex(m.link, num_links, what + ".link", "links");
    if (m.base_type < msgs::root_link_t::BASE_FIXED || m.base_type > msgs::root_link_t::BASE_FLOATING) {
      Protocol(kFrom, what + ".base_type = " + std::to_string(m.base_type) + " is not a BASE_* value (0..3)");
    }
    roots.push_back(RootLink{.link = m.link,
                             .pose_in_world = {Vec3(m.position), Quat(m.orientation)},
                             .base = static_cast<BaseType>(m.base_type)});
  }

  RobotModel model(msg.robot_name, std::move(links), std::move(joints), std::move(frames), std::move(roots));

  // The message must be the model's unique encoding, so that one robot has
  // one hash. RobotModel appends a fixed root for every unlisted parentless
  // link; a message must list them all.
  if (model.roots().size() != msg.roots.size()) {
    Protocol(kFrom, "num_roots = " + std::to_string(msg.num_roots) + " but robot " + Quote(msg.robot_name) +
                        " has " + std::to_string(model.roots().size()) +
                        " parentless links; every one must be listed");
  }
  const std::uint64_t canonical = ConfigHash(model);
  if (canonical != static_cast<std::uint64_t>(msg.header.hash)) {
    Protocol(kFrom, "the message is not the canonical encoding of robot " + Quote(msg.robot_name) +
                        " (header.hash " + Hex(static_cast<std::uint64_t>(msg.header.hash)) + ", canonical " +
                        Hex(canonical) + ")");
  }
  return model;
}

std::vector<std::uint8_t> EncodeConfig(const RobotModel& model) { return EncodeMessage(ToMessage(model)); }

RobotModel DecodeConfig(std::span<const std::uint8_t> bytes) {
  bytes = WithoutSignature(bytes);  // a keyed server's; verified (or not) by the caller
  if (bytes.size() > static_cast<std::size_t>(INT_MAX)) {
    Protocol("DecodeConfig", std::to_string(bytes.size()) + " bytes is more than an LCM message can hold");
  }
  const std::size_t length = ScanConfig(bytes);
  msgs::robot_config_t msg;
  const int decoded = msg.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
  if (decoded < 0 || static_cast<std::size_t>(decoded) != length) {
    // The scanner accepted what LCM refused: the two disagree on the layout.
    Protocol("DecodeConfig", "LCM decoded " + std::to_string(decoded) + " bytes where the scan found " +
                                 std::to_string(length));
  }
  return FromMessage(msg);
}

robotalk_msgs::config_header_t DecodeConfigHeader(std::span<const std::uint8_t> bytes) {
  const ElementSizes& z = Sizes();
  WireScanner s("DecodeConfigHeader", bytes);
  CheckFingerprint(s);
  const std::size_t start = s.pos();
  s.Skip(z.header, "header");
  msgs::config_header_t header;
  if (header._decodeNoHash(bytes.data(), static_cast<int>(start), static_cast<int>(z.header)) != z.header) {
    s.Fail("header", "LCM could not decode it");
  }
  if (header.format_version != kFormatVersion) {
    Protocol("DecodeConfigHeader", "header.format_version = " + std::to_string(header.format_version) +
                                       " is not supported (this build reads " +
                                       std::to_string(kFormatVersion) + ")");
  }
  return header;
}

std::uint64_t DecodeConfigHash(std::span<const std::uint8_t> bytes) {
  return static_cast<std::uint64_t>(DecodeConfigHeader(bytes).hash);
}

std::uint64_t ConfigHash(const RobotModel& model) {
  return static_cast<std::uint64_t>(ToMessage(model).header.hash);
}

}  // namespace robotalk
