#include "client/faulty_transport.h"

#include "robotalk/error.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <random>
#include <regex>
#include <vector>

namespace robotalk::testing {

namespace {

struct Rule {
  FaultyTransport::FaultId id = 0;
  Fault fault;
  std::regex regex;
  FaultCounts counts;
};

// A message held by a fault: sent `copies` times when released.
struct Held {
  FaultyTransport::FaultId rule = 0;
  std::string channel;
  std::vector<std::uint8_t> bytes;
  int copies = 1;
  TimePoint due{};
};

}  // namespace

struct FaultyTransport::State {
  explicit State(const FaultyTransportOptions& options)
      : rng(options.seed), clock(options.clock ? options.clock : &steady) {}

  // How many copies of a message go on now (0: dropped or held). Held
  // messages go to `delayed` or a batch; a batch that fills up is moved to
  // `release`, last first. REQUIRES: mu held.
  int Decide(Direction direction, const std::string& channel, std::span<const std::uint8_t> bytes,
             std::vector<Held>& release) {
    int copies = 1;
    for (Rule& r : rules) {
      const Fault& f = r.fault;
      if (f.direction != direction || !std::regex_match(channel, r.regex)) continue;
      if (f.when && !f.when(channel, bytes)) continue;
      ++r.counts.matched;
      if (f.mute || r.counts.matched <= static_cast<std::uint64_t>(f.drop_first) ||
          (f.drop_probability > 0 && Draw() < f.drop_probability)) {
        ++r.counts.dropped;
        return 0;
      }
      if (f.duplicate_probability > 0 && Draw() < f.duplicate_probability) {
        ++r.counts.duplicated;
        copies *= 2;
      }
      if (f.delay > Duration(0) || f.reverse_batch > 0) {
        ++r.counts.held;
        Held h{r.id, channel, {bytes.begin(), bytes.end()}, copies, clock->Now() + f.delay};
        if (f.delay > Duration(0)) {
          delayed.push_back(std::move(h));
          return 0;
        }
        std::vector<Held>& batch = batches[r.id];
        batch.push_back(std::move(h));
        if (batch.size() >= f.reverse_batch) TakeBatch(r.id, release);
        return 0;
      }
    }
    return copies;
  }

  double Draw() { return std::uniform_real_distribution<double>(0.0, 1.0)(rng); }

  // Moves fault `id`'s batch to `out`, last first. REQUIRES: mu held.
  void TakeBatch(FaultId id, std::vector<Held>& out) {
    auto it = batches.find(id);
    if (it == batches.end()) return;
    for (auto h = it->second.rbegin(); h != it->second.rend(); ++h) out.push_back(std::move(*h));
    Count(id, it->second.size());
    batches.erase(it);
  }

  // Moves the delayed messages `pick` selects to `out`, in order. REQUIRES: mu held.
  template <typename Pick>
  void TakeDelayed(Pick pick, std::vector<Held>& out) {
    auto keep =
        std::stable_partition(delayed.begin(), delayed.end(), [&](const Held& h) { return !pick(h); });
    for (auto it = keep; it != delayed.end(); ++it) {
      Count(it->rule, 1);
      out.push_back(std::move(*it));
    }
    delayed.erase(keep, delayed.end());
  }

  void Count(FaultId id, std::size_t released) {  // REQUIRES: mu held
    for (Rule& r : rules) {
      if (r.id == id) r.counts.released += released;
    }
  }

  mutable std::mutex mu;
  std::vector<Rule> rules;  // GUARDED_BY(mu), in the order added
  std::mt19937_64 rng;      // GUARDED_BY(mu)
  SteadyClock steady;
  const Clock* clock;
  std::vector<Held> delayed;                     // GUARDED_BY(mu), in the order held
  std::map<FaultId, std::vector<Held>> batches;  // GUARDED_BY(mu), in the order held
  FaultId next_id = 1;                           // GUARDED_BY(mu)
};

namespace {

int Send(Transport& inner, const std::vector<Held>& messages) {
  for (const Held& h : messages) {
    for (int k = 0; k < h.copies; ++k) inner.Publish(h.channel, h.bytes);
  }
  return static_cast<int>(messages.size());
}

}  // namespace

FaultyTransport::FaultyTransport(Transport& inner, FaultyTransportOptions options)
    : inner_(inner), state_(std::make_shared<State>(options)) {}

FaultyTransport::~FaultyTransport() = default;

FaultyTransport::FaultId FaultyTransport::Add(Fault fault) {
  const auto bad = [&](const std::string& why) {
    return Error("FaultyTransport: fault on '" + fault.channel_regex + "': " + why);
  };
  const bool holds = fault.delay > Duration(0) || fault.reverse_batch > 0;
  if (holds && fault.direction == Direction::kIncoming) throw bad("an incoming fault cannot hold messages");
  if (fault.delay > Duration(0) && fault.reverse_batch > 0) throw bad("delay and reverse_batch together");
  for (double p : {fault.drop_probability, fault.duplicate_probability}) {
    if (!(p >= 0.0 && p <= 1.0)) throw bad("probability " + std::to_string(p) + " is not in [0, 1]");
  }
  Rule rule;
  try {
    rule.regex = std::regex(fault.channel_regex, std::regex::extended);
  } catch (const std::regex_error& e) {
    throw bad(std::string("bad channel regex: ") + e.what());
  }
  rule.fault = std::move(fault);
  std::lock_guard lock(state_->mu);
  rule.id = state_->next_id++;
  state_->rules.push_back(std::move(rule));
  return state_->rules.back().id;
}

void FaultyTransport::Remove(FaultId id) {
  std::vector<Held> release;
  {
    std::lock_guard lock(state_->mu);
    state_->TakeDelayed([&](const Held& h) { return h.rule == id; }, release);
    state_->TakeBatch(id, release);
    std::erase_if(state_->rules, [&](const Rule& r) { return r.id == id; });
  }
  Send(inner_, release);
}

FaultCounts FaultyTransport::counts(FaultId id) const {
  std::lock_guard lock(state_->mu);
  for (const Rule& r : state_->rules) {
    if (r.id == id) return r.counts;
  }
  throw Error("FaultyTransport: no fault " + std::to_string(id));
}

int FaultyTransport::ReleaseDue() {
  std::vector<Held> release;
  {
    std::lock_guard lock(state_->mu);
    const TimePoint now = state_->clock->Now();
    state_->TakeDelayed([&](const Held& h) { return h.due <= now; }, release);
  }
  return Send(inner_, release);
}

int FaultyTransport::ReleaseAll() {
  std::vector<Held> release;
  {
    std::lock_guard lock(state_->mu);
    state_->TakeDelayed([](const Held&) { return true; }, release);
    while (!state_->batches.empty()) state_->TakeBatch(state_->batches.begin()->first, release);
  }
  return Send(inner_, release);
}

std::size_t FaultyTransport::held() const {
  std::lock_guard lock(state_->mu);
  std::size_t n = state_->delayed.size();
  for (const auto& [id, batch] : state_->batches) n += batch.size();
  return n;
}

void FaultyTransport::Publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  ReleaseDue();
  std::vector<Held> release;
  int copies = 0;
  {
    std::lock_guard lock(state_->mu);
    copies = state_->Decide(Direction::kOutgoing, channel, bytes, release);
  }
  for (int k = 0; k < copies; ++k) inner_.Publish(channel, bytes);
  Send(inner_, release);
}

std::unique_ptr<Subscription> FaultyTransport::Subscribe(const std::string& channel_regex, Handler handler) {
  return inner_.Subscribe(
      channel_regex, [state = state_, handler = std::move(handler)](const std::string& channel,
                                                                    std::span<const std::uint8_t> bytes) {
        std::vector<Held> none;  // incoming faults never hold (Add refuses them)
        int copies = 0;
        {
          std::lock_guard lock(state->mu);
          copies = state->Decide(Direction::kIncoming, channel, bytes, none);
        }
        for (int k = 0; k < copies; ++k) handler(channel, bytes);
      });
}

int FaultyTransport::HandleFor(Duration timeout) {
  ReleaseDue();
  return inner_.HandleFor(timeout);
}

int FaultyTransport::fileno() const { return inner_.fileno(); }

std::string FaultyTransport::url() const { return inner_.url(); }

}  // namespace robotalk::testing
