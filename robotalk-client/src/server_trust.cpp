// Trust on first use of a server key (server_trust.h).
#include "server_trust.h"

#include "robotalk/known_servers.h"

namespace robotalk::client {

ServerTrust::ServerTrust(std::optional<PublicKey> explicit_key, std::string explicit_file,
                         std::filesystem::path pin_file)
    : explicit_file_(std::move(explicit_file)), pin_file_(std::move(pin_file)), trusted_(explicit_key) {
  if (trusted_) source_ = TrustedServer::Source::kExplicit;
}

void ServerTrust::Load(const std::string& robot, const std::string& network) {
  robot_ = robot;
  network_ = network;
  if (source_ == TrustedServer::Source::kExplicit) return;
  if (pin_file_.empty()) {
    throw KeyError("keyed mode: no known-servers file to pin robot '" + robot +
                   "''s server key in (neither ROBOTALK_KNOWN_SERVERS nor HOME is set): set one, "
                   "or give the server's public key (--server-key FILE.pub)");
  }
  const KnownServers pins = KnownServers::Read(pin_file_);
  if (const ServerPin* pin = pins.Find(robot, network)) {
    trusted_ = pin->key;
    source_ = TrustedServer::Source::kPinned;
    pin_line_ = pin->line;
  }
}

std::string ServerTrust::Check(const PublicKey& offered) const {
  if (!trusted_ || offered == *trusted_) return "";
  const std::string where = "robot '" + robot_ + "' on " + network_;
  switch (source_) {
    case TrustedServer::Source::kExplicit:
      return where + ": the server answered with key " + offered.Fingerprint() + ", not the key of " +
             explicit_file_ + " (" + trusted_->Fingerprint() + ") given with --server-key; refused";
    case TrustedServer::Source::kPinned: {
      const std::string line = pin_file_.string() + ":" + std::to_string(pin_line_);
      return "WARNING: " + where + ": the server's key has CHANGED.\n  pinned (" + line +
             "): " + trusted_->Fingerprint() + "\n  this server's key: " + offered.Fingerprint() +
             "\n  Another process may be impersonating the server, or the server was given a new key. "
             "If you know that it was, delete line " +
             std::to_string(pin_line_) + " of " + pin_file_.string() +
             " (the next connection pins the new key), or give the server's key with --server-key FILE.pub. "
             "Refused.";
    }
    case TrustedServer::Source::kPinnedNow:
    case TrustedServer::Source::kNone:
      break;
  }
  return where + ": this client trusts server key " + trusted_->Fingerprint() +
         " (its first session), and a server answered with " + offered.Fingerprint() + "; refused";
}

void ServerTrust::WritePin(const PublicKey& key) const {
  KnownServers::Append(pin_file_, {robot_, network_, key});
}

void ServerTrust::Trust(const PublicKey& key) {
  if (trusted_) return;
  trusted_ = key;
  source_ = TrustedServer::Source::kPinnedNow;
}

TrustedServer ServerTrust::Describe() const {
  TrustedServer out;
  out.source = source_;
  if (trusted_) {
    out.key = trusted_->ToString();
    out.fingerprint = trusted_->Fingerprint();
  }
  if (source_ == TrustedServer::Source::kExplicit) {
    out.file = explicit_file_;
  } else if (source_ != TrustedServer::Source::kNone) {
    out.file = pin_file_.string();
  }
  return out;
}

}  // namespace robotalk::client
