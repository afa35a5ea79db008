// robotalk-logplay export (docs/logplay.md): the session as CSV for a
// spreadsheet or a script, and the joint names those columns carry.
//
// Joint names are not in the STATE stream (positions in dof order only): they
// come from the configuration messages on ROBOTALK/<robot>/CONFIG, which a
// server publishes when a client connects (a CONFIG query). LoggedConfigs
// collects them; a robot whose configuration the log lacks keeps q0, q1, ...
// and ExportCsv says so.
//
// Thread safety: none (value types, pure functions apart from the files).
// Errors: ExportCsv throws LogError when it cannot write; an undecodable
// CONFIG message is counted, never thrown.
#pragma once

#include "session_log.h"

#include <cstdint>
#include <iosfwd>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace robotalk::logplay {

/// One dof as a column: its name and unit ("rad", "m", or "" when unknown).
struct DofColumn {
  std::string name;
  std::string unit;
  bool operator==(const DofColumn&) const = default;
};

/// The configurations a log holds, by robot.
class LoggedConfigs {
 public:
  /// One log event; anything but a decodable ROBOTALK/<robot>/CONFIG is ignored.
  void Add(const std::string& channel, std::span<const std::uint8_t> bytes);

  /// The dofs of `robot` for a state of `num_dofs` positions: the newest
  /// logged configuration of that size, or nullptr when the log has none.
  const std::vector<DofColumn>* Find(const std::string& robot, std::size_t num_dofs) const;

  std::uint64_t undecodable() const { return undecodable_; }

 private:
  std::map<std::string, std::vector<std::vector<DofColumn>>> robots_;  // newest last
  std::uint64_t undecodable_ = 0;
};

/// Reads the CONFIG messages of an LCM log (LcmLogReader). Throws LogError
/// when the file cannot be opened.
LoggedConfigs ReadConfigs(const std::string& path);

/// `export`: DIR/commands.csv, DIR/state.csv (one column per dof, named) and
/// DIR/joints.csv (robot, dof index, column, unit, where the name came from);
/// returns the files written. A robot without a logged configuration gets
/// columns q0..qN and one line on `warnings` naming it.
std::vector<std::string> ExportCsv(const SessionLog& log, const LoggedConfigs& configs,
                                   const std::string& dir, std::ostream& warnings);

}  // namespace robotalk::logplay
