// The access-list parser (access_list.h). Strict on purpose: a typo in a
// security file must be an error naming the line, never a silent default.
#include "robotalk/access_list.h"

#include "file_trust.h"
#include "robotalk/channels.h"

#include "robotalk/request.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <tuple>

namespace robotalk {
namespace {

// A list of a few thousand clients is a few hundred KB; cap it well above.
constexpr std::size_t kMaxFileBytes = std::size_t{4} * 1024 * 1024;

std::vector<std::string_view> Fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t b = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > b) out.push_back(line.substr(b, i - b));
  }
  return out;
}

class LineParser {
 public:
  LineParser(std::string_view source, int line)
      : where_(std::string(source) + ":" + std::to_string(line) + ": ") {}

  [[noreturn]] void Fail(const std::string& what) const { throw AccessListError(where_ + what); }

  Rights ParseRights(std::string_view robot, std::string_view list) const {
    Rights r;
    if (list.empty()) Fail("robot '" + std::string(robot) + "': no rights after '='; use e.g. query or none");
    std::size_t b = 0;
    while (b <= list.size()) {
      const std::size_t e = std::min(list.find(',', b), list.size());
      const std::string_view word = list.substr(b, e - b);
      if (word == "command") {
        r.command = true;
      } else if (word == "query") {
        r.query = true;
      } else if (word == "panic") {
        r.panic = true;
      } else if (word == "all") {
        r = Rights::All();
      } else if (word == "none") {
        // explicit nothing: useful to exclude one robot from a '*' entry
      } else {
        Fail("robot '" + std::string(robot) + "': unknown right '" + std::string(word) +
             "' (known: command, query, panic, all, none)");
      }
      b = e + 1;
    }
    return r;
  }

  AccessEntry Parse(const std::vector<std::string_view>& f) const {
    if (f.size() < 3) {
      Fail("expected '<public key> <name> <robot>=<rights> ...', got " + std::to_string(f.size()) +
           " field(s)");
    }
    AccessEntry entry;
    try {
      entry.key = PublicKey::Parse(f[0]);
    } catch (const KeyError& e) {
      Fail(e.what());
    }
    if (!IsValidKeyName(f[1])) {
      Fail("name '" + std::string(f[1].substr(0, 80)) + "': use 1-64 letters, digits, '_', '.', '@' or '-'");
    }
    entry.name = f[1];
    for (std::size_t i = 2; i < f.size(); ++i) {
      const auto eq = f[i].find('=');
      if (eq == std::string_view::npos) {
        Fail("'" + std::string(f[i].substr(0, 80)) + "': expected <robot>=<rights>");
      }
      const std::string_view robot = f[i].substr(0, eq);
      if (robot != "*" && !IsValidRobotName(robot)) {
        Fail("robot '" + std::string(robot.substr(0, 80)) + "': not '*' and " + RobotNameProblem(robot));
      }
      const Rights rights = ParseRights(robot, f[i].substr(eq + 1));
      if (!entry.robots.emplace(std::string(robot), rights).second) {
        Fail("robot '" + std::string(robot) + "' given twice for '" + entry.name + "'");
      }
    }
    return entry;
  }

 private:
  std::string where_;
};

}  // namespace

std::string Rights::ToString() const {
  std::string s;
  for (const auto& [on, word] : {std::pair{command, "command"}, {query, "query"}, {panic, "panic"}}) {
    if (!on) continue;
    if (!s.empty()) s += ",";
    s += word;
  }
  return s.empty() ? "none" : s;
}

AccessList AccessList::Parse(std::string_view text, std::string_view source) {
  AccessList list;
  std::map<std::string, int, std::less<>> names;
  int number = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    ++number;
    const auto fields = Fields(line);
    if (fields.empty() || fields[0].starts_with('#')) continue;
    const LineParser parser(source, number);
    AccessEntry entry = parser.Parse(fields);
    entry.line = number;
    if (const auto it = list.by_key_.find(entry.key); it != list.by_key_.end()) {
      parser.Fail("key " + entry.key.Fingerprint() + " already given on line " +
                  std::to_string(list.entries_[it->second].line) + " (as '" + list.entries_[it->second].name +
                  "')");
    }
    if (const auto it = names.find(entry.name); it != names.end()) {
      parser.Fail("name '" + entry.name + "' already used on line " + std::to_string(it->second));
    }
    names.emplace(entry.name, number);
    list.by_key_.emplace(entry.key, list.entries_.size());
    list.entries_.push_back(std::move(entry));
  }
  return list;
}

AccessList AccessList::ReadFile(const std::filesystem::path& file) {
  struct stat st {};
  std::string text;
  std::string problem;
  const int fd = OpenTrustedFile(file, st, problem);
  if (fd < 0) throw AccessListError("access list " + file.string() + ": " + problem);
  if (problem = FileTrustProblem(file, st, TrustedFile::kShared); !problem.empty()) {
    // owner, mode (who may write it grants themselves rights), directories
  } else if (static_cast<std::size_t>(st.st_size) > kMaxFileBytes) {
    problem = "larger than " + std::to_string(kMaxFileBytes) + " bytes";
  } else {
    text.resize(static_cast<std::size_t>(st.st_size));
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    text.resize(done);
  }
  ::close(fd);
  if (!problem.empty()) throw AccessListError("access list " + file.string() + ": " + problem);
  return Parse(text, file.string());
}

const AccessEntry* AccessList::Find(const PublicKey& key) const {
  const auto it = by_key_.find(key);
  return it == by_key_.end() ? nullptr : &entries_[it->second];
}

Rights AccessList::RightsFor(const PublicKey& key, std::string_view robot) const {
  const AccessEntry* entry = Find(key);
  if (entry == nullptr) return {};
  if (const auto it = entry->robots.find(robot); it != entry->robots.end()) return it->second;
  if (const auto it = entry->robots.find(std::string_view("*")); it != entry->robots.end()) return it->second;
  return {};
}

Rights RequiredRights(const Request& request) {
  Rights need;
  need.panic = request.panic;
  need.command = !request.commands.empty();
  need.query = !request.queries.empty();
  return need;
}

std::string CheckRights(const AccessList& list, const AccessEntry& entry, std::string_view robot,
                        const Request& request) {
  const Rights need = RequiredRights(request);
  const Rights have = list.RightsFor(entry.key, robot);
  std::string missing;
  for (const auto& [needed, held, verb] : {std::tuple{need.command, have.command, "command"},
                                           {need.query, have.query, "query"},
                                           {need.panic, have.panic, "panic"}}) {
    if (!needed || held) continue;
    if (!missing.empty()) missing += ", ";
    missing += verb;
  }
  if (missing.empty()) return {};
  return "client '" + entry.name + "' may not " + missing + " robot '" + std::string(robot) +
         "' (its rights there: " + have.ToString() + ")";
}

}  // namespace robotalk
