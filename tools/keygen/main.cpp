// robotalk-keygen: writes a RoboTalk identity key pair (Ed25519) for keyed
// mode: FILE (the secret key, mode 0600) and FILE.pub (the public key and a
// name: one line to paste into the server's --clients list). Never
// overwrites. docs/security.md.
#include "robotalk/keys.h"
#include "robotalk/log_writer.h"  // OpenStandardDescriptors
#include "robotalk/option_reader.h"

#include <filesystem>
#include <iostream>
#include <string>

namespace {

constexpr const char* kUsage =
    "usage: robotalk-keygen --out FILE [--name NAME]\n"
    "       robotalk-keygen --fingerprint FILE.pub\n"
    "\n"
    "Writes a RoboTalk identity key pair (Ed25519, libsodium):\n"
    "  FILE      the secret key, mode 0600; give it to the client (--key FILE)\n"
    "  FILE.pub  'ed25519:<hex> NAME'; add rights and put the line in the\n"
    "            server's --clients file, e.g. '<FILE.pub line> pioneer=command,query,panic'\n"
    "Refuses to overwrite either file.\n"
    "\n"
    "  --out FILE          where to write the pair\n"
    "  --name NAME         the client's name in the access list and the server log\n"
    "                      (1-64 of A-Z a-z 0-9 _ . @ -; default: FILE's base name)\n"
    "  --fingerprint FILE  print the short fingerprint of a key file (.pub or secret)\n"
    "  --help, --version\n";

/// 1: the key could not be made or read; 2: a usage error (as every tool).
int Fail(const std::string& message, int status = 1) {
  std::cerr << "robotalk-keygen: " << message << "\n";
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: a key is never written to descriptor 1 or 2 of ours
  std::string out;
  std::string name;
  std::string fingerprint;
  try {
    robotalk::OptionReader r(argc, argv);
    while (r.Next()) {
      if (r.IsHelp()) {
        std::cout << kUsage;
        return 0;
      } else if (r.IsVersion()) {
        std::cout << "robotalk-keygen " << ROBOTALK_VERSION << "\n";
        return 0;
      } else if (r.Is("--out")) {
        out = r.Value();
      } else if (r.Is("--name")) {
        name = r.Value();
      } else if (r.Is("--fingerprint")) {
        fingerprint = r.Value();
      } else {
        r.Unknown();
      }
    }
  } catch (const robotalk::UsageError& e) {
    return Fail(e.what(), 2);
  }
  try {
    if (!fingerprint.empty()) {
      const std::filesystem::path f(fingerprint);
      const robotalk::PublicKey key = f.extension() == ".pub" ? robotalk::ReadPublicKeyFile(f).key
                                                              : robotalk::ReadSecretKeyFile(f).public_key;
      std::cout << key.Fingerprint() << " " << key.ToString() << "\n";
      return 0;
    }
    if (out.empty()) return Fail("--out FILE is required (see --help)", 2);
    if (name.empty()) name = std::filesystem::path(out).filename().string();
    const robotalk::KeyPair key = robotalk::KeyPair::Generate();
    robotalk::WriteKeyFiles(out, key, name);
    std::cout << "wrote " << out << " (secret, mode 0600) and " << out << ".pub\n"
              << "name        " << name << "\n"
              << "fingerprint " << key.public_key.Fingerprint() << "\n"
              << "public key  " << key.public_key.ToString() << "\n";
    return 0;
  } catch (const robotalk::Error& e) {
    return Fail(e.what());
  }
}
