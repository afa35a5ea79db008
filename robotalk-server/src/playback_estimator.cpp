#include "playback_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace robotalk {

PlaybackEstimator::PlaybackEstimator(std::size_t total_frames, Duration duration,
                                     PlaybackEstimatorOptions options)
    : total_(std::max<std::size_t>(total_frames, 1)), duration_(duration), options_(options) {
  const auto by_fraction =
      static_cast<std::size_t>(std::ceil(options_.fraction * static_cast<double>(total_)));
  needed_ = std::min(total_, std::max(options_.min_frames, by_fraction));
  frames_.reserve(std::min<std::size_t>(needed_, 1024));  // a declaration is a claim, not memory to reserve
}

std::optional<Duration> OneWayDelay(TimePoint sent, TimePoint arrival) {
  const std::optional<Duration> d = CheckedSub(arrival, sent);
  constexpr Duration kBound(Duration::rep{1} << 61);
  if (!d || *d > kBound || *d < -kBound) return std::nullopt;
  return d;
}

void DelayHistory::Ring::Push(const Sample& s) {
  samples[next] = s;
  next = (next + 1) % kCapacity;
  size = std::min(size + 1, kCapacity);
}

void DelayHistory::Ring::AppendRecent(TimePoint now, Duration window, std::vector<Sample>& out) const {
  for (std::size_t k = 0; k < size; ++k) {
    const Sample& s = samples[(next + kCapacity - size + k) % kCapacity];
    if (now - s.received <= window) out.push_back(s);
  }
}

void DelayHistory::Add(TimePoint sent, TimePoint received, std::optional<TimePoint> arrived) {
  const std::optional<Duration> d = OneWayDelay(sent, received);
  if (!d) return;
  const Duration lag = arrived && *arrived < received ? received - *arrived : Duration(0);
  delays_.Push({received, *d, lag});
}

void DelayHistory::AddCopy(TimePoint sent, TimePoint received) {
  copies_.Push({received, OneWayDelay(sent, received).value_or(Duration(0)), Sample::kCopy});
}

std::vector<DelayHistory::Sample> DelayHistory::RecentSamples(TimePoint now, Duration window) const {
  std::vector<Sample> out;
  out.reserve(delays_.size + copies_.size);
  delays_.AppendRecent(now, window, out);
  const auto first_copy = static_cast<std::ptrdiff_t>(out.size());
  copies_.AppendRecent(now, window, out);
  // Both rings are in the order handled: one list in that order, a delay before a copy handled at the same
  // time.
  std::inplace_merge(out.begin(), out.begin() + first_copy, out.end(),
                     [](const Sample& a, const Sample& b) { return a.received < b.received; });
  return out;
}

std::vector<Duration> DelayHistory::Recent(TimePoint now, Duration window) const {
  std::vector<Sample> samples;
  delays_.AppendRecent(now, window, samples);
  std::vector<Duration> out;
  for (const Sample& s : samples) out.push_back(s.delay);
  return out;
}

void PlaybackEstimator::SetDelayHistory(const std::vector<DelayHistory::Sample>& samples) {
  history_.clear();
  history_received_.clear();
  history_lag_.clear();
  copies_.clear();
  for (const DelayHistory::Sample& s : samples) {
    if (s.copy()) {
      copies_.push_back({s.received, s.delay});
      continue;
    }
    history_.push_back(s.delay);
    history_received_.push_back(s.received);
    history_lag_.push_back(s.lag);
  }
}

void PlaybackEstimator::Add(Duration offset, TimePoint arrival, std::optional<TimePoint> sent, Duration lag) {
  frames_.push_back({offset, arrival, sent ? OneWayDelay(*sent, arrival) : std::nullopt, lag});
}

std::vector<PlaybackEstimator::Seen> PlaybackEstimator::SeenPackages() const {
  std::vector<Seen> seen;
  if (frames_.empty() || history_.size() + frames_.size() < options_.quick_min_delays) return seen;
  const bool known = history_received_.size() == history_.size();
  for (std::size_t k = 0; k < history_.size(); ++k)
    seen.push_back({known ? history_received_[k] : TimePoint{}, history_[k], known});
  for (const Frame& f : frames_) {
    if (!f.delay) return {};  // a client that sends no send times
    seen.push_back({f.arrival, *f.delay, true});
  }
  return seen;
}

bool PlaybackEstimator::ArrivedInSendOrder(const std::vector<Seen>& seen) {
  // Each package's send time is its arrival − its delay (both on the server
  // clock, less the constant offset); in arrival order they must not go back.
  std::vector<std::pair<TimePoint, TimePoint>> order;  // arrival, send time
  for (const Seen& p : seen) {
    if (!p.known_arrival) return false;
    order.push_back({p.arrival, p.arrival - p.delay});
  }
  std::sort(order.begin(), order.end());
  for (std::size_t j = 1; j < order.size(); ++j)
    if (order[j].second < order[j - 1].second) return false;
  return !order.empty();
}

PlaybackEstimator::Channel PlaybackEstimator::ChannelDelays() const {
  const std::vector<Seen> seen = SeenPackages();
  Channel measured;
  for (const Seen& p : seen) measured.delays.push_back(p.delay);
  if (!options_.burst_wait_discount || measured.delays.empty()) return measured;
  const auto spread = [](const std::vector<Duration>& d) {
    const auto [lo, hi] = std::minmax_element(d.begin(), d.end());
    return ToSeconds(*hi - *lo);
  };
  const double gate = Gate();
  // Within the gate too where the link is FIFO: the burst's own queue then
  // overstates the worst delay a frame meets (issue 23, seventh session: at
  // U[0, 50] starts of 1.4 to 2 times the hindsight minimum). A jittery
  // link reorders a burst sent a millisecond apart, and its spread is the
  // jitter frames meet too: there only where the gate needs it.
  const bool fifo = options_.burst_wait_discount_fifo && ArrivedInSendOrder(seen);
  if (!fifo && spread(measured.delays) <= gate) return measured;
  // A client's connect-time packages (hello, clock, heartbeat) leave within a
  // millisecond; on a congested FIFO link each waits for the one before it to
  // get through, so their delays add up the services before them: a spread
  // that a frame, one interval after the one before it, does not meet. With
  // d_min the least delay, package j would have arrived at u_j = s_j + d_min
  // (s_j its send time) behind an empty queue; it could not get through
  // before a_{j-1}, so it waited w_j = max(0, a_{j-1} - u_j) behind its
  // predecessor (Lindley's recursion, as in Services). That wait is left
  // out for a package sent less than a frame interval after the one before
  // it (a burst denser than the sequence), the first frame's included (sent
  // right after the connect-time packages). A later frame keeps its wait: a
  // queue of frames is what the gate is for.
  Channel discounted{measured.delays, true};
  const Duration least = *std::min_element(measured.delays.begin(), measured.delays.end());
  const Duration burst = FromSeconds(interval());
  for (std::size_t j = 1; j < seen.size() && j <= history_.size(); ++j) {
    if (!seen[j].known_arrival || !seen[j - 1].known_arrival) continue;
    const TimePoint sent = seen[j].arrival - seen[j].delay,
                    sent_before = seen[j - 1].arrival - seen[j - 1].delay;
    // A copy of an earlier package handled between the two (the client's
    // retransmission): on a FIFO link the package waited behind it, whenever
    // it was sent, a queue the client's own copy made.
    const TimePoint before = BehindCopy(seen[j - 1].arrival, seen[j].arrival);
    if (before == seen[j - 1].arrival && (sent - sent_before >= burst || sent < sent_before)) continue;
    const Duration wait = before - (sent + least);
    discounted.delays[j] -= std::clamp(wait, Duration(0), seen[j].delay - least);
  }
  // Only on a FIFO link, where that brings the spread within the gate, or
  // where a queue beyond it may be followed (follow_queue: its start covers
  // the channel's delays, not the burst's own queue); else as measured.
  const bool follows = options_.follow_queue && !options_.queue_start;
  return fifo || spread(discounted.delays) <= gate || follows ? discounted : measured;
}

TimePoint PlaybackEstimator::BehindCopy(TimePoint after, TimePoint before) const {
  TimePoint latest = after;
  for (const Copy& c : copies_)
    if (c.received > latest && c.received < before) latest = c.received;
  return latest;
}

bool PlaybackEstimator::burst_discounted() const { return ChannelDelays().discounted; }

std::optional<Duration> PlaybackEstimator::delay_spread() const {
  const std::vector<Duration> delays = ChannelDelays().delays;
  if (delays.empty()) return std::nullopt;
  const auto [lo, hi] = std::minmax_element(delays.begin(), delays.end());
  return *hi - *lo;
}

double PlaybackEstimator::interval() const {
  return total_ > 1 ? ToSeconds(duration_) / static_cast<double>(total_ - 1) : 1.0;
}

std::optional<PlaybackEstimator::Spread> PlaybackEstimator::FencedSpread() const {
  std::vector<Duration> delays = ChannelDelays().delays;
  if (delays.empty()) return std::nullopt;  // too few, or a frame without a send time
  std::sort(delays.begin(), delays.end());
  // A package whose first copy was lost arrives as its retransmission, which
  // carries its first send time: its delay includes the client's resend wait
  // (100 ms at least by default, doubling). Such outliers, more than
  // max(8 × (median − least), 50 ms) above the median, are not the
  // channel's jitter and are left out (a later frame that is that slow gets
  // its gap stretched, or is late).
  const Duration least = delays.front(), median = delays[delays.size() / 2];
  const Duration fence = median + std::max(8 * (median - least), Duration(std::chrono::milliseconds(50)));
  std::size_t kept = delays.size();
  while (kept > 1 && delays[kept - 1] > fence) --kept;
  return Spread{least, delays[kept - 1], kept};
}

bool PlaybackEstimator::SpreadWithinGate() const {
  // The whole spread, outliers included: the paper's congestion (a server
  // pausing after each package) shows as a few slow packages among fast ones.
  const std::optional<Duration> spread = delay_spread();
  return spread && ToSeconds(*spread) <= Gate();
}

double PlaybackEstimator::WiderStretch() const {
  return std::max(0.0, options_.max_stretch - PlaybackEstimatorOptions::kGateStretch);
}

double PlaybackEstimator::Gate() const {
  // The gate was set for the default stretch (kGateStretch): frames whose
  // services exceed the interval by up to that much are followed gap by gap.
  // A wider stretch follows services as much longer, so the gate moves up by
  // the difference (a service of at most (1 + max_stretch) intervals adds at
  // most max_stretch intervals to the next frame's delay: one gap's stretch).
  return (options_.adaptive_max_spread + WiderStretch()) * interval();
}

bool PlaybackEstimator::adaptive() const {
  if (!options_.adaptive || !delay_spread()) return false;
  if (SpreadWithinGate()) return true;
  if (options_.queue_start) return QueueFollowable(options_.confidence_z);
  return options_.follow_queue && ServerKeptUp() && QueueFollowable(options_.follow_z);
}

bool PlaybackEstimator::followed() const {
  return !options_.queue_start && adaptive() && !SpreadWithinGate();
}

Duration PlaybackEstimator::followed_queue() const {
  return *playout_delay() - options_.adaptive_margin - FencedSpread()->least;
}

bool PlaybackEstimator::ServerKeptUp() const {
  // The server's own lag handling a package (handled − reached the socket)
  // is a queue in front of the playback that the link's services do not
  // show: the paper's Fig. 11 pauses the server after each package, 8
  // packages a second against 10 frames, a drift the stretch cannot follow.
  const Duration bound =
      FromSeconds(std::max(0.0, options_.follow_max_lag) * std::max(0.0, options_.max_stretch) * interval());
  for (Duration lag : history_lag_)
    if (lag > bound) return false;
  for (const Frame& f : frames_)
    if (f.lag > bound) return false;
  return true;
}

bool PlaybackEstimator::QueueFollowable(double z) const {
  // The frames' queue drifts by (mean service - T) a frame, which the
  // stretch follows up to max_stretch × T. A channel that may be slower than
  // that (the mean's upper confidence bound, of the few services seen) gets
  // the paper's estimate, which waits for frames and projects their drift.
  // Re-checked at every frame before the start is decided: paced frames
  // show the pauses that sparse packages may not (Fig. 11's injector).
  const std::vector<double> s = Services();
  const auto n = static_cast<double>(s.size());
  double mean = 0, var = 0;
  for (double x : s) mean += x / n;
  for (double x : s) var += (x - mean) * (x - mean);
  const double sd = s.size() > 1 ? std::sqrt(var / (n - 1)) : mean;
  return mean + z * sd / std::sqrt(n) <= interval() * (1.0 + options_.max_stretch);
}

bool PlaybackEstimator::ready() const {
  if (!queued()) return quick() || frames_.size() >= needed_;
  if (frames_.size() >= needed_) return true;
  // The queue start is decided once the next frame may come after it: until
  // then nothing plays, and each frame that comes first adds its service
  // (paced frames show the sequence's own queue, which sparse packages may
  // not: Fig. 11's server pauses after each package).
  TimePoint latest = TimePoint::min();
  for (const Frame& f : frames_) latest = std::max(latest, f.arrival);
  return StartTime() - latest < FromSeconds(interval());
}

bool PlaybackEstimator::queued() const { return options_.queue_start && adaptive() && !SpreadWithinGate(); }

std::vector<double> PlaybackEstimator::Services() const {
  // The packages seen (the history's and the frames'), in arrival order. On a
  // FIFO bottleneck whose least delay is d_min, package j would arrive at
  // u_j = a_j - (d_j - d_min) with an empty queue; it waited for the one
  // before it until max(a_{j-1}, u_j), so its own service took
  // s_j = a_j - max(a_{j-1}, u_j) (Lindley's recursion read backwards). A
  // delay beyond the fence (a retransmission: its resend wait) is no service.
  const std::vector<Seen> seen = SeenPackages();  // both in arrival order
  const std::vector<Duration> channel = ChannelDelays().delays;
  const Spread fenced = *FencedSpread();
  std::vector<double> service;  // s
  std::optional<TimePoint> previous;
  for (std::size_t k = 0; k < seen.size(); ++k) {
    const Seen& p = seen[k];
    const Duration excess = p.delay - fenced.least;
    Duration s = excess;  // arrival unknown: as if it had not queued (the larger service)
    if (p.known_arrival && previous)
      s = std::min(excess, p.arrival - std::max(BehindCopy(*previous, p.arrival), p.arrival - excess));
    if (p.known_arrival) previous = p.arrival;
    if (channel[k] <= fenced.most) service.push_back(ToSeconds(s));
  }
  return service;  // not empty: the fence keeps the least
}

Duration PlaybackEstimator::QueueWorst() const {
  const std::vector<double> service = Services();
  const Duration least = FencedSpread()->least;
  // The sequence's frames, one every interval T, queue behind each other:
  // frame i waits w_i = max(0, w_{i-1} + s_{i-1} - T) (Lindley) and arrives
  // d_min + w_i + s_i. Resampled from the services seen (a fixed seed: the
  // estimate is a pure function of its inputs), the worst of each simulated
  // sequence; the start covers their queue_quantile. A channel slower than
  // the sequence (mean s > T, the paper's Fig. 11) drifts, and the simulated
  // worst grows with the sequence's length as the real one will.
  const double t = interval();
  const std::size_t frames = std::min(total_, kQueueHorizon);
  const std::size_t runs = std::max<std::size_t>(options_.queue_resamples, 1);
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  const auto draw = [&] {  // splitmix64
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return service[(z ^ (z >> 31)) % service.size()];
  };
  std::vector<double> worst(runs);
  for (double& w_max : worst) {
    double wait = 0, previous_s = 0, total = 0;
    for (std::size_t i = 0; i < frames; ++i) {
      wait = std::max(0.0, wait + previous_s - t);
      previous_s = draw();
      total += previous_s;
      w_max = std::max(w_max, wait + previous_s);
    }
    // Beyond the horizon, a drifting queue keeps growing at its drift.
    const double drift = total / static_cast<double>(frames) - t;
    if (drift > 0) w_max += drift * static_cast<double>(total_ - frames);
  }
  const auto q = static_cast<std::size_t>(
      std::clamp(options_.queue_quantile, 0.0, 1.0) * static_cast<double>(runs - 1) + 0.5);
  std::nth_element(worst.begin(), worst.begin() + static_cast<std::ptrdiff_t>(q), worst.end());
  return least + FromSeconds(worst[q]);
}

bool PlaybackEstimator::quick() const {
  if (adaptive()) return true;
  if (options_.adaptive) return false;  // the adaptive start's fallback is the paper's estimate
  if (!options_.quick_start) return false;
  const std::optional<Duration> spread = delay_spread();
  // A spread this small beside the frame interval is a channel that keeps up
  // (a queue cannot build); a larger one gets the paper's estimate, which
  // sees the drift.
  const double interval = total_ > 1 ? ToSeconds(duration_) / static_cast<double>(total_ - 1) : 1.0;
  return spread && ToSeconds(*spread) <= options_.quick_max_spread * interval;
}

Duration PlaybackEstimator::AdaptiveWorst(double headroom) const {
  if (queued()) return QueueWorst();
  const Spread s = *FencedSpread();
  const Duration spread = s.most - s.least;
  // Delays that vary by less than a frame interval cannot build a queue of
  // frames: the worst recent delay, and the schedule's stretch for a slower
  // frame. The spread beyond one interval may accumulate in a queue that
  // sparse packages never met: it is covered quick_jitter_factor times.
  // With a wider stretch than the default, the threshold moves up with the
  // gate (see Gate()): the stretch follows what lies below it.
  // A followed queue (beyond the gate) is covered by the playout delay the
  // stretch grows to (playout_delay), not by the start.
  const double excess =
      followed()
          ? 0.0
          : std::max(0.0, ToSeconds(spread) - (options_.quick_max_spread + WiderStretch()) * interval());
  return s.most + FromSeconds(excess * options_.quick_jitter_factor +
                              ToSeconds(spread) * headroom / static_cast<double>(s.kept));
}

void PlaybackEstimator::AddFrameCopy(TimePoint sent, TimePoint received) {
  const std::optional<Duration> d = OneWayDelay(sent, received);
  if (!d) return;
  frame_copies_.push_back(*d);
  DecideAt(received);
}

Duration PlaybackEstimator::CopiesWorst() const {
  const Duration single = AdaptiveWorst(options_.start_headroom);
  if (followed() || queued()) return single;
  // The single-copy delays: the channel's (history and frames; a frame's
  // first copy is the earlier of its two, its second the later: two draws)
  // and the frames' second copies, within the fence (a retransmission's
  // resend wait is no draw of the channel).
  std::vector<Duration> x = ChannelDelays().delays;
  x.insert(x.end(), frame_copies_.begin(), frame_copies_.end());
  std::sort(x.begin(), x.end());
  const Duration least = x.front(), median = x[x.size() / 2];
  const Duration fence = median + std::max(8 * (median - least), Duration(std::chrono::milliseconds(50)));
  while (x.size() > 1 && x.back() > fence) x.pop_back();
  const auto n = static_cast<double>(x.size());
  const Duration spread = x.back() - least;
  // M frames to come, each the earlier of two independent draws: the
  // quantile whose tail is sqrt(copies_tail / M) (P(min > x) = P(X > x)²),
  // at the plotting position rank u (n + 1); past the largest, spread / n a rank.
  const double to_come =
      static_cast<double>(std::max<std::size_t>(1, total_ - std::min(total_, frames_.size())));
  const double u = 1.0 - std::sqrt(std::clamp(options_.copies_tail, 0.0, to_come) / to_come);
  const double rank = u * (n + 1.0);  // 1-based
  Duration q;
  if (rank <= 1.0) {
    q = least;
  } else if (rank >= n) {
    q = x.back() + FromSeconds((rank - n) * ToSeconds(spread) / n);
  } else {
    const auto lo = static_cast<std::size_t>(std::floor(rank)) - 1;
    const double f = rank - std::floor(rank);
    q = x[lo] + FromSeconds(f * ToSeconds(x[lo + 1] - x[lo]));
  }
  // The spread beyond one interval (a queue sparse packages never met) as the single-copy start adds it.
  const Spread s = *FencedSpread();
  const Duration excess =
      single - s.most -
      FromSeconds(ToSeconds(s.most - s.least) * options_.start_headroom / static_cast<double>(s.kept));
  return std::min(single, q + std::max(Duration(0), excess));
}

Duration PlaybackEstimator::StartWorst() const {
  return options_.copies_start && frames_copied() ? CopiesWorst() : AdaptiveWorst(options_.start_headroom);
}

std::optional<Duration> PlaybackEstimator::playout_delay() const {
  if (!adaptive()) return std::nullopt;
  const Duration worst = AdaptiveWorst(options_.adaptive_headroom);
  // A followed queue: the worst delay of its simulated sequences, which the
  // schedule reaches by stretching each gap (at most max_stretch of it).
  return (followed() ? std::max(worst, QueueWorst()) : worst) + options_.adaptive_margin;
}

PlaybackScheduleOptions PlaybackEstimator::schedule_options() const {
  // With the adaptive estimator the gaps stretch whichever start decided
  // (its fallback, the paper's estimate, too); the quick and the paper's
  // estimators keep the fixed schedule.
  if (!options_.adaptive) return {.max_stretch = 0.0, .margin = options_.adaptive_margin};
  // The thin buffer's lead scales with the channel: a quarter of the delay
  // spread (on an unimpaired link a fraction of a millisecond, so its
  // sequences keep the normal bound), on a FIFO link only (every package
  // seen arrived in the order it was sent): there the frames after a thin
  // one queue behind it. On a jittery link a frame's delay says little of
  // the next one's: only a frame past the normal bound takes the wider one.
  const std::optional<Duration> spread = delay_spread();
  const bool fifo = spread && ArrivedInSendOrder(SeenPackages());
  return {
      .max_stretch = options_.max_stretch,
      .margin = options_.adaptive_margin,
      .thin_max_stretch = options_.thin_stretch,
      .thin_lead = fifo ? FromSeconds(std::max(0.0, options_.thin_lead) * ToSeconds(*spread)) : Duration(0)};
}

Duration PlaybackEstimator::start_lead() const {
  return FromSeconds(std::max(0.0, options_.start_lead) * std::max(0.0, options_.max_stretch) * interval());
}

TimePoint PlaybackEstimator::StartCovering(Duration worst, Duration margin, Duration lead) const {
  // Offset 0 plays when the latest frame seen (arrival − offset) would plus
  // the worst delay's excess over the frame's own; never before the decision
  // (as StartTime).
  const Frame* anchor = &frames_.front();  // quick(): every frame has a delay
  Duration first_offset = Duration::max();
  TimePoint decided = TimePoint::min();
  for (const Frame& f : frames_) {
    if (f.arrival - f.offset > anchor->arrival - anchor->offset) anchor = &f;
    first_offset = std::min(first_offset, f.offset);
    decided = std::max(decided, f.arrival);
  }
  decided = std::max(decided, decided_at_);  // a wait for a frame's second copy ended: decided then
  const Duration excess = std::max(Duration(0), worst - *anchor->delay);
  return std::max(anchor->arrival - anchor->offset + excess - lead, decided - first_offset) + margin;
}

Duration PlaybackEstimator::mean_command_interval() const {
  if (frames_.size() < 2) return Duration(0);
  auto [lo, hi] = std::minmax_element(frames_.begin(), frames_.end(),
                                      [](const Frame& a, const Frame& b) { return a.offset < b.offset; });
  return (hi->offset - lo->offset) / static_cast<Duration::rep>(frames_.size() - 1);
}

Duration PlaybackEstimator::mean_arrival_interval() const {
  if (frames_.size() < 2) return Duration(0);
  auto [lo, hi] = std::minmax_element(frames_.begin(), frames_.end(),
                                      [](const Frame& a, const Frame& b) { return a.arrival < b.arrival; });
  return (hi->arrival - lo->arrival) / static_cast<Duration::rep>(frames_.size() - 1);
}

Duration PlaybackEstimator::ExtraLagBound(Duration remaining) const {
  // Each frame's lag behind its own offset, l_i = a_i - o_i, grows like a
  // queue's backlog: a random walk in the offset with drift mu (0 when the
  // channel keeps up, T_a/T_c - 1 when arrivals are slower) and variance
  // sigma^2 per second of offset. Both come from successive frames (sorted by
  // offset; a burst of frames at one offset counts once). Over the `remaining`
  // R seconds the lag grows by mu R +- sigma sqrt(R); mu itself is uncertain
  // by sigma / sqrt(T) after T seconds seen. Both at z standard deviations:
  // running dry costs more than starting a little later.
  std::vector<const Frame*> sorted;
  sorted.reserve(frames_.size());
  for (const Frame& f : frames_) sorted.push_back(&f);
  std::sort(sorted.begin(), sorted.end(),
            [](const Frame* a, const Frame* b) { return a->offset < b->offset; });
  double seen = 0, growth = 0;  // seconds of offset covered, lag gained over them
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    seen += ToSeconds(sorted[i]->offset - sorted[i - 1]->offset);
    growth += ToSeconds((sorted[i]->arrival - sorted[i]->offset) -
                        (sorted[i - 1]->arrival - sorted[i - 1]->offset));
  }
  if (seen <= 0) return Duration(0);  // every frame at one offset: no rate to see yet
  const double mu = growth / seen;
  double variance = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i) {
    const double dt = ToSeconds(sorted[i]->offset - sorted[i - 1]->offset);
    const double dl = ToSeconds((sorted[i]->arrival - sorted[i]->offset) -
                                (sorted[i - 1]->arrival - sorted[i - 1]->offset));
    variance += (dl - mu * dt) * (dl - mu * dt);
  }
  const double sigma = std::sqrt(variance / seen);
  const double z = options_.confidence_z;
  const double r = ToSeconds(remaining);
  const double mu_bound = std::max(0.0, mu + z * sigma / std::sqrt(seen));
  return FromSeconds(mu_bound * r + z * sigma * std::sqrt(r));
}

TimePoint PlaybackEstimator::StartTime() const {
  if (queued()) {
    // Still undecided after the paper's count of frames: the later of both.
    const TimePoint start = StartCovering(QueueWorst(), options_.adaptive_margin);
    return frames_.size() >= needed_ ? std::max(start, PaperStart()) : start;
  }
  if (adaptive()) {
    // Less the lead: the first gaps stretch (at most max_stretch × their
    // length each) until the buffer covers the worst delay, so the frames
    // after them find it; frame 0 itself has arrived. StartCovering's floor
    // (the decision + margin) stays.
    // Frames that come twice: the earlier of two delays (copies_start).
    return StartCovering(StartWorst(), options_.adaptive_margin, start_lead());
  }
  if (quick()) {
    // The worst delay a later frame may have is predicted as the least seen
    // plus quick_jitter_factor times the spread (the history is a sample:
    // its max underestimates the channel's).
    Duration least = Duration::max();
    for (const Frame& f : frames_) least = std::min(least, *f.delay);
    for (Duration d : history_) least = std::min(least, d);
    return StartCovering(least + FromSeconds(ToSeconds(*delay_spread()) * options_.quick_jitter_factor),
                         options_.quick_margin);
  }
  return PaperStart();
}

TimePoint PlaybackEstimator::PaperStart() const {
  // Frames seen must be there before they play: start >= a_i - o_i.
  TimePoint lag = TimePoint::min();
  Duration first_offset = Duration::max(), last_offset = Duration::min();
  TimePoint decided = TimePoint::min();  // the estimate is made when the last frame seen arrived
  for (const Frame& f : frames_) {
    lag = std::max(lag, f.arrival - f.offset);
    first_offset = std::min(first_offset, f.offset);
    last_offset = std::max(last_offset, f.offset);
    decided = std::max(decided, f.arrival);
  }
  // Frames still to come lag more if the channel is slower than the sequence.
  const TimePoint projected = lag + ExtraLagBound(duration_ - std::min(duration_, last_offset));
  // Nothing may be scheduled before the decision: the waiting for enough
  // frames is playback's start latency (paper Table I).
  return std::max(projected, decided - first_offset) + options_.margin;
}

std::string PlaybackEstimator::Describe() const {
  // Milliseconds above the least delay seen (the clocks' offset cancels), to one decimal.
  const std::vector<Seen> seen = SeenPackages();
  const Channel channel = ChannelDelays();
  Duration least = Duration::max();
  for (const Seen& p : seen) least = std::min(least, p.delay);
  const auto ms = [](Duration d) {
    char b[32];
    std::snprintf(b, sizeof b, "%.1f", ToSeconds(d) * 1e3);
    return std::string(b);
  };
  const auto list = [&](auto begin, auto end, auto f) {
    std::string out = "[";
    for (auto it = begin; it != end; ++it) out += (it == begin ? "" : ",") + f(*it);
    return out + "]";
  };
  std::string out = "{\"history\":" + std::to_string(history_.size()) + ",\"delays\":" +
                    list(seen.begin(), seen.end(), [&](const Seen& p) { return ms(p.delay - least); });
  out += ",\"channel\":" +
         list(channel.delays.begin(), channel.delays.end(), [&](Duration d) { return ms(d - least); });
  const TimePoint sent0 =
      seen.empty() ? TimePoint{} : seen[history_.size()].arrival - seen[history_.size()].delay;
  out += ",\"sent\":" + list(seen.begin(), seen.end(), [&](const Seen& p) {
           return p.known_arrival ? ms(p.arrival - p.delay - sent0) : std::string("null");
         });
  // Copies of earlier packages: when handled (ms after the first frame) and the send time they carry.
  out += ",\"copies\":" + list(copies_.begin(), copies_.end(), [&](const Copy& c) {
           return "[" + ms(c.received - frames_.front().arrival) + "," +
                  (seen.empty() ? std::string("null") : ms(c.received - c.delay - sent0)) + "]";
         });
  out += ",\"lags\":" + list(history_lag_.begin(), history_lag_.end(), ms);
  out += ",\"frame_lags\":" + list(frames_.begin(), frames_.end(), [&](const Frame& f) { return ms(f.lag); });
  const TimePoint first = frames_.front().arrival;
  out += ",\"frame_arrivals\":" +
         list(frames_.begin(), frames_.end(), [&](const Frame& f) { return ms(f.arrival - first); });
  out += std::string(",\"adaptive\":") + (adaptive() ? "true" : "false") +
         ",\"followed\":" + (followed() ? "true" : "false") + ",\"queued\":" + (queued() ? "true" : "false") +
         ",\"discounted\":" + (channel.discounted ? "true" : "false");
  if (const std::optional<Spread> s = FencedSpread()) {
    out += ",\"fenced_most\":" + ms(s->most - least) + ",\"kept\":" + std::to_string(s->kept);
  }
  if (adaptive()) {
    if (frames_copied()) {
      out += ",\"frame_copies\":" +
             list(frame_copies_.begin(), frame_copies_.end(), [&](Duration d) { return ms(d - least); });
      out += ",\"copies_worst\":" + ms(CopiesWorst() - least) + ",\"decided\":" + ms(decided_at_ - first);
    }
    out += ",\"worst\":" + ms(AdaptiveWorst(options_.start_headroom) - least) +
           ",\"playout\":" + ms(*playout_delay() - least) + ",\"lead\":" + ms(start_lead());
    out += ",\"thin_lead\":" + ms(schedule_options().thin_lead);
  }
  if (!seen.empty()) out += ",\"frame0\":" + ms(seen[history_.size()].delay - least);
  out += ",\"start\":" + ms(StartTime() - first) + "}";
  return out;
}

}  // namespace robotalk
