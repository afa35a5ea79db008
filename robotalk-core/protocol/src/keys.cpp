// Ed25519 identity keys and their files (keys.h). Every primitive is
// libsodium's; this file only formats, parses and guards files.
#include "robotalk/keys.h"

#include "file_trust.h"

#include <fcntl.h>
#include <sodium.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <utility>
#include <vector>

namespace robotalk {
namespace {

constexpr std::string_view kSecretTag = "robotalk-secret-key-v1";
constexpr std::string_view kPublicPrefix = "ed25519:";
// A key file is one short line plus comments; anything larger is not ours.
constexpr off_t kMaxKeyFileBytes = 4096;

std::string Hex(std::span<const std::uint8_t> bytes) {
  std::string out(bytes.size() * 2 + 1, '\0');
  sodium_bin2hex(out.data(), out.size(), bytes.data(), bytes.size());
  out.pop_back();
  return out;
}

// Exactly out.size() bytes of hex, nothing else; false otherwise.
bool FromHex(std::string_view hex, std::span<std::uint8_t> out) {
  if (hex.size() != out.size() * 2) return false;
  std::size_t written = 0;
  const char* end = nullptr;
  if (sodium_hex2bin(out.data(), out.size(), hex.data(), hex.size(), nullptr, &written, &end) != 0) {
    return false;
  }
  return written == out.size() && end == hex.data() + hex.size();
}

std::string ErrnoText() { return std::strerror(errno); }

// Reads a whole small file through an fd we already hold.
std::string ReadFd(int fd, const std::filesystem::path& file) {
  std::string text;
  char buf[1024];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw KeyError("key file " + file.string() + ": cannot read: " + ErrnoText());
    }
    if (n == 0) break;
    text.append(buf, static_cast<std::size_t>(n));
    if (text.size() > static_cast<std::size_t>(kMaxKeyFileBytes)) {
      throw KeyError("key file " + file.string() + ": larger than " + std::to_string(kMaxKeyFileBytes) +
                     " bytes; not a RoboTalk key file");
    }
  }
  return text;
}

// The first line that is neither blank nor a '#' comment, trimmed.
std::string FirstContentLine(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    const auto b = line.find_first_not_of(" \t\r");
    if (b == std::string::npos || line[b] == '#') continue;
    const auto e = line.find_last_not_of(" \t\r");
    return line.substr(b, e - b + 1);
  }
  return {};
}

class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(Fd&& other) noexcept : fd_(other.release()) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

// Creates `file` exclusively with `mode` and writes `text`; removes it again on failure.
void WriteNewFile(const std::filesystem::path& file, const std::string& text, mode_t mode) {
  Fd fd(::open(file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, mode));
  if (fd.get() < 0) {
    throw KeyError("key file " + file.string() + ": cannot create: " + ErrnoText() +
                   (errno == EEXIST ? " (refusing to overwrite an existing key)" : ""));
  }
  // open() applies the umask; set the mode we promise exactly.
  bool ok = ::fchmod(fd.get(), mode) == 0;
  std::size_t done = 0;
  while (ok && done < text.size()) {
    const ssize_t n = ::write(fd.get(), text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  ok = ok && ::fsync(fd.get()) == 0;
  const std::string why = ok ? "" : ErrnoText();
  ok = ::close(fd.release()) == 0 && ok;
  if (!ok) {
    ::unlink(file.c_str());
    throw KeyError("key file " + file.string() + ": cannot write: " + why);
  }
}

}  // namespace

void InitSodium() {
  // sodium_init is itself thread-safe and idempotent (returns 1 when done before).
  if (sodium_init() < 0) throw KeyError("libsodium: sodium_init() failed");
}

std::string PublicKey::ToString() const { return std::string(kPublicPrefix) + Hex(bytes); }

std::string PublicKey::Fingerprint() const {
  std::array<std::uint8_t, crypto_generichash_BYTES> hash{};
  crypto_generichash(hash.data(), hash.size(), bytes.data(), bytes.size(), nullptr, 0);
  const std::string hex = Hex(std::span<const std::uint8_t>(hash.data(), 8));
  return "rt:" + hex.substr(0, 4) + ":" + hex.substr(4, 4) + ":" + hex.substr(8, 4) + ":" + hex.substr(12, 4);
}

PublicKey PublicKey::Parse(std::string_view text) {
  PublicKey key;
  if (!text.starts_with(kPublicPrefix) || !FromHex(text.substr(kPublicPrefix.size()), key.bytes)) {
    const std::string shown(text.substr(0, 80));
    throw KeyError("public key '" + shown + "': expected 'ed25519:' followed by 64 hex digits");
  }
  return key;
}

SecretKey::~SecretKey() { sodium_memzero(bytes_.data(), bytes_.size()); }

SecretKey::SecretKey(SecretKey&& other) noexcept : bytes_(other.bytes_) {
  sodium_memzero(other.bytes_.data(), other.bytes_.size());
}

SecretKey& SecretKey::operator=(SecretKey&& other) noexcept {
  if (this != &other) {
    bytes_ = other.bytes_;
    sodium_memzero(other.bytes_.data(), other.bytes_.size());
  }
  return *this;
}

KeyPair KeyPair::Generate() {
  InitSodium();
  KeyPair pair;
  crypto_sign_keypair(pair.public_key.bytes.data(), pair.secret_key.bytes_.data());
  return pair;
}

KeyPair KeyPair::FromSeed(std::span<const std::uint8_t, SecretKey::kSeedBytes> seed) {
  InitSodium();
  KeyPair pair;
  crypto_sign_seed_keypair(pair.public_key.bytes.data(), pair.secret_key.bytes_.data(), seed.data());
  return pair;
}

std::array<std::uint8_t, 64> Sign(const KeyPair& key, std::span<const std::uint8_t> message) {
  static_assert(crypto_sign_BYTES == 64);
  std::array<std::uint8_t, 64> sig{};
  crypto_sign_detached(sig.data(), nullptr, message.data(), message.size(), key.secret_key.bytes().data());
  return sig;
}

bool VerifySignature(const PublicKey& key, std::span<const std::uint8_t> message,
                     std::span<const std::uint8_t, 64> signature) {
  InitSodium();
  return crypto_sign_verify_detached(signature.data(), message.data(), message.size(), key.bytes.data()) == 0;
}

bool IsValidKeyName(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '.' || c == '@' || c == '-';
    if (!ok) return false;
  }
  return true;
}

void WriteKeyFiles(const std::filesystem::path& secret_file, const KeyPair& key, std::string_view name) {
  const std::filesystem::path public_file = secret_file.string() + ".pub";
  if (!IsValidKeyName(name)) {
    throw KeyError("key name '" + std::string(name.substr(0, 80)) +
                   "': use 1-64 letters, digits, '_', '.', '@' or '-'");
  }
  // Check both first so a refusal writes nothing; O_EXCL below closes the race.
  for (const auto& f : {secret_file, public_file}) {
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::symlink_status(f, ec))) {
      throw KeyError("key file " + f.string() + ": exists; refusing to overwrite a key");
    }
  }
  const std::string secret_text = "# RoboTalk secret key (Ed25519 seed) of '" + std::string(name) +
                                  "'. Keep it private: mode 0600.\n" + std::string(kSecretTag) + " " +
                                  Hex(key.secret_key.seed()) + "\n";
  WriteNewFile(secret_file, secret_text, 0600);
  try {
    WriteNewFile(public_file, key.public_key.ToString() + " " + std::string(name) + "\n", 0644);
  } catch (...) {
    ::unlink(secret_file.c_str());
    throw;
  }
}

namespace {
// Opens a key file after the checks of file_trust.h; throws KeyError naming
// the file and the problem.
Fd OpenKeyFile(const std::filesystem::path& file, TrustedFile kind) {
  const std::string what =
      (kind == TrustedFile::kSecret ? "secret key file " : "public key file ") + file.string();
  struct stat st {};
  std::string problem;
  Fd fd(OpenTrustedFile(file, st, problem));
  if (fd.get() < 0) throw KeyError(what + ": " + problem);
  problem = FileTrustProblem(file, st, kind);
  if (!problem.empty()) throw KeyError(what + ": " + problem);
  return fd;
}
}  // namespace

KeyPair ReadSecretKeyFile(const std::filesystem::path& file) {
  const Fd fd = OpenKeyFile(file, TrustedFile::kSecret);
  std::string text = ReadFd(fd.get(), file);
  const std::string line = FirstContentLine(text);
  sodium_memzero(text.data(), text.size());
  std::array<std::uint8_t, SecretKey::kSeedBytes> seed{};
  const auto space = line.find(' ');
  const bool ok = space != std::string::npos && std::string_view(line).substr(0, space) == kSecretTag &&
                  FromHex(std::string_view(line).substr(space + 1), seed);
  if (!ok) {
    throw KeyError("secret key file " + file.string() + ": expected a line '" + std::string(kSecretTag) +
                   " <64 hex digits>' (written by robotalk-keygen)");
  }
  KeyPair pair = KeyPair::FromSeed(seed);
  sodium_memzero(seed.data(), seed.size());
  return pair;
}

PublicKeyFile ReadPublicKeyFile(const std::filesystem::path& file) {
  const Fd fd = OpenKeyFile(file, TrustedFile::kShared);
  const std::string line = FirstContentLine(ReadFd(fd.get(), file));
  const auto space = line.find(' ');
  try {
    PublicKeyFile out{PublicKey::Parse(std::string_view(line).substr(0, space)), ""};
    if (space != std::string::npos) out.name = line.substr(line.find_first_not_of(" \t", space));
    if (!IsValidKeyName(out.name)) throw KeyError("name '" + out.name + "' is missing or invalid");
    return out;
  } catch (const KeyError& e) {
    throw KeyError("public key file " + file.string() + ": " + e.what());
  }
}

}  // namespace robotalk
