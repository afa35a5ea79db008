// The robot descriptions a client keeps, by configuration hash. Bounded
// (issue 19: 20,000 forged CONFIG messages grew a client from 7 to 100 MB,
// one decoded description per hash, kept forever):
//   - kept: the descriptions somebody asked for by hash (Connect,
//     ReloadModel, a re-sync after a server restart). Never dropped, so a
//     RobotModel reference the client handed out stays valid; their number
//     grows only with the client's own CONFIG queries.
//   - unasked: received before (or without) anybody asking; only the last
//     kUnasked are kept (a CONFIG message may arrive before the reply that
//     names its hash).
// In keyed mode only descriptions whose server signature verified get here.
//
// Thread safety: none; RobotClient::Impl uses it under its mutex.
#pragma once

#include "robotalk/robot_model.h"

#include <cstdint>
#include <deque>
#include <memory>
#include <unordered_map>
#include <unordered_set>

namespace robotalk::client {

class ConfigStore {
 public:
  static constexpr std::size_t kUnasked = 4;
  using Model = std::shared_ptr<const RobotModel>;

  /// True when `hash` is held (kept or unasked): no need to decode it again.
  bool Has(std::uint64_t hash) const;
  /// Files a received description of `bytes` encoded bytes: kept when
  /// wanted, else among the unasked (the oldest unasked one is dropped).
  void Add(std::uint64_t hash, Model model, std::size_t bytes);
  /// Asks for `hash`: returns it (now kept) if held; otherwise remembers that
  /// it is wanted, so that Add keeps it when it arrives, and returns nullptr.
  Model Want(std::uint64_t hash);

  std::size_t size() const { return kept_.size() + unasked_.size(); }
  std::size_t bytes() const { return bytes_; }

 private:
  struct Entry {
    Model model;
    std::size_t bytes = 0;
  };
  std::unordered_map<std::uint64_t, Entry> kept_;
  std::deque<std::pair<std::uint64_t, Entry>> unasked_;
  std::unordered_set<std::uint64_t> wanted_;  // asked for, not received yet
  std::size_t bytes_ = 0;
};

}  // namespace robotalk::client
