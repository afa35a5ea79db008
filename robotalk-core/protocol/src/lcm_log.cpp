// LcmLogReader (lcm_log.h).
#include "robotalk/lcm_log.h"

#include "robotalk/error.h"

#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>

namespace robotalk {
namespace {

constexpr std::uint32_t kSync = 0xEDA1DA01;
constexpr std::size_t kHeader = 4 + 8 + 8 + 4 + 4;

std::uint64_t BigEndian(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = v << 8 | p[i];
  return v;
}

struct Header {
  std::uint32_t sync = 0;
  std::int64_t event_number = 0, timestamp_us = 0;
  std::int32_t channel_length = 0, data_length = 0;
};

Header Parse(const std::uint8_t* h) {
  return Header{static_cast<std::uint32_t>(BigEndian(h, 4)), static_cast<std::int64_t>(BigEndian(h + 4, 8)),
                static_cast<std::int64_t>(BigEndian(h + 12, 8)),
                static_cast<std::int32_t>(static_cast<std::uint32_t>(BigEndian(h + 20, 4))),
                static_cast<std::int32_t>(static_cast<std::uint32_t>(BigEndian(h + 24, 4)))};
}

}  // namespace

LcmLogReader::LcmLogReader(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "rb")) {
  if (!file_) throw Error("cannot open LCM log '" + path + "': " + std::strerror(errno));
}

LcmLogReader::~LcmLogReader() {
  if (file_) std::fclose(file_);
}

std::uint64_t LcmLogReader::FileSize() {
  struct stat st {};
  if (::fstat(::fileno(file_), &st) != 0 || st.st_size < 0) return 0;
  return static_cast<std::uint64_t>(st.st_size);
}

std::size_t LcmLogReader::ReadAt(std::uint64_t at, void* out, std::size_t n) {
  if (::fseeko(file_, static_cast<off_t>(at), SEEK_SET) != 0) return 0;
  return std::fread(out, 1, n, file_);
}

std::string LcmLogReader::Check(std::uint64_t at) {
  std::array<std::uint8_t, kHeader> h{};
  const std::size_t got = ReadAt(at, h.data(), h.size());
  if (got < h.size())
    return "the log ends inside an event header (" + std::to_string(got) + " of " + std::to_string(kHeader) +
           " bytes)";
  const Header e = Parse(h.data());
  if (e.sync != kSync) {
    char text[96];
    std::snprintf(text, sizeof text, "no event starts here (sync word 0x%08X, expected 0x%08X)", e.sync,
                  kSync);
    return text;
  }
  const std::string event = "event " + std::to_string(e.event_number);
  if (e.channel_length < 1 || e.channel_length > kMaxChannelLength)
    return event + ": channel length " + std::to_string(e.channel_length) + " is not 1.." +
           std::to_string(kMaxChannelLength);
  if (e.data_length < 0) return event + ": data length " + std::to_string(e.data_length) + " is negative";
  const std::uint64_t need =
      kHeader + static_cast<std::uint64_t>(e.channel_length) + static_cast<std::uint64_t>(e.data_length);
  const std::uint64_t size = FileSize();
  const std::uint64_t left = size > at ? size - at : 0;
  if (need > left)
    return event + " declares " + std::to_string(e.channel_length) + " channel and " +
           std::to_string(e.data_length) + " data bytes; only " +
           std::to_string(left - std::min(left, kHeader)) + " follow its header in the file";
  return "";
}

std::uint64_t LcmLogReader::NextEventAfter(std::uint64_t from) {
  constexpr std::uint8_t kSyncBytes[] = {0xED, 0xA1, 0xDA, 0x01};
  std::vector<std::uint8_t> chunk(64 * 1024);
  std::uint64_t at = from + 1;
  for (;;) {
    const std::size_t got = ReadAt(at, chunk.data(), chunk.size());
    if (got < sizeof kSyncBytes) return std::max(FileSize(), from + 1);
    auto it = chunk.begin();
    const auto end = chunk.begin() + static_cast<std::ptrdiff_t>(got);
    while ((it = std::search(it, end, std::begin(kSyncBytes), std::end(kSyncBytes))) != end) {
      const std::uint64_t candidate = at + static_cast<std::uint64_t>(it - chunk.begin());
      if (Check(candidate).empty()) return candidate;
      ++it;
    }
    at += got - (sizeof kSyncBytes - 1);  // a sync word across the chunk's end is found next time
  }
}

void LcmLogReader::Damage(std::uint64_t at, const std::string& why, std::uint64_t resumed) {
  if (damaged_++ >= kKeptDamage) return;
  const std::uint64_t size = FileSize();
  std::string text = "byte " + std::to_string(at) + " of '" + path_ + "': " + why;
  if (resumed >= size)
    text += "; the log ends there (" + std::to_string(size - at) + " bytes not read" +
            (why.find("declares") != std::string::npos || why.find("header (") != std::string::npos
                 ? ": cut short, as a recorder stopped while writing leaves it)"
                 : ")");
  else
    text += "; skipped " + std::to_string(resumed - at) + " bytes to the next event, at byte " +
            std::to_string(resumed);
  damage_.push_back(std::move(text));
}

const LcmLogEvent* LcmLogReader::Next() {
  for (;;) {
    const std::uint64_t at = pos_;
    std::array<std::uint8_t, kHeader> h{};
    if (ReadAt(at, h.data(), 1) == 0) return nullptr;  // the end, between events
    const std::string why = Check(at);
    if (!why.empty()) {
      pos_ = NextEventAfter(at);
      Damage(at, why, pos_);
      continue;
    }
    ReadAt(at, h.data(), h.size());
    const Header e = Parse(h.data());
    event_.event_number = e.event_number;
    event_.timestamp_us = e.timestamp_us;
    event_.offset = at;
    event_.channel.resize(static_cast<std::size_t>(e.channel_length));
    event_.data.resize(static_cast<std::size_t>(e.data_length));
    const bool whole =
        ReadAt(at + kHeader, event_.channel.data(), event_.channel.size()) == event_.channel.size() &&
        std::fread(event_.data.data(), 1, event_.data.size(), file_) == event_.data.size();
    if (!whole) {  // the file shrank under us
      pos_ = FileSize();
      Damage(at, "event " + std::to_string(e.event_number) + " could not be read whole", pos_);
      continue;
    }
    pos_ = at + kHeader + event_.channel.size() + event_.data.size();
    return &event_;
  }
}

}  // namespace robotalk
