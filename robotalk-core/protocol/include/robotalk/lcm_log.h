// LcmLogReader: reads an LCM log file (lcm-logger's format) checking every
// event header against the bytes the file holds before allocating anything.
//
// LCM's own reader (lcm::LogFile, lcm_eventlog_read_next_event) allocates
// what an event header declares before reading it: a header declaring
// 2^31 - 1 data bytes made it fread into a failed allocation (a segfault in
// every reader: robotalk-logplay, Python's robotalk.log_info, LogTransport),
// and a smaller damaged length ended the log there without a word. Here an
// event is read only when its channel and data fit in what is left of the
// file; a damaged stretch (a bad sync word, an impossible length) is skipped
// to the next sync word where an event header checks out, and said in
// damage(); a log that ends inside an event (a recorder stopped mid-write)
// says so too. The file may grow while it is read (a recorder still writing):
// its size is read again before an event is judged too long.
//
// Format (big-endian): sync word 0xEDA1DA01, int64 event number, int64
// timestamp (us), int32 channel length, int32 data length, channel (no NUL),
// data.
//
// Thread safety: none; one reader per thread.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace robotalk {

struct LcmLogEvent {
  std::int64_t event_number = 0;
  std::int64_t timestamp_us = 0;
  std::string channel;
  std::vector<std::uint8_t> data;
  std::uint64_t offset = 0;  ///< its sync word's byte in the file
};

class LcmLogReader {
 public:
  /// LCM's own bound on a logged channel name's length.
  static constexpr std::int32_t kMaxChannelLength = 999;
  /// damage() keeps this many descriptions; damaged_stretches() counts all.
  static constexpr std::size_t kKeptDamage = 20;

  /// Opens `path`; throws robotalk::Error naming it when it cannot be read.
  explicit LcmLogReader(const std::string& path);
  ~LcmLogReader();
  LcmLogReader(const LcmLogReader&) = delete;
  LcmLogReader& operator=(const LcmLogReader&) = delete;

  /// The next intact event (valid until the next call), or nullptr at the
  /// end of the file.
  const LcmLogEvent* Next();

  /// What was wrong, one line per damaged stretch ("byte N: ..."), in file order.
  const std::vector<std::string>& damage() const { return damage_; }
  std::uint64_t damaged_stretches() const { return damaged_; }

 private:
  std::uint64_t FileSize();
  // Reads `n` bytes at `at` into `out`; the count read.
  std::size_t ReadAt(std::uint64_t at, void* out, std::size_t n);
  // The offset of the next sync word after `from` whose header checks out, or the file's size.
  std::uint64_t NextEventAfter(std::uint64_t from);
  // Why the header at `at` cannot start an event that fits in the file ("" when it can).
  std::string Check(std::uint64_t at);
  void Damage(std::uint64_t at, const std::string& why, std::uint64_t resumed);

  std::string path_;
  std::FILE* file_ = nullptr;
  std::uint64_t pos_ = 0;
  LcmLogEvent event_;
  std::vector<std::string> damage_;
  std::uint64_t damaged_ = 0;
};

}  // namespace robotalk
