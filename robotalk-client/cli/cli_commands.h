// The subcommands of the `robotalk` CLI (docs/client.md). Each returns the
// process exit status: 0 when every reply is SUCCESS or MODIFIED, 1 for any
// other signal, a timeout or a client error; usage errors throw UsageError
// (exit 2, handled by main).
#pragma once

#include "robotalk/robot_client.h"

#include <iosfwd>
#include <string>
#include <vector>

namespace robotalk::cli {

struct GlobalOptions {
  std::string url;            ///< --url; "" = LCM default
  double timeout_s = 5.0;     ///< --timeout
  std::string key_file;       ///< --key; "" = $ROBOTALK_KEY or open mode
  std::string server_key;     ///< --server-key: pin the server's public key
  std::string known_servers;  ///< --known-servers: the pin file ("" = the default)
  Duration max_late{0};       ///< --max-late: ClientOptions::max_late (0 = the robot's default)
};

/// Pulls `--name VALUE` (or the flag `--name` when value is null) out of
/// args; returns whether it was there. Throws UsageError when the value is missing.
bool TakeOption(std::vector<std::string>& args, const std::string& name, std::string* value);
/// Throws UsageError "unknown option '--x'" for any option left in args.
void RejectOptions(const std::vector<std::string>& args);
/// 0 for SUCCESS / MODIFIED, 1 otherwise.
int ExitStatus(const Reply& r);

/// `<id> <SIGNAL> "<message>" [values]` on one line.
void PrintReply(const Reply& r, std::ostream& out);

int RunRobots(const GlobalOptions& g, const std::vector<std::string>& args);
int RunDescribe(const GlobalOptions& g, const std::vector<std::string>& args);
int RunQuery(const GlobalOptions& g, const std::vector<std::string>& args);
int RunSend(const GlobalOptions& g, const std::vector<std::string>& args);
int RunPanic(const GlobalOptions& g, const std::vector<std::string>& args);
int RunReset(const GlobalOptions& g, const std::vector<std::string>& args);
int RunWatch(const GlobalOptions& g, const std::vector<std::string>& args);

}  // namespace robotalk::cli
