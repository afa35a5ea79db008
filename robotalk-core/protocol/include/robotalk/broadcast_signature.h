// Signatures of what a keyed server multicasts to every reader: ANNOUNCE,
// CONFIG and STATE (docs/security.md, "Which server?"). A MAC cannot do
// that job (every reader would hold the key, so every reader could forge);
// the server's Ed25519 identity key signs, and a reader verifies with the
// server key it trusts (pinned, or given with --server-key).
//
// Wire form: a keyed server appends a 120-byte suffix to the LCM encoding.
//
//   message || "rtsig-v1" (8) || server key (32) || instance nonce (16) || signature (64)
//   signature = Ed25519(server identity key,
//                       "robotalk-broadcast-v1" || channel || 0x00 || every byte before the signature)
//
// The channel is signed so that a robot's STATE cannot be replayed as
// another's; the instance nonce (the one the hello answer signs) ties a
// sample to the server instance the client has a session with, so samples
// recorded from an earlier instance are refused. LCM's generated decoders
// (C, C++, Java, Lua) read the message and ignore what follows it: readers
// that do not verify (open-mode clients, lcm-spy, lcm-logger) are unchanged,
// and open mode sends no suffix at all.
//
// Thread safety: the functions may be called from any thread; a
// BroadcastSigner is immutable after construction.
#pragma once

#include "robotalk/keys.h"
#include "robotalk/session_auth.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace robotalk {

inline constexpr std::string_view kSignatureMagic = "rtsig-v1";
inline constexpr std::size_t kSignatureSuffixBytes = 8 + 32 + 16 + 64;

/// `bytes` without its signature suffix (all of them when there is none).
/// Verifies nothing: for readers that only look (tools, open-mode clients).
std::span<const std::uint8_t> WithoutSignature(std::span<const std::uint8_t> bytes);

/// Who signed a broadcast, as its suffix says (not verified by itself).
struct SignedBy {
  PublicKey server_key;
  Nonce instance_nonce{};
};

/// The suffix's key and instance, or nullopt when `bytes` carry none.
std::optional<SignedBy> SignatureSuffix(std::span<const std::uint8_t> bytes);

/// A keyed server's signer: its identity (copied) and this instance's nonce.
class BroadcastSigner {
 public:
  BroadcastSigner(const KeyPair& identity, const Nonce& instance_nonce);
  /// Appends the signature suffix of `bytes` published on `channel`.
  void Sign(std::string_view channel, std::vector<std::uint8_t>& bytes) const;
  const PublicKey& public_key() const { return identity_.public_key; }

 private:
  KeyPair identity_;
  Nonce instance_nonce_;
};

enum class BroadcastVerdict {
  kAuthentic,      ///< signed by the trusted key, for this channel (and instance)
  kUnsigned,       ///< no suffix: an open-mode server, or a forger who did not try
  kOtherKey,       ///< signed (or claiming to be) by another key
  kOtherInstance,  ///< the trusted key, another server instance: a recording of an earlier run
  kForged,         ///< the signature does not verify
};
const char* ToString(BroadcastVerdict verdict);

/// Checks a received broadcast against the key a client trusts and, when
/// `instance` is not null, the instance it has a session with. The cheap
/// comparisons come first; the Ed25519 verification (about 60 µs) last.
BroadcastVerdict VerifyBroadcast(std::string_view channel, std::span<const std::uint8_t> bytes,
                                 const PublicKey& trusted, const Nonce* instance);

/// Verifies a broadcast under the key its own suffix names (an ANNOUNCE read
/// by someone with no trust yet: "this key signed it", to compare with a
/// pin). nullopt when unsigned or forged.
std::optional<SignedBy> VerifySelfSigned(std::string_view channel, std::span<const std::uint8_t> bytes);

}  // namespace robotalk
