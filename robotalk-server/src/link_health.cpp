#include "link_health.h"

#include "playback_estimator.h"  // OneWayDelay

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace robotalk {

Duration LinkHealth::SlowTransit() const {
  // The 90th percentile, not the greatest: one package its sender or this
  // server was slow to handle (a loaded machine) must not widen the range
  // past a retransmission's wait.
  std::array<Duration, 64> sorted = transits_;
  const auto end = sorted.begin() + static_cast<std::ptrdiff_t>(transit_count_);
  const auto at = sorted.begin() + static_cast<std::ptrdiff_t>((transit_count_ - 1) * 9 / 10);
  std::nth_element(sorted.begin(), at, end);
  return *at;
}

void LinkHealth::Decide(bool lost) {
  ++f_.expected;
  ++current_.expected;
  if (lost) {
    ++f_.lost;
    ++current_.lost;
  }
}

bool LinkHealth::OnPackage(std::int64_t sequence, bool duplicate, TimePoint sent, TimePoint received,
                           Duration round_trip) {
  Tick(received);
  // The round trip is the client's latest report: that of its highest-numbered
  // package. A copy (a duplicated datagram, a recording replayed: keyed mode
  // answers it from the session table) or a package a later-numbered one
  // overtook carries an older report; taking it let a replay from a bad spell
  // make a good link bad (--link-stop stopped the robot) or hide a bad one.
  if (round_trip > Duration::zero() && !duplicate && (!started_ || sequence > highest_))
    f_.round_trip = round_trip;
  if (duplicate) {
    ++f_.duplicates;
    return false;
  }
  ++f_.packages;
  // The transit on the client's clock: only its differences mean anything.
  // Unknown for a send time no clock has (OneWayDelay: within 2^61 ns, so
  // two transits always subtract; the wire's extremes overflowed here).
  const std::optional<Duration> transit = sent != TimePoint{} ? OneWayDelay(sent, received) : std::nullopt;
  // A retransmission's transit is the client's resend wait, not the network's:
  // it counts in neither the jitter nor the transit range.
  bool resent = false;
  // Slower than the slowest recent first copies (their 90th percentile) by
  // more than reordering explains: a copy sent again.
  const auto came_resent = [&] {
    return transit && transit_count_ > 0 && *transit - SlowTransit() > options_.reorder_tolerance;
  };
  if (!started_) {
    started_ = true;
    highest_ = lowest_ = sequence;
    Decide(false);
  } else if (sequence < lowest_) {
    // Sent before the first that came (reordered at the start): not lost;
    // the numbers between it and that first one are missing now. Counted
    // as reordered (its loss cannot be judged), but a copy this much slower
    // than the first that came is a retransmission all the same: its
    // transit carries the resend wait (kept out of the transits, and
    // returned: playback's delay history leaves it out).
    for (std::int64_t s = sequence + 1; s < lowest_ && missing_.size() < kMaxMissing; ++s)
      missing_.emplace(s, received);
    lowest_ = sequence;
    ++f_.reordered;
    Decide(false);
    resent = came_resent();
  } else if (sequence > highest_) {
    // Numbers skipped are missing until they come or the horizon passes; a
    // jump past the bound (the SequenceWindow refuses such) decides them lost.
    for (std::int64_t s = highest_ + 1; s < sequence; ++s) {
      if (missing_.size() < kMaxMissing) {
        missing_.emplace(s, received);
      } else {
        Decide(true);
      }
    }
    highest_ = sequence;
    Decide(false);
  } else if (const auto it = missing_.find(sequence); it != missing_.end()) {
    missing_.erase(it);
    // Reordered (came a little late) or a retransmission (its first copy was
    // lost, and this copy carries the first one's send time, so its transit
    // includes the client's resend wait): told apart by how much slower it
    // travelled than the slowest recent first copies (came_resent).
    resent = came_resent();
    if (resent) {
      ++f_.retransmitted;
    } else {
      ++f_.reordered;
    }
    Decide(resent);
  } else {
    resent = true;
    ++f_.retransmitted;  // a number already decided lost: its retransmission came at last
  }
  if (transit && !resent) {
    if (last_transit_) {
      const double d = std::abs(static_cast<double>((*transit - *last_transit_).count())) / 1000.0;
      jitter_us_ += (d - jitter_us_) / 16.0;
    }
    last_transit_ = transit;
    transits_[transit_next_] = *transit;
    transit_next_ = (transit_next_ + 1) % transits_.size();
    transit_count_ = std::min(transit_count_ + 1, transits_.size());
  }
  return resent;
}

void LinkHealth::OnReply(Duration lateness, bool expired, TimePoint now) {
  Tick(now);
  ++f_.replies;
  if (expired) {
    ++f_.expired;
    ++current_.expired;
  } else if (lateness > options_.late_threshold) {
    ++f_.late;
  }
}

void LinkHealth::Tick(TimePoint now) {
  // Detection times are not in sequence order (a number skipped later can
  // be lower than one skipped earlier only by a reordering, but sweep anyway).
  for (auto it = missing_.begin(); it != missing_.end();) {
    if (now - it->second >= options_.loss_horizon) {
      it = missing_.erase(it);
      Decide(true);
    } else {
      ++it;
    }
  }
  if (!window_started_) {
    window_started_ = true;
    window_start_ = now;
  }
  while (now - window_start_ >= options_.window) {
    previous_ = current_;
    current_ = {};
    window_start_ += options_.window;
    if (now - window_start_ >= options_.window) {  // silent for two windows: nothing recent
      previous_ = {};
      window_start_ = now;
    }
  }
}

LinkFigures LinkHealth::Figures() const {
  LinkFigures f = f_;
  f.jitter = Duration(static_cast<Duration::rep>(jitter_us_ * 1000));
  f.loss = f.expected == 0 ? 0.0 : static_cast<double>(f.lost) / static_cast<double>(f.expected);
  const std::uint64_t expected = current_.expected + previous_.expected;
  f.recent_loss = expected == 0
                      ? 0.0
                      : static_cast<double>(current_.lost + previous_.lost) / static_cast<double>(expected);
  f.recent_expired = current_.expired + previous_.expired;
  return f;
}

LinkHealth::Verdict LinkHealth::Evaluate() const {
  Verdict v;
  if (!started_) return v;
  const LinkFigures f = Figures();
  const auto past = [&](const LinkThresholds& t) {
    std::string why;
    const auto add = [&](const std::string& part) { why += (why.empty() ? "" : ", ") + part; };
    char buf[96];
    if (f.recent_loss > t.loss) {
      std::snprintf(buf, sizeof buf, "loss %.1f %% > %.1f %%", 100 * f.recent_loss, 100 * t.loss);
      add(buf);
    }
    if (const std::optional<Duration> delay = f.delay(); delay && *delay > t.delay) {
      std::snprintf(buf, sizeof buf, "delay %.0f ms > %.0f ms", ToSeconds(*delay) * 1e3,
                    ToSeconds(t.delay) * 1e3);
      add(buf);
    }
    if (f.jitter > t.jitter) {
      std::snprintf(buf, sizeof buf, "jitter %.1f ms > %.1f ms", ToSeconds(f.jitter) * 1e3,
                    ToSeconds(t.jitter) * 1e3);
      add(buf);
    }
    if (f.recent_expired >= t.expired && t.expired > 0) {
      std::snprintf(buf, sizeof buf, "%llu expired commands (limit %llu)",
                    static_cast<unsigned long long>(f.recent_expired),
                    static_cast<unsigned long long>(t.expired));
      add(buf);
    }
    return why;
  };
  if (std::string why = past(options_.stop); !why.empty()) return {Level::kBad, std::move(why)};
  if (std::string why = past(options_.warn); !why.empty()) return {Level::kDegraded, std::move(why)};
  v.level = Level::kGood;
  return v;
}

}  // namespace robotalk
