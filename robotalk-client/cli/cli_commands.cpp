#include "cli_commands.h"

#include "cli_support.h"
#include "describe_format.h"
#include "interrupt.h"
#include "robotalk/channels.h"
#include "robotalk/known_servers.h"
#include "robotalk/log_writer.h"
#include "robotalk/routed_lcm_transport.h"
#include "robotalk/sequence_file.h"
#include "sequence_runner.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>

namespace robotalk::cli {

// Pulls `--name VALUE` out of args; returns whether it was there.
bool TakeOption(std::vector<std::string>& args, const std::string& name, std::string* value) {
  auto it = std::find(args.begin(), args.end(), name);
  if (it == args.end()) return false;
  if (value) {
    if (it + 1 == args.end()) throw UsageError(name + " needs a value");
    *value = *(it + 1);
    args.erase(it, it + 2);
  } else {
    args.erase(it);
  }
  return true;
}

void RejectOptions(const std::vector<std::string>& args) {
  for (const auto& a : args) {
    if (a.size() > 1 && a[0] == '-' && !(a[1] >= '0' && a[1] <= '9') && a[1] != '.')
      throw UsageError("unknown option '" + a + "'");
  }
}

int ExitStatus(const Reply& r) { return Succeeded(r.signal) ? 0 : 1; }

void PrintReply(const Reply& r, std::ostream& out) {
  // The message is the server's text (in open mode anyone's who forges a
  // reply): quoted, on one line, no control character reaching the terminal.
  std::string quoted = "\"";
  for (char c : r.message) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c;
  }
  quoted = EscapeControls(quoted);
  quoted += '"';
  out << r.id << ' ' << ToString(r.signal) << ' ' << quoted;
  for (double v : r.values) {
    char buf[32];
    std::snprintf(buf, sizeof buf, " %.6g", v);
    out << buf;
  }
  out << '\n';
}

namespace {
// A keyed server's key as `robots` shows it: its fingerprint and what the
// pin file says of it (a signature proves only that its signer holds that key).
std::string KeyColumn(const GlobalOptions& g, const AnnouncedRobot& r) {
  if (r.server_key.empty()) return "- (open mode)";
  const PublicKey key = PublicKey::Parse(r.server_key);
  if (!g.server_key.empty()) {
    return key.Fingerprint() +
           (ReadPublicKeyFile(g.server_key).key == key ? " (--server-key)" : " (NOT --server-key)");
  }
  const std::filesystem::path file =
      g.known_servers.empty() ? DefaultKnownServersFile() : std::filesystem::path(g.known_servers);
  const std::string network = PinNetwork(ResolveLcmUrl(g.url));
  const ServerPin* pin = nullptr;
  std::optional<KnownServers> pins;
  try {
    if (!file.empty()) pins = KnownServers::Read(file);
    if (pins) pin = pins->Find(r.name, network);
  } catch (const KeyError& e) {
    return key.Fingerprint() + " (" + e.what() + ")";
  }
  if (!pin) return key.Fingerprint() + " (not pinned)";
  return key.Fingerprint() +
         (pin->key == key ? " (pinned)" : " (NOT the pinned " + pin->key.Fingerprint() + ")");
}
}  // namespace

int RunRobots(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string listen;
  const bool has_listen = TakeOption(args, "--listen", &listen);
  const bool json = TakeOption(args, "--json", nullptr);
  RejectOptions(args);
  if (!args.empty()) throw UsageError("robots takes no arguments");
  // By default long enough to hear every live server once.
  const double seconds = has_listen ? ParseSeconds(listen, "--listen") : ToSeconds(kAnnounceHeardWithin);
  std::size_t unlisted = 0;
  const auto robots = ListRobots(MakeOptions(g), FromSeconds(seconds), &unlisted);
  if (unlisted > 0)
    std::cerr << "robotalk: listing the first " << kMaxListedRobots << " robots heard; " << unlisted
              << " announcements named others: more names than a LAN has robots, someone may be flooding "
              << "ROBOTALK/ANNOUNCE\n";
  if (robots.empty())
    std::cerr << "robotalk: no robot announced itself within " << FormatSeconds(seconds) << "\n";
  if (json) {
    std::cout << RobotsJson(robots) << "\n";
    return 0;
  }
  if (robots.empty()) return 0;
  std::printf("%-20s %-10s %5s %-16s %-5s %7s %-16s %s\n", "ROBOT", "DRIVER", "DOFS", "CONFIG_HASH", "PANIC",
              "CLIENTS", "SERVER", "KEY");
  for (const auto& r : robots) {
    std::printf("%-20s %-10s %5d %016llx %-5s %7d %016llx %s\n", r.name.c_str(), r.driver.c_str(),
                r.total_dofs, static_cast<unsigned long long>(r.config_hash), r.panic ? "yes" : "no",
                r.num_clients, static_cast<unsigned long long>(r.server_id), KeyColumn(g, r).c_str());
  }
  return 0;
}

int RunDescribe(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  const bool json = TakeOption(args, "--json", nullptr);
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("usage: robotalk describe ROBOT [--json]");
  const auto client = ConnectClient(g, args[0], ClockUse::kUntimed);
  if (json) {
    PrintModelJson(client->model(), {}, std::cout);
  } else {
    PrintModelTable(client->model(), std::cout);
  }
  ExitAfterOutput(0);
}

int RunQuery(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  const bool json = TakeOption(args, "--json", nullptr);
  RejectOptions(args);
  if (args.size() < 2 || args.size() > 3) {
    throw UsageError("usage: robotalk query ROBOT joint_state|link_poses|frame_poses|base_pose [TARGET]");
  }
  const auto type = ParseQueryType(args[1]);
  if (!type)
    throw UsageError("unknown query '" + args[1] + "' (joint_state, link_poses, frame_poses, base_pose)");
  const auto client = ConnectClient(g, args[0], ClockUse::kUntimed);
  const Reply r = client->Query(*type, args.size() == 3 ? args[2] : "");
  if (json) {
    std::cout << ReplyJson(r) << "\n";
  } else {
    PrintReply(r, std::cout);
  }
  ExitAfterOutput(ExitStatus(r));
}

int RunPanic(const GlobalOptions& g, const std::vector<std::string>& args) {
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("usage: robotalk panic ROBOT");
  const auto client = ConnectClient(g, args[0], ClockUse::kUntimed);
  try {
    client->Panic();
  } catch (const PanicRefusedError& e) {
    std::cerr << "panic REFUSED by " << args[0] << ": " << ErrorText(e.what()) << "\n";
    ExitAfterOutput(1);
  }
  std::cout << "panic taken by " << args[0] << " (the robot is in panic)\n";
  ExitAfterOutput(0);
}

int RunReset(const GlobalOptions& g, const std::vector<std::string>& args) {
  RejectOptions(args);
  if (args.size() != 1) throw UsageError("usage: robotalk reset ROBOT");
  const auto client = ConnectClient(g, args[0], ClockUse::kUntimed);
  const Reply r = client->ResetPanic();
  PrintReply(r, std::cout);
  ExitAfterOutput(ExitStatus(r));
}

namespace {
// Three announce periods without an announcement or a STATE sample mean the
// server is gone.
constexpr Duration kServerSilence = 3 * kAnnouncePeriod;
constexpr Duration kStreamCancelWait = std::chrono::milliseconds(200);
}  // namespace

int RunWatch(const GlobalOptions& g, const std::vector<std::string>& in) {
  std::vector<std::string> args = in;
  std::string period = "0.1", duration, count;
  TakeOption(args, "--period", &period);
  const bool has_duration = TakeOption(args, "--duration", &duration);
  const bool has_count = TakeOption(args, "--count", &count);
  const bool json = TakeOption(args, "--json", nullptr);
  RejectOptions(args);
  if (args.size() != 1)
    throw UsageError("usage: robotalk watch ROBOT [--period S] [--duration S] [--count N] [--json]");
  const double period_s = ParseSeconds(period, "--period");
  const double duration_s = has_duration ? ParseSeconds(duration, "--duration") : kMaxTextSeconds;
  const double max_samples =
      has_count ? ParseNumberIn(count, "--count", {.min = 1, .max = 0x1p53 - 1, .whole = true}) : 1e18;
  if (period_s < 0.001 || duration_s <= 0) {
    throw UsageError("watch: --period must be >= 0.001 s and --duration positive");
  }
  const auto client = ConnectClient(g, args[0]);
  // With the STATE samples: is the server still there? Keyed: only its signed
  // announcements count (as only its signed STATE does), as of their signed
  // server time (a replayed recording is stale).
  AnnounceWatch announces(g.url, client->trusted_server().key,
                          [&client](TimePoint server_time) { return client->ClientTime(server_time); });
  std::cerr << "robotalk: watching ROBOTALK/" << args[0] << "/STATE (asked every " << FormatSeconds(period_s)
            << "; Ctrl-C ends)\n";
  std::mutex mu;
  double samples = 0;                           // GUARDED_BY(mu)
  LinkState shown_link;                         // GUARDED_BY(mu): the link line last printed
  TimePoint link_shown_at{};                    // GUARDED_BY(mu)
  TimePoint last_sample = SteadyClock().Now();  // GUARDED_BY(mu)
  const Duration actual = client->StartStateStream(FromSeconds(period_s), [&](const StateSample& s) {
    std::lock_guard lock(mu);
    last_sample = SteadyClock().Now();
    if (samples >= max_samples) return;
    if (json) {
      std::cout << StateJson(s) << '\n' << std::flush;
    } else {
      char line[160];
      std::snprintf(line, sizeof line, "%" PRId64 " t=%.3f base %.4f %.4f %.4f v=%.3f w=%.3f%s q", s.sample,
                    ToSeconds(s.server_time.time_since_epoch()), s.base.x, s.base.y, s.base.theta, s.base.v,
                    s.base.omega, s.panic ? " PANIC" : "");
      std::cout << line;
      for (double q : s.positions) std::cout << ' ' << q;
      std::cout << '\n' << std::flush;
      // The motion owner's link (issue 23), on stderr so the sample lines stay
      // one per sample: when its client or level changes, and every 5 s while
      // it is not good.
      const LinkState& l = s.link;
      const bool changed = l.client_id != shown_link.client_id || l.level != shown_link.level;
      const bool poor = l.level >= LinkState::Level::kDegraded;
      if (changed || (poor && SteadyClock().Now() - link_shown_at > std::chrono::seconds(5))) {
        std::cerr << "robotalk: link "
                  << (l.client_id == 0 ? std::string("(nobody moves the robot)") : LinkSummary(l)) << '\n';
        shown_link = l;
        link_shown_at = SteadyClock().Now();
      }
    }
    ++samples;
  });
  if (actual != FromSeconds(period_s)) {
    std::cerr << "robotalk: the stream runs every " << FormatDuration(actual)
              << " (another client asked for faster)\n";
  }
  // Ends at --duration, --count or a signal (exit 0), or when the server has
  // gone quiet: no STATE sample and no announcement for kServerSilence (exit 1).
  Interrupter::Defer(true);
  const TimePoint start = SteadyClock().Now();
  const TimePoint end = start + FromSeconds(duration_s);
  bool gone = false;
  while (SteadyClock().Now() < end && !Interrupter::Signal()) {
    TimePoint heard = announces.LastHeard(args[0]).value_or(start);
    {
      std::lock_guard lock(mu);
      if (samples >= max_samples) break;
      heard = std::max(heard, last_sample);
    }
    if (SteadyClock().Now() - heard > kServerSilence) {
      gone = true;
      break;
    }
    Interrupter::WaitFor(std::min<Duration>(std::chrono::milliseconds(20), end - SteadyClock().Now()));
  }
  const auto streaming = [&] {  // samples still arrive (not under `mu` while the cancel waits)
    std::lock_guard lock(mu);
    return SteadyClock().Now() - last_sample < std::max<Duration>(3 * actual, kStreamCancelWait);
  };
  if (gone) {
    std::cerr << "robotalk: " << args[0] << ": no STATE sample and no announcement for "
              << FormatDuration(kServerSilence)
              << ": its server is gone (stopped, crashed or unreachable); watch ends\n";
  } else if (streaming()) {
    // The stream runs: ask the server to end it now (it ends with this
    // client's session anyway), never waiting long for the answer, and not
    // at all when the samples stopped (a server gone: Ctrl-C ends at once).
    try {
      client->SendQuery({.type = QueryType::kStateStreamCancel}).Wait(kStreamCancelWait);
    } catch (const std::exception&) {
    }
  }
  if (const std::uint64_t stale = announces.Stale(); stale > 0) {
    std::cerr << "robotalk: refused " << stale
              << " announcements signed by the server but stale (replayed, delayed or of another clock)\n";
  }
  if (const std::uint64_t refused = client->stats().broadcasts_refused; refused > 0) {
    std::cerr << "robotalk: dropped " << refused
              << " STATE/CONFIG messages not signed by the server's key (forged, replayed, or of another "
                 "server)\n";
  }
  // No teardown: the sample callback must not outlive `mu` and `samples`.
  ExitAfterOutput(gone ? 1 : 0);
}

}  // namespace robotalk::cli
