// A bounds-checked reader of LCM's big-endian encoding, used to walk a
// received message before LCM's generated decoder touches it: that decoder
// sizes arrays from their count fields before checking the bytes are there,
// so a hostile count would allocate gigabytes (and a string length of 0
// throws std::length_error, through LCM's C callback if it runs there).
// Every failure throws ProtocolError naming the function, the element, the
// field and the offset. DecodeChecked (below) is the codecs' one way from
// received bytes to a wire struct.
#pragma once

#include "robotalk/error.h"

#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <utility>

namespace robotalk {

/// Bytes of an LCM string besides its characters: int32 length + NUL.
inline constexpr std::int64_t kLcmStringOverhead = 4 + 1;

class WireScanner {
 public:
  WireScanner(const char* function, std::span<const std::uint8_t> bytes)
      : function_(function), bytes_(bytes) {}

  std::size_t pos() const { return pos_; }
  std::size_t left() const { return bytes_.size() - pos_; }
  /// The element being scanned, for messages ("links[3]").
  void SetContext(std::string context) { context_ = std::move(context); }

  void Skip(std::int64_t n, const char* field) {
    Need(n, field);
    pos_ += static_cast<std::size_t>(n);
  }
  std::int64_t Int64(const char* field) { return static_cast<std::int64_t>(Unsigned(8, field)); }
  std::int32_t Int32(const char* field) { return static_cast<std::int32_t>(Unsigned(4, field)); }
  std::int16_t Int16(const char* field) { return static_cast<std::int16_t>(Unsigned(2, field)); }
  std::int8_t Int8(const char* field) { return static_cast<std::int8_t>(Unsigned(1, field)); }

  /// An LCM string: length in [1, bytes left], NUL-terminated, no NUL inside.
  void String(const char* field) {
    const std::size_t at = pos_;
    const std::int32_t len = Int32(field);
    if (len < 1 || static_cast<std::size_t>(len) > left()) {
      Fail(field, "string length " + std::to_string(len) + " at byte " + std::to_string(at) +
                      " is outside [1, " + std::to_string(left()) + "] (the bytes left)");
    }
    const auto* begin = bytes_.data() + pos_;
    if (begin[len - 1] != 0)
      Fail(field, "string at byte " + std::to_string(at) + " lacks its terminating NUL");
    if (std::memchr(begin, 0, static_cast<std::size_t>(len - 1)) != nullptr) {
      Fail(field, "string at byte " + std::to_string(at) + " contains a NUL byte");
    }
    pos_ += static_cast<std::size_t>(len);
  }

  /// An int32 array count: non-negative, and its elements (each at least
  /// `min_element` bytes) must fit in what is left.
  std::int32_t Count(const char* field, std::int64_t min_element) {
    const std::size_t at = pos_;
    return CheckCount(field, at, Int32(field), min_element);
  }
  /// The same for an int16 count.
  std::int32_t Count16(const char* field, std::int64_t min_element) {
    const std::size_t at = pos_;
    return CheckCount(field, at, Int16(field), min_element);
  }

  /// Fails unless every byte was read.
  void ExpectEnd() const {
    if (left() != 0) Fail("end", std::to_string(left()) + " bytes left over after the message");
  }

  [[noreturn]] void Fail(const char* field, const std::string& what) const {
    throw ProtocolError(std::string(function_) + ": " + (context_.empty() ? std::string() : context_ + ".") +
                        field + ": " + what);
  }

 private:
  std::uint64_t Unsigned(int n, const char* field) {
    Need(n, field);
    std::uint64_t v = 0;
    for (int i = 0; i < n; ++i) v = (v << 8) | bytes_[pos_++];
    return v;
  }
  std::int32_t CheckCount(const char* field, std::size_t at, std::int32_t n, std::int64_t min_element) const {
    if (n < 0 || static_cast<std::int64_t>(n) * min_element > static_cast<std::int64_t>(left())) {
      Fail(field, std::to_string(n) + " at byte " + std::to_string(at) +
                      " is negative or cannot fit in the " + std::to_string(left()) +
                      " bytes left (each element takes at least " + std::to_string(min_element) + ")");
    }
    return n;
  }
  void Need(std::int64_t n, const char* field) const {
    if (n > static_cast<std::int64_t>(left())) {
      Fail(field, "truncated: needs " + std::to_string(n) + " bytes at byte " + std::to_string(pos_) + ", " +
                      std::to_string(left()) + " left of " + std::to_string(bytes_.size()));
    }
  }

  const char* function_;
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
  std::string context_;
};

/// Received bytes as `Msg` (an lcm-gen type): at most `max_bytes`; the
/// fingerprint first (another type gives a clear error); then `scan_body`
/// walks the rest with the scanner (every count and string checked against
/// the bytes left) before LCM's decoder allocates anything; every byte must
/// belong to the message. Throws ProtocolError naming `function` and the field.
template <typename Msg, typename ScanBody>
Msg DecodeChecked(std::span<const std::uint8_t> bytes, const char* function, std::size_t max_bytes,
                  ScanBody&& scan_body) {
  if (bytes.size() > max_bytes) {
    throw ProtocolError(std::string(function) + ": " + std::to_string(bytes.size()) + " bytes; at most " +
                        std::to_string(max_bytes));
  }
  WireScanner scan(function, bytes);
  if (scan.Int64("fingerprint") != Msg::getHash())
    scan.Fail("fingerprint", "does not match (another message type?)");
  std::forward<ScanBody>(scan_body)(scan);
  scan.ExpectEnd();
  Msg msg{};
  if (msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())) != static_cast<int>(bytes.size())) {
    scan.Fail("message", "LCM decode failed");
  }
  return msg;
}

/// The largest message LCM can decode (its sizes are int).
inline constexpr std::size_t kMaxLcmMessageBytes = 0x7fffffff;
/// The bound of the small fixed-layout messages (hello, answer, announce).
inline constexpr std::size_t kMaxSmallMessageBytes = 64 * 1024;

}  // namespace robotalk
