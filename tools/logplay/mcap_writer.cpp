#include "mcap_writer.h"

#include "robotalk/error.h"

#include <algorithm>

namespace robotalk::logplay {
namespace {

constexpr char kMagic[] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

// Little-endian fields and the spec's length-prefixed types.
void U8(std::string& o, std::uint8_t v) { o.push_back(static_cast<char>(v)); }
void U16(std::string& o, std::uint64_t v) {
  for (int i = 0; i < 2; ++i) o.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void U32(std::string& o, std::uint64_t v) {
  for (int i = 0; i < 4; ++i) o.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void U64(std::string& o, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) o.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}
void Str(std::string& o, std::string_view s) {  // String and uint32-prefixed Bytes
  U32(o, s.size());
  o.append(s);
}

// <opcode><uint64 content length><content>
std::string Record(Op op, const std::string& content) {
  std::string r;
  r.reserve(9 + content.size());
  U8(r, op);
  U64(r, content.size());
  r += content;
  return r;
}

}  // namespace

McapWriter::McapWriter(const std::string& path, std::size_t chunk_bytes)
    : path_(path), out_(path, std::ios::binary | std::ios::trunc), chunk_bytes_(chunk_bytes) {
  if (!out_) throw Error("McapWriter: cannot write '" + path + "'");
  Emit(std::string(kMagic, sizeof kMagic));
  std::string header;
  Str(header, "");  // no well-known profile: JSON messages with JSON Schemas
  Str(header, "robotalk-logplay");
  Emit(Record(kHeader, header));
}

McapWriter::~McapWriter() {
  try {
    Close();
  } catch (const std::exception&) {  // a destructor does not throw; Close() first to see the error
  }
}

void McapWriter::Emit(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) throw Error("McapWriter: cannot write '" + path_ + "' (disk full?)");
  offset_ += bytes.size();
}

std::uint16_t McapWriter::AddSchema(const std::string& name, const std::string& encoding,
                                    const std::string& data) {
  for (const Schema& s : schemas_)
    if (s.name == name && s.encoding == encoding && s.data == data) return s.id;
  if (schemas_.size() >= 0xffff) throw Error("McapWriter: more than 65535 schemas");
  schemas_.push_back({static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data});
  schema_written_.push_back(false);
  return schemas_.back().id;
}

std::uint16_t McapWriter::AddChannel(std::uint16_t schema_id, const std::string& topic,
                                     const std::string& message_encoding) {
  for (const Channel& c : channels_)
    if (c.topic == topic) return c.id;
  if (schema_id == 0 || schema_id > schemas_.size())
    throw Error("McapWriter: channel '" + topic + "': no schema " + std::to_string(schema_id));
  if (channels_.size() >= 0xffff) throw Error("McapWriter: more than 65535 channels");
  channels_.push_back({static_cast<std::uint16_t>(channels_.size() + 1), schema_id, topic, message_encoding});
  channel_written_.push_back(false);
  sequence_.push_back(0);
  return channels_.back().id;
}

namespace {
std::string SchemaContent(std::uint16_t id, const std::string& name, const std::string& encoding,
                          const std::string& data) {
  std::string c;
  U16(c, id);
  Str(c, name);
  Str(c, encoding);
  Str(c, data);
  return c;
}
std::string ChannelContent(std::uint16_t id, std::uint16_t schema_id, const std::string& topic,
                           const std::string& encoding) {
  std::string c;
  U16(c, id);
  U16(c, schema_id);
  Str(c, topic);
  Str(c, encoding);
  U32(c, 0);  // metadata: an empty map
  return c;
}
}  // namespace

void McapWriter::Write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
                       std::string_view data) {
  if (closed_) throw Error("McapWriter: '" + path_ + "' is closed");
  if (channel_id == 0 || channel_id > channels_.size())
    throw Error("McapWriter: no channel " + std::to_string(channel_id));
  const Channel& ch = channels_[channel_id - 1];
  // A chunk must hold (or follow) the Schema and Channel its messages use.
  if (!schema_written_[ch.schema_id - 1]) {
    const Schema& s = schemas_[ch.schema_id - 1];
    chunk_ += Record(kSchema, SchemaContent(s.id, s.name, s.encoding, s.data));
    schema_written_[ch.schema_id - 1] = true;
  }
  if (!channel_written_[channel_id - 1]) {
    chunk_ += Record(kChannel, ChannelContent(ch.id, ch.schema_id, ch.topic, ch.encoding));
    channel_written_[channel_id - 1] = true;
  }
  chunk_index_[channel_id].push_back({log_time_ns, chunk_.size()});
  std::string m;
  m.reserve(22 + data.size());
  U16(m, channel_id);
  U32(m, ++sequence_[channel_id - 1]);
  U64(m, log_time_ns);
  U64(m, publish_time_ns);
  m.append(data);
  chunk_ += Record(kMessage, m);
  if (!chunk_has_messages_) {
    chunk_start_ns_ = chunk_end_ns_ = log_time_ns;
    chunk_has_messages_ = true;
  }
  chunk_start_ns_ = std::min(chunk_start_ns_, log_time_ns);
  chunk_end_ns_ = std::max(chunk_end_ns_, log_time_ns);
  if (message_count_ == 0) start_ns_ = end_ns_ = log_time_ns;
  start_ns_ = std::min(start_ns_, log_time_ns);
  end_ns_ = std::max(end_ns_, log_time_ns);
  ++message_count_;
  ++channel_counts_[channel_id];
  if (chunk_.size() >= chunk_bytes_) FlushChunk();
}

void McapWriter::FlushChunk() {
  if (chunk_.empty()) return;
  ChunkIndex index{};
  index.start_ns = chunk_has_messages_ ? chunk_start_ns_ : 0;
  index.end_ns = chunk_has_messages_ ? chunk_end_ns_ : 0;
  index.offset = offset_;
  index.size = chunk_.size();
  std::string c;
  c.reserve(chunk_.size() + 48);
  U64(c, index.start_ns);
  U64(c, index.end_ns);
  U64(c, chunk_.size());  // uncompressed size
  U32(c, 0);              // uncompressed CRC: not computed
  Str(c, "");             // no compression
  U64(c, chunk_.size());  // records: uint64 length-prefixed bytes
  c += chunk_;
  const std::string chunk = Record(kChunk, c);
  index.length = chunk.size();
  Emit(chunk);
  const std::uint64_t index_start = offset_;
  for (const auto& [channel, entries] : chunk_index_) {  // one Message Index per channel in the chunk
    std::string mi;
    U16(mi, channel);
    U32(mi, entries.size() * 16);
    for (const auto& [time, at] : entries) {
      U64(mi, time);
      U64(mi, at);
    }
    index.index_offsets[channel] = offset_;
    Emit(Record(kMessageIndex, mi));
  }
  index.index_length = offset_ - index_start;
  chunks_.push_back(std::move(index));
  chunk_.clear();
  chunk_index_.clear();
  chunk_has_messages_ = false;
}

void McapWriter::Close() {
  if (closed_) return;
  closed_ = true;
  FlushChunk();
  Emit(Record(kDataEnd, std::string(4, '\0')));  // data section CRC: not computed
  const std::uint64_t summary_start = offset_;
  std::vector<std::tuple<Op, std::uint64_t, std::uint64_t>> groups;  // opcode, start, length
  auto group = [&](Op op, const std::vector<std::string>& contents) {
    if (contents.empty()) return;
    const std::uint64_t start = offset_;
    for (const std::string& c : contents) Emit(Record(op, c));
    groups.emplace_back(op, start, offset_ - start);
  };
  std::vector<std::string> contents;
  for (const Schema& s : schemas_) contents.push_back(SchemaContent(s.id, s.name, s.encoding, s.data));
  group(kSchema, contents);
  contents.clear();
  for (const Channel& ch : channels_)
    contents.push_back(ChannelContent(ch.id, ch.schema_id, ch.topic, ch.encoding));
  group(kChannel, contents);
  std::string stats;
  U64(stats, message_count_);
  U16(stats, schemas_.size());
  U32(stats, channels_.size());
  U32(stats, 0);  // attachments
  U32(stats, 0);  // metadata
  U32(stats, chunks_.size());
  U64(stats, message_count_ ? start_ns_ : 0);
  U64(stats, message_count_ ? end_ns_ : 0);
  U32(stats, channel_counts_.size() * 10);
  for (const auto& [channel, count] : channel_counts_) {
    U16(stats, channel);
    U64(stats, count);
  }
  group(kStatistics, {stats});
  contents.clear();
  for (const ChunkIndex& ci : chunks_) {
    std::string c;
    U64(c, ci.start_ns);
    U64(c, ci.end_ns);
    U64(c, ci.offset);
    U64(c, ci.length);
    U32(c, ci.index_offsets.size() * 10);
    for (const auto& [channel, at] : ci.index_offsets) {
      U16(c, channel);
      U64(c, at);
    }
    U64(c, ci.index_length);
    Str(c, "");       // compression
    U64(c, ci.size);  // compressed size (= uncompressed)
    U64(c, ci.size);
    contents.push_back(std::move(c));
  }
  group(kChunkIndex, contents);
  const std::uint64_t summary_offset_start = offset_;
  for (const auto& [op, start, length] : groups) {
    std::string c;
    U8(c, op);
    U64(c, start);
    U64(c, length);
    Emit(Record(kSummaryOffset, c));
  }
  std::string footer;
  U64(footer, summary_start);
  U64(footer, summary_offset_start);
  U32(footer, 0);  // summary CRC: not computed
  Emit(Record(kFooter, footer));
  Emit(std::string(kMagic, sizeof kMagic));
  out_.close();
  if (!out_) throw Error("McapWriter: cannot close '" + path_ + "'");
}

}  // namespace robotalk::logplay
