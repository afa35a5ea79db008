// Identity keys of RoboTalk clients and servers (docs/security.md).
//
// An identity is an Ed25519 signing key pair (libsodium crypto_sign). Why
// signatures and not crypto_kx static keys: a client hello signed with the
// identity key can be checked by the server from the public key alone, before
// it stores anything (a forged hello costs one verification, no state); the
// signature is a proof a log line can name; and the same key signs the
// server's answer, so a client can pin its server. Session keys come from a
// fresh X25519 (crypto_kx) exchange per session (session_auth.h), so an
// identity key never takes part in key agreement and a session key is new
// even if a nonce repeats.
//
// Files (one line each, '#' comments allowed before it):
//   secret  FILE      "robotalk-secret-key-v1 <64 hex: the 32-byte Ed25519 seed>"   mode 0600
//   public  FILE.pub  "ed25519:<64 hex: the public key> <name>"                     mode 0644
// The .pub line is also the start of an access-list line (access_list.h).
//
// Thread safety: the free functions may be called from any thread (libsodium
// is initialised once, thread-safely). Values are plain; a SecretKey wipes its
// bytes when destroyed.
#pragma once

#include "robotalk/error.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

namespace robotalk {

/// A key file or printed key is missing, malformed, too open, or would be
/// overwritten; or libsodium could not start. The message names the file.
class KeyError : public Error {
 public:
  using Error::Error;
};

/// Initialises libsodium once per process; later calls return at once.
/// @throw KeyError if sodium_init() fails.
void InitSodium();

/// An Ed25519 public key: who a client or server is.
struct PublicKey {
  static constexpr std::size_t kBytes = 32;
  std::array<std::uint8_t, kBytes> bytes{};

  /// "ed25519:" followed by 64 lowercase hex digits.
  std::string ToString() const;
  /// A short form for logs and humans: "rt:" + the first 8 bytes of the
  /// key's BLAKE2b-256 hash as four groups of 4 hex digits ("rt:1a2b:3c4d:5e6f:7a8b").
  std::string Fingerprint() const;
  /// Parses ToString()'s form. @throw KeyError naming the text.
  static PublicKey Parse(std::string_view text);

  friend bool operator==(const PublicKey&, const PublicKey&) = default;
};

/// An Ed25519 secret key (libsodium's 64-byte form: seed + public key). Move
/// only; its bytes are wiped when it is destroyed or moved from.
class SecretKey {
 public:
  static constexpr std::size_t kBytes = 64;
  static constexpr std::size_t kSeedBytes = 32;

  SecretKey() = default;
  ~SecretKey();
  SecretKey(SecretKey&& other) noexcept;
  SecretKey& operator=(SecretKey&& other) noexcept;
  SecretKey(const SecretKey&) = delete;
  SecretKey& operator=(const SecretKey&) = delete;

  std::span<const std::uint8_t, kBytes> bytes() const { return bytes_; }
  /// The 32-byte seed the whole pair is derived from (what the file holds).
  std::span<const std::uint8_t, kSeedBytes> seed() const {
    return std::span<const std::uint8_t, kSeedBytes>(bytes_.data(), kSeedBytes);
  }

 private:
  friend struct KeyPair;
  std::array<std::uint8_t, kBytes> bytes_{};
};

/// An identity: public and secret key.
struct KeyPair {
  PublicKey public_key;
  SecretKey secret_key;

  /// A fresh random pair (libsodium's CSPRNG).
  static KeyPair Generate();
  /// The pair of a 32-byte seed: deterministic, for tests and for reading files.
  static KeyPair FromSeed(std::span<const std::uint8_t, SecretKey::kSeedBytes> seed);
};

/// Detached Ed25519 signature of `message`.
std::array<std::uint8_t, 64> Sign(const KeyPair& key, std::span<const std::uint8_t> message);
/// True when `signature` is `key`'s signature of `message`.
bool VerifySignature(const PublicKey& key, std::span<const std::uint8_t> message,
                     std::span<const std::uint8_t, 64> signature);

/// Writes `secret_file` (mode 0600) and `secret_file` + ".pub" (mode 0644,
/// carrying `name`). Refuses to overwrite: if either file exists nothing is
/// written. `name`: 1-64 of [A-Za-z0-9_.@-].
/// @throw KeyError naming the file (exists, cannot create, bad name).
void WriteKeyFiles(const std::filesystem::path& secret_file, const KeyPair& key, std::string_view name);

/// Reads a secret key file. Refuses a file that is not a regular file or
/// whose mode lets group or others read or write it ("... mode 0644: the
/// secret key must not be readable by group or others; run chmod 600 FILE").
/// The mode is checked on the opened file (fstat), not on the path.
/// @throw KeyError naming the file and the problem.
KeyPair ReadSecretKeyFile(const std::filesystem::path& file);

/// A public key file: its key and its name.
struct PublicKeyFile {
  PublicKey key;
  std::string name;
};
/// Reads a .pub file. @throw KeyError naming the file.
PublicKeyFile ReadPublicKeyFile(const std::filesystem::path& file);

/// True when `name` is a valid key / client name: 1-64 of [A-Za-z0-9_.@-].
bool IsValidKeyName(std::string_view name);

}  // namespace robotalk
