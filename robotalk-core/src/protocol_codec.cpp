#include "robotalk/protocol_codec.h"

#include "robotalk/error.h"

#include <cstring>

namespace robotalk {
namespace {

// Walks LCM's big-endian encoding with bounds checks (see the header).
class WireWalker {
 public:
  WireWalker(std::span<const std::uint8_t> bytes, const char* message) : bytes_(bytes), message_(message) {}

  void Skip(size_t n, const char* field) {
    if (n > bytes_.size() - pos_) Fail(std::string(field) + " needs " + std::to_string(n) + " bytes");
    pos_ += n;
  }
  std::int64_t ReadInt(size_t n, const char* field) {
    if (n > bytes_.size() - pos_) Fail(std::string(field) + " needs " + std::to_string(n) + " bytes");
    std::uint64_t v = 0;
    for (size_t i = 0; i < n; ++i) v = (v << 8) | bytes_[pos_ + i];
    pos_ += n;
    // Sign-extend from n bytes.
    const unsigned shift = static_cast<unsigned>(64 - 8 * n);
    return static_cast<std::int64_t>(v << shift) >> shift;
  }
  void SkipString(const char* field) {
    const std::int64_t len = ReadInt(4, field);
    if (len < 1) Fail(std::string(field) + " has invalid length " + std::to_string(len));
    Skip(static_cast<size_t>(len), field);
  }
  // An array count: non-negative and small enough that every element (at
  // least `min_element_bytes` each) can still fit in what is left.
  std::int64_t ReadCount(size_t n, const char* field, size_t min_element_bytes) {
    const std::int64_t count = ReadInt(n, field);
    if (count < 0) Fail(std::string(field) + " is negative (" + std::to_string(count) + ")");
    if (static_cast<std::uint64_t>(count) * min_element_bytes > bytes_.size() - pos_) {
      Fail(std::string(field) + " = " + std::to_string(count) + " does not fit in the " +
           std::to_string(bytes_.size() - pos_) + " bytes left");
    }
    return count;
  }
  void ExpectEnd() {
    if (pos_ != bytes_.size()) Fail(std::to_string(bytes_.size() - pos_) + " trailing bytes");
  }
  [[noreturn]] void Fail(const std::string& what) const {
    throw ProtocolError(std::string(message_) + ": malformed message (" + std::to_string(bytes_.size()) +
                        " bytes): " + what);
  }

 private:
  std::span<const std::uint8_t> bytes_;
  size_t pos_ = 0;
  const char* message_;
};

// Smallest encodings: id + type + empty string ("\0" with length 1) ...
constexpr size_t kMinQueryBytes = 8 + 1 + 5;
constexpr size_t kMinCommandBytes = 8 + 1 + 8 + 5 + 2;
constexpr size_t kMinReplyBytes = 8 + 1 + 5 + 8 + 8 + 4;

void WalkPackage(WireWalker& w) {
  w.Skip(8, "fingerprint");
  w.Skip(2 + 8 + 8 + 8 + 1 + 1 + 4, "header");
  const std::int64_t nq = w.ReadCount(4, "num_queries", kMinQueryBytes);
  for (std::int64_t i = 0; i < nq; ++i) {
    w.Skip(8 + 1, "query");
    w.SkipString("query.target");
  }
  const std::int64_t nc = w.ReadCount(4, "num_commands", kMinCommandBytes);
  for (std::int64_t i = 0; i < nc; ++i) {
    w.Skip(8 + 1 + 8, "command");
    w.SkipString("command.target");
    const std::int64_t nv = w.ReadCount(2, "command.num_values", 8);
    w.Skip(static_cast<size_t>(nv) * 8, "command.values");
  }
  w.ExpectEnd();
}

void WalkReplyPackage(WireWalker& w) {
  w.Skip(8, "fingerprint");
  w.Skip(2 + 8 + 8 + 8 + 8, "header");
  const std::int64_t nr = w.ReadCount(4, "num_replies", kMinReplyBytes);
  for (std::int64_t i = 0; i < nr; ++i) {
    w.Skip(8 + 1, "reply");
    w.SkipString("reply.message");
    w.Skip(8 + 8, "reply times");
    const std::int64_t nv = w.ReadCount(4, "reply.num_values", 8);
    w.Skip(static_cast<size_t>(nv) * 8, "reply.values");
  }
  w.ExpectEnd();
}

template <typename Msg>
Msg DecodeChecked(std::span<const std::uint8_t> bytes, const char* name, void (*walk)(WireWalker&)) {
  if (bytes.size() > static_cast<size_t>(INT32_MAX)) throw ProtocolError(std::string(name) + ": message too large");
  WireWalker walker(bytes, name);
  // The fingerprint first: a message of another type gives a clear error.
  if (bytes.size() < 8) walker.Fail("shorter than LCM's 8-byte fingerprint");
  std::int64_t fingerprint = 0;
  for (int i = 0; i < 8; ++i) fingerprint = (fingerprint << 8) | bytes[static_cast<size_t>(i)];
  if (fingerprint != Msg::getHash()) walker.Fail("fingerprint does not match (another message type?)");
  walk(walker);
  Msg msg;
  if (msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())) != static_cast<int>(bytes.size())) {
    walker.Fail("LCM decode failed");
  }
  return msg;
}

}  // namespace

robotalk_msgs::command_t ToWire(const Command& c) {
  robotalk_msgs::command_t w{};
  w.id = c.id;
  w.type = static_cast<std::int8_t>(c.type);
  w.start_time_us = c.start_time ? ToWireMicros(*c.start_time) : 0;
  w.target = c.target;
  w.num_values = static_cast<std::int16_t>(c.values.size());
  w.values = c.values;
  return w;
}

robotalk_msgs::query_t ToWire(const Query& q) {
  robotalk_msgs::query_t w{};
  w.id = q.id;
  w.type = static_cast<std::int8_t>(q.type);
  w.target = q.target;
  return w;
}

robotalk_msgs::reply_t ToWire(const Reply& r) {
  robotalk_msgs::reply_t w{};
  w.id = r.id;
  w.signal = static_cast<std::int8_t>(r.signal);
  w.message = r.message;
  w.exec_time_us = ToWireMicros(r.exec_time);
  w.lateness_us = ToWireMicros(r.lateness);
  w.num_values = static_cast<std::int32_t>(r.values.size());
  w.values = r.values;
  return w;
}

Command FromWire(const robotalk_msgs::command_t& w) {
  if (w.type < 1 || w.type > static_cast<std::int8_t>(CommandType::kPanicReset)) {
    throw ProtocolError("command " + std::to_string(w.id) + ": unknown command type " + std::to_string(w.type));
  }
  if (w.start_time_us < 0) {
    throw ProtocolError("command " + std::to_string(w.id) + ": negative start time " + std::to_string(w.start_time_us) + " us");
  }
  Command c;
  c.id = w.id;
  c.type = static_cast<CommandType>(w.type);
  if (w.start_time_us != 0) c.start_time = FromWireMicros(w.start_time_us);
  c.target = w.target;
  c.values = w.values;
  return c;
}

Query FromWire(const robotalk_msgs::query_t& w) {
  if (w.type < 1 || w.type > static_cast<std::int8_t>(QueryType::kClock)) {
    throw ProtocolError("query " + std::to_string(w.id) + ": unknown query type " + std::to_string(w.type));
  }
  return Query{w.id, static_cast<QueryType>(w.type), w.target};
}

Reply FromWire(const robotalk_msgs::reply_t& w) {
  auto signal = SignalFromWire(w.signal);
  if (!signal) throw ProtocolError("reply " + std::to_string(w.id) + ": unknown signal " + std::to_string(w.signal));
  Reply r;
  r.id = w.id;
  r.signal = *signal;
  r.message = w.message;
  r.exec_time = FromWireMicros(w.exec_time_us);
  r.lateness = std::chrono::microseconds(w.lateness_us);
  r.values = w.values;
  return r;
}

robotalk_msgs::package_t DecodePackage(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::package_t>(bytes, "package_t", &WalkPackage);
}

robotalk_msgs::reply_package_t DecodeReplyPackage(std::span<const std::uint8_t> bytes) {
  return DecodeChecked<robotalk_msgs::reply_package_t>(bytes, "reply_package_t", &WalkReplyPackage);
}

std::string CheckPackageHeader(const robotalk_msgs::package_t& p) {
  const auto& h = p.header;
  if (h.protocol_version != kProtocolVersion) {
    return "package: protocol version " + std::to_string(h.protocol_version) + " is not supported (server speaks " +
           std::to_string(kProtocolVersion) + ")";
  }
  if (h.client_id == 0) return "package: client id 0 is reserved";
  if (h.sequence <= 0) return "package: sequence " + std::to_string(h.sequence) + " is not positive";
  if (p.num_queries > 0 && p.num_commands > 0) {
    return "package: mixes " + std::to_string(p.num_queries) + " queries and " + std::to_string(p.num_commands) +
           " commands; a package carries one or the other";
  }
  const bool panic_only = h.panic && p.num_queries == 0 && p.num_commands == 0;
  if (h.payload_type == robotalk_msgs::package_header_t::PAYLOAD_QUERIES) {
    if (p.num_commands > 0) return "package: payload type QUERIES but it carries commands";
    if (h.payload_size != p.num_queries) {
      return "package: header payload size " + std::to_string(h.payload_size) + " but " + std::to_string(p.num_queries) + " queries";
    }
  } else if (h.payload_type == robotalk_msgs::package_header_t::PAYLOAD_COMMANDS) {
    if (p.num_queries > 0) return "package: payload type COMMANDS but it carries queries";
    if (h.payload_size != p.num_commands) {
      return "package: header payload size " + std::to_string(h.payload_size) + " but " + std::to_string(p.num_commands) + " commands";
    }
  } else if (!panic_only) {
    return "package: unknown payload type " + std::to_string(h.payload_type);
  }
  return "";
}

}  // namespace robotalk
