// McapWriter: a minimal writer of MCAP files (https://mcap.dev/spec, major
// version 0), enough for `robotalk-logplay export --mcap` (docs/interop.md).
// Debian packages no MCAP library for C++, so this is our own, written from
// the specification.
//
// What it writes:
//   Magic, Header (profile "", library "robotalk-logplay"),
//   the data section: Chunks (uncompressed) holding the Schema, Channel and
//   Message records, each chunk followed by one Message Index per channel in
//   it; then Data End;
//   the summary section: every Schema, every Channel, one Statistics, one
//   Chunk Index per chunk (grouped by opcode, as the spec requires), then
//   Summary Offset records for each group; Footer; Magic.
// The indexes are there because Foxglove reads an MCAP file through them:
// an unindexed file opens with "This file is unindexed. Unindexed files may
// have degraded performance", and chunks without message indexes are refused
// ("Chunks without message indexes are not currently supported";
// foxglove/ws-protocol#592). CRC fields are written as 0 ("not computed"),
// which the spec allows everywhere.
//
// Messages must come in log-time order for the indexes to be tight (they are
// still valid otherwise: each chunk's start and end times are its min / max).
//
// Thread safety: none. Errors: throws robotalk::Error naming the file when it
// cannot be written, and for a schema / channel id overflow (65535 ids).
#pragma once

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk::logplay {

class McapWriter {
 public:
  /// Opens `path` for writing and writes the magic and header. A chunk is
  /// closed when its records reach `chunk_bytes`.
  explicit McapWriter(const std::string& path, std::size_t chunk_bytes = 1 << 20);
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Returns the id of a schema (1, 2, ...; the same id for the same name, encoding and data).
  std::uint16_t AddSchema(const std::string& name, const std::string& encoding, const std::string& data);
  /// Returns the id of a channel (the same for the same topic).
  std::uint16_t AddChannel(std::uint16_t schema_id, const std::string& topic,
                           const std::string& message_encoding);
  /// One message; times in ns (log_time: when recorded; publish_time: when sent).
  void Write(std::uint16_t channel_id, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             std::string_view data);
  /// Writes the last chunk, the summary and the footer, and closes the file.
  /// Called by the destructor if not before (errors are then swallowed).
  void Close();

  std::uint64_t messages() const { return message_count_; }
  std::uint64_t bytes_written() const { return offset_; }

 private:
  struct Schema {
    std::uint16_t id;
    std::string name, encoding, data;
  };
  struct Channel {
    std::uint16_t id, schema_id;
    std::string topic, encoding;
  };
  struct ChunkIndex {
    std::uint64_t start_ns, end_ns, offset, length, index_length, size;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
  };

  void FlushChunk();
  void Emit(const std::string& bytes);

  std::string path_;
  std::ofstream out_;
  std::size_t chunk_bytes_;
  std::uint64_t offset_ = 0;
  bool closed_ = false;
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<bool> schema_written_, channel_written_;  // into a chunk, before their first message
  // The open chunk: its records, per channel (log time, offset in the records), its time span.
  std::string chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  bool chunk_has_messages_ = false;
  std::vector<ChunkIndex> chunks_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::uint64_t message_count_ = 0, start_ns_ = 0, end_ns_ = 0;
  std::vector<std::uint32_t> sequence_;  // per channel
};

}  // namespace robotalk::logplay
