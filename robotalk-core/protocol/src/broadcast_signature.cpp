// Signed broadcasts (broadcast_signature.h; docs/security.md).
#include "robotalk/broadcast_signature.h"

#include <sodium.h>

#include <algorithm>
#include <cstring>

namespace robotalk {
namespace {

constexpr std::string_view kDomain = "robotalk-broadcast-v1";
constexpr std::size_t kKeyAt = kSignatureMagic.size();  // offsets inside the suffix
constexpr std::size_t kNonceAt = kKeyAt + PublicKey::kBytes;
constexpr std::size_t kSignatureAt = kNonceAt + kNonceBytes;
static_assert(kSignatureAt + 64 == kSignatureSuffixBytes);

bool HasSuffix(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kSignatureSuffixBytes + 8) return false;  // 8: an LCM fingerprint at least
  const std::uint8_t* suffix = bytes.data() + bytes.size() - kSignatureSuffixBytes;
  return std::memcmp(suffix, kSignatureMagic.data(), kSignatureMagic.size()) == 0;
}

// What the signature covers: the domain, the channel, a NUL, then every byte
// before the signature (the message, the magic, the key and the nonce).
std::vector<std::uint8_t> Covered(std::string_view channel, std::span<const std::uint8_t> signed_part) {
  std::vector<std::uint8_t> out(kDomain.size() + channel.size() + 1 + signed_part.size());
  std::uint8_t* p = out.data();
  std::memcpy(p, kDomain.data(), kDomain.size());
  p += kDomain.size();
  if (!channel.empty()) std::memcpy(p, channel.data(), channel.size());
  p += channel.size();
  *p++ = 0;
  if (!signed_part.empty()) std::memcpy(p, signed_part.data(), signed_part.size());
  return out;
}

bool SignatureVerifies(std::string_view channel, std::span<const std::uint8_t> bytes, const PublicKey& key) {
  const std::size_t signature_at = bytes.size() - 64;
  const std::vector<std::uint8_t> covered = Covered(channel, bytes.first(signature_at));
  return VerifySignature(key, covered, std::span<const std::uint8_t, 64>(bytes.data() + signature_at, 64));
}

}  // namespace

std::span<const std::uint8_t> WithoutSignature(std::span<const std::uint8_t> bytes) {
  return HasSuffix(bytes) ? bytes.first(bytes.size() - kSignatureSuffixBytes) : bytes;
}

std::optional<SignedBy> SignatureSuffix(std::span<const std::uint8_t> bytes) {
  if (!HasSuffix(bytes)) return std::nullopt;
  const std::uint8_t* suffix = bytes.data() + bytes.size() - kSignatureSuffixBytes;
  SignedBy by;
  std::copy_n(suffix + kKeyAt, PublicKey::kBytes, by.server_key.bytes.begin());
  std::copy_n(suffix + kNonceAt, kNonceBytes, by.instance_nonce.begin());
  return by;
}

BroadcastSigner::BroadcastSigner(const KeyPair& identity, const Nonce& instance_nonce)
    : identity_(KeyPair::FromSeed(identity.secret_key.seed())), instance_nonce_(instance_nonce) {}

void BroadcastSigner::Sign(std::string_view channel, std::vector<std::uint8_t>& bytes) const {
  const std::size_t at = bytes.size();
  bytes.resize(at + kSignatureSuffixBytes);
  std::uint8_t* suffix = bytes.data() + at;
  std::memcpy(suffix, kSignatureMagic.data(), kSignatureMagic.size());
  std::memcpy(suffix + kKeyAt, identity_.public_key.bytes.data(), PublicKey::kBytes);
  std::memcpy(suffix + kNonceAt, instance_nonce_.data(), kNonceBytes);
  const auto signature = robotalk::Sign(
      identity_, Covered(channel, std::span<const std::uint8_t>(bytes.data(), at + kSignatureAt)));
  std::memcpy(bytes.data() + at + kSignatureAt, signature.data(), signature.size());
}

const char* ToString(BroadcastVerdict verdict) {
  switch (verdict) {
    case BroadcastVerdict::kAuthentic:
      return "authentic";
    case BroadcastVerdict::kUnsigned:
      return "not signed";
    case BroadcastVerdict::kOtherKey:
      return "signed by another key";
    case BroadcastVerdict::kOtherInstance:
      return "from another server instance";
    case BroadcastVerdict::kForged:
      return "forged (the signature does not verify)";
  }
  return "?";
}

BroadcastVerdict VerifyBroadcast(std::string_view channel, std::span<const std::uint8_t> bytes,
                                 const PublicKey& trusted, const Nonce* instance) {
  const std::optional<SignedBy> by = SignatureSuffix(bytes);
  if (!by) return BroadcastVerdict::kUnsigned;
  if (sodium_memcmp(by->server_key.bytes.data(), trusted.bytes.data(), PublicKey::kBytes) != 0) {
    return BroadcastVerdict::kOtherKey;
  }
  if (instance && by->instance_nonce != *instance) return BroadcastVerdict::kOtherInstance;
  if (!SignatureVerifies(channel, bytes, trusted)) return BroadcastVerdict::kForged;
  return BroadcastVerdict::kAuthentic;
}

std::optional<SignedBy> VerifySelfSigned(std::string_view channel, std::span<const std::uint8_t> bytes) {
  std::optional<SignedBy> by = SignatureSuffix(bytes);
  if (!by || !SignatureVerifies(channel, bytes, by->server_key)) return std::nullopt;
  return by;
}

}  // namespace robotalk
