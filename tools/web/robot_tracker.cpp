#include "robot_tracker.h"

#include "json_text.h"
#include "robotalk/announce_listener.h"
#include "robotalk/channels.h"
#include "robotalk/clock.h"
#include "robotalk/connect_scheduler.h"
#include "robotalk/error.h"
#include "robotalk/request.h"
#include "robotalk/robot_client.h"
#include "robotalk/routed_lcm_transport.h"
#include "scene_json.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <filesystem>
#include <map>
#include <mutex>
#include <thread>

namespace robotalk::web {
namespace {

// The newest sample of one robot, written by its client's ReadDaemon.
struct SampleSlot {
  std::mutex mutex;
  StateSample sample;          // GUARDED_BY(mutex)
  std::uint64_t received = 0;  // GUARDED_BY(mutex)
};

struct Robot {
  std::string name;
  std::int64_t server_id = 0;
  std::uint64_t announced_hash = 0;
  std::string driver;
  bool panic = false;
  int num_clients = 0;
  // The newest announcement taken: its server time, and when it came (steady).
  TimePoint announced_server_time{};
  TimePoint announced_at{};
  std::string message;
  std::shared_ptr<RobotClient> client;
  std::int64_t client_server_id = 0;
  std::uint64_t client_hash = 0;
  std::shared_ptr<SampleSlot> slot;
  std::uint64_t slot_seen = 0;
  // Touched by the Poll() thread only once `client` is set.
  std::shared_ptr<const RobotModel> model;
  std::unique_ptr<StatePoser> poser;
  std::uint64_t generation = 0;
  std::shared_ptr<const std::string> model_message;
  // A floating base without a control frame: its height and tilt are not in
  // the state stream, so a LINK_POSES query for the root runs alongside.
  std::optional<PendingReply> root_query;
  bool streaming = false;    // the current client asked for the state stream
  bool stream_task = false;  // a start/stop of the stream is queued
};

// A robot's panics in flight: one thread sends them, one at a time. Requests
// that come while one is sent (a page or Foxglove client may send them as
// fast as its socket carries them) are answered together by the next, so
// each request is answered by a panic sent after it came (a reset in between
// is not hidden), without a thread of its own.
using PanicDone = std::function<void(const std::string&)>;
struct PanicInFlight {
  std::thread thread;
  std::vector<PanicDone> sending;  // answered by the panic being sent
  std::vector<PanicDone> next;     // came after it was sent: answered by the next one
  bool finished = false;           // all answered: the thread is ending and may be joined
};
// The options of every client the tracker makes (connects, ListRobots' key).
ClientOptions ClientOptionsFor(const WebOptions& o) {
  ClientOptions co;
  co.lcm_url = o.lcm_url;
  co.key_file = o.key_file;
  co.server_key_file = o.server_key_file;
  return co;
}

// Requests that may wait for one robot's next panic; later ones are answered
// at once, saying so.
constexpr std::size_t kMaxPanicWaiters = 65536;

}  // namespace

class RobotTracker::Impl {
 public:
  explicit Impl(const WebOptions& o)
      : options_(o),
        only_key_(ExplicitServerKey(ClientOptionsFor(o))),
        connects_(std::make_unique<ConnectScheduler>(
            [this](const std::string& name, Duration timeout) { Connect(name, timeout); },
            [this](const std::string& name, const std::string& error, Duration) {
              ConnectFailed(name, error);
            },
            ConnectSchedulerOptions{.silent_after = FromSeconds(o.robot_timeout_s)})) {
    if (!o.key_file.empty() || !o.server_key_file.empty()) {
      // The keys every connect will use, read once now: a bad file is named at start-up.
      RobotClient check(ClientOptionsFor(o));
    }
    announcements_ =
        std::make_unique<AnnounceListener>(OpenLcmTransport(o.lcm_url, kAnnounceQueue), only_key_,
                                           [this](const HeardAnnouncement& a) { OnAnnounce(a); });
    worker_ = std::thread([this] { Work(); });
  }

  ~Impl() {
    announcements_.reset();  // its thread takes mutex_
    stop_ = true;
    wake_.notify_all();
    worker_.join();
    connects_.reset();  // waits for the connects in flight, which take mutex_
    std::vector<std::thread> threads;
    {
      std::lock_guard lock(mutex_);
      for (auto& [robot, p] : panics_) threads.push_back(std::move(p.thread));
    }
    for (std::thread& t : threads) t.join();  // each takes mutex_ to answer its waiters
    std::lock_guard lock(mutex_);
    robots_.clear();  // each RobotClient joins its ReadDaemon
  }

  TrackerFrame Poll();
  void SetWatching(bool watching) { watching_ = watching; }
  void SetOnSample(std::function<void()> f) {
    std::lock_guard lock(mutex_);
    on_sample_ = std::move(f);
  }
  void Panic(const std::string& robot, std::function<void(const std::string&)> done);

 private:
  // Keyed with --server-key, only what that key signed reaches here.
  void OnAnnounce(const HeardAnnouncement& heard) {
    const Announcement& announcement = heard.announcement;
    const TimePoint now = clock_.Now();
    std::lock_guard lock(mutex_);
    for (const RobotAnnouncement& r : announcement.robots) {
      // A robot's announcements are taken in their server's time order: one
      // no newer than the last taken is a replay (a recording, signed by the
      // trusted key, of an earlier instance or of the present one) and
      // changes nothing: neither the server id (its client would be dropped
      // as stale, over and over) nor the panic flag shown, nor silence. Only
      // a robot not heard for --robot-timeout takes any time again (a server
      // host restarted with its clock). Signed announcements only: an
      // unsigned one's time is anyone's, and one forged far ahead would
      // otherwise shut out the real server until that timeout.
      if (auto known = robots_.find(r.name); !heard.server_key.empty() && known != robots_.end()) {
        const Robot& k = known->second;
        const bool heard_lately = now - k.announced_at < FromSeconds(options_.robot_timeout_s);
        if (heard_lately && announcement.server_time <= k.announced_server_time) continue;
      }
      std::string evicted;  // the scheduler's table and robots_ hold the same names
      if (connects_->Announce(r.name, &evicted) == ConnectScheduler::Heard::kRefused) continue;
      if (!evicted.empty()) robots_.erase(evicted);
      Robot& robot = robots_[r.name];
      robot.name = r.name;
      robot.server_id = announcement.server_id;
      robot.announced_hash = r.config_hash;
      robot.driver = r.driver;
      robot.panic = r.panic;
      robot.num_clients = r.num_clients;
      robot.announced_server_time = announcement.server_time;
      robot.announced_at = now;
    }
  }

  // Worker: starts / stops state streams (blocking calls, up to the client's
  // timeout) of connected robots. Connects run on threads of their own.
  void Work() {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      if (queue_.empty()) {
        wake_.wait_for(lock, std::chrono::milliseconds(200));
        continue;
      }
      const std::string name = queue_.front();
      queue_.pop_front();
      lock.unlock();
      SetStream(name);
      lock.lock();
    }
  }

  // The scheduler's connect (on a thread of its own): throws when it fails.
  void Connect(const std::string& name, Duration connect_timeout) {
    ClientOptions co = ClientOptionsFor(options_);
    co.timeout = std::chrono::seconds(2);
    co.connect_timeout = connect_timeout;
    auto client = std::make_shared<RobotClient>(co);
    client->Connect(name);
    auto slot = std::make_shared<SampleSlot>();
    std::lock_guard lock(mutex_);
    auto it = robots_.find(name);  // always found: a name connecting is never forgotten or pushed out
    if (it == robots_.end()) throw Error("robot '" + name + "' is no longer tracked");
    Robot& r = it->second;
    r.root_query.reset();
    r.streaming = false;
    r.client = std::move(client);
    r.client_server_id = r.server_id;
    r.client_hash = r.announced_hash;
    r.slot = std::move(slot);
    r.slot_seen = 0;
    r.model = std::make_shared<const RobotModel>(r.client->model());
    r.poser = std::make_unique<StatePoser>(*r.model);
    r.message.clear();
    ++r.generation;
    nlohmann::json m = {
        {"type", "model"}, {"robot", name}, {"generation", r.generation}, {"model", ModelToJson(*r.model)}};
    r.model_message = std::make_shared<const std::string>(JsonText(m));
  }

  void ConnectFailed(const std::string& name, const std::string& error) {
    std::lock_guard lock(mutex_);
    if (auto it = robots_.find(name); it != robots_.end()) it->second.message = "cannot connect: " + error;
  }

  // Asks for the state stream while a page is open, cancels it when none is:
  // a bridge nobody looks at adds no traffic to the bus.
  void SetStream(const std::string& name) {
    std::shared_ptr<RobotClient> client;
    std::shared_ptr<SampleSlot> slot;
    std::function<void()> on_sample;
    const bool want = watching_;
    {
      std::lock_guard lock(mutex_);
      auto it = robots_.find(name);
      if (it == robots_.end()) return;
      it->second.stream_task = false;
      on_sample = on_sample_;
      client = it->second.client;
      slot = it->second.slot;
    }
    if (!client || !slot) return;
    std::string error;
    try {
      if (want) {
        client->StartStateStream(options_.period(), [slot, on_sample](const StateSample& s) {
          {
            std::lock_guard l(slot->mutex);
            slot->sample = s;
            ++slot->received;
          }
          if (on_sample) on_sample();
        });
      } else {
        client->StopStateStream();
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    std::lock_guard lock(mutex_);
    auto it = robots_.find(name);
    if (it == robots_.end() || it->second.client != client) return;
    if (error.empty())
      it->second.streaming = want;
    else
      it->second.message = std::string("state stream: ") + error;
  }

  void Housekeep(Robot& r, const ConnectScheduler::State& s, std::vector<std::shared_ptr<RobotClient>>& drop);
  static void MeasureRoot(Robot& r);
  nlohmann::json RobotJson(const Robot& r, const ConnectScheduler::State& s) const;

  const WebOptions options_;
  const std::optional<PublicKey> only_key_;  // --server-key: only its robots are tracked
  const SteadyClock clock_;
  std::atomic<bool> stop_{false};
  std::mutex mutex_;
  std::condition_variable wake_;
  std::map<std::string, Robot> robots_;  // GUARDED_BY(mutex_): the names of connects_'s table
  std::deque<std::string> queue_;        // GUARDED_BY(mutex_): state stream tasks
  std::atomic<bool> watching_{false};
  std::function<void()> on_sample_;              // GUARDED_BY(mutex_)
  std::map<std::string, PanicInFlight> panics_;  // GUARDED_BY(mutex_): at most one per robot
  // The robots announced, their connects (at most 32 at once), back-off and
  // table (at most 256); it calls Connect() and ConnectFailed().
  std::unique_ptr<ConnectScheduler> connects_;
  std::thread worker_;
  std::unique_ptr<AnnounceListener> announcements_;  // calls OnAnnounce(); started last, stopped first
};

// REQUIRES: mutex_ held. A robot not announced for robot_timeout_s is gone:
// its client is dropped; so is a stale one (the server restarted or the robot
// changed), and the scheduler tries it again.
void RobotTracker::Impl::Housekeep(Robot& r, const ConnectScheduler::State& s,
                                   std::vector<std::shared_ptr<RobotClient>>& drop) {
  const bool stale = r.client && (r.client_server_id != r.server_id || r.client_hash != r.announced_hash);
  if (r.client && (s.silent || stale)) {
    drop.push_back(std::move(r.client));
    r.client.reset();
    r.root_query.reset();
    connects_->Lost(r.name);
  }
  if (r.client && !r.stream_task && r.streaming != watching_) {
    r.stream_task = true;
    queue_.push_back(r.name);
    wake_.notify_all();
  }
}

// One LINK_POSES query for the root in flight at a time; a new one goes out
// when the previous is answered (so at most one per round trip and Poll()).
void RobotTracker::Impl::MeasureRoot(Robot& r) {
  try {
    if (r.root_query) {
      const std::optional<Reply> reply = r.root_query->Poll();
      if (!reply) return;
      r.root_query.reset();
      if (reply->values.size() == 7) {
        const auto& v = reply->values;
        Eigen::Isometry3d root = Eigen::Isometry3d::Identity();
        root.translation() << v[0], v[1], v[2];
        root.linear() = Eigen::Quaterniond(v[3], v[4], v[5], v[6]).normalized().toRotationMatrix();
        if (root.matrix().allFinite()) r.poser->SetMeasuredRoot(root);
      }
    }
    const std::string root_link = r.model->link(r.model->roots().front().link).name;
    r.root_query = r.client->SendQuery({.type = QueryType::kLinkPoses, .target = root_link});
  } catch (const std::exception& e) {  // the client gave up (timeout): try again next time
    r.root_query.reset();
    r.message = std::string("root pose query: ") + e.what();
  }
}

nlohmann::json RobotTracker::Impl::RobotJson(const Robot& r, const ConnectScheduler::State& s) const {
  nlohmann::json urdf = nullptr;
  if (auto it = options_.urdf.find(r.name); it != options_.urdf.end())
    urdf = "/urdf/" + r.name + "/" + std::filesystem::path(it->second).filename().string();
  std::string status = "live", message = r.message;
  if (!r.client && s.silent) {
    status = "gone";
    message = "not announced for " + std::to_string(static_cast<int>(options_.robot_timeout_s)) + " s";
  } else if (!r.client && s.failures > 0 && !s.connecting) {
    status = "error";  // message: why its last connect failed
  } else if (!r.client) {
    status = "connecting";
    message.clear();
  }
  return {{"name", r.name},
          {"status", status},
          {"message", message},
          {"driver", r.driver},
          {"panic", r.panic},
          {"num_clients", r.num_clients},
          {"server_id", Hex64(static_cast<std::uint64_t>(r.server_id))},
          {"generation", r.generation},
          {"urdf", urdf}};
}

std::set<std::string> ModelledRobots(const TrackerFrame& frame) {
  std::set<std::string> names;
  for (const TrackerFrame::Model& m : frame.models) names.insert(m.robot);
  return names;
}

TrackerFrame RobotTracker::Impl::Poll() {
  TrackerFrame frame;
  std::vector<std::shared_ptr<RobotClient>> drop;  // destroyed outside the lock (joins threads)
  {
    std::lock_guard lock(mutex_);
    nlohmann::json list = nlohmann::json::array();
    for (auto& [name, r] : robots_)
      if (const auto s = connects_->Find(name)) Housekeep(r, *s, drop);
    for (const std::string& name : connects_->Poll()) robots_.erase(name);  // forgotten
    for (auto& [name, r] : robots_) {
      const auto s = connects_->Find(name);
      if (!s) continue;
      list.push_back(RobotJson(r, *s));
      if (r.model_message) frame.models.push_back({name, r.generation, r.model_message, r.model});
      if (!r.client || !r.slot || !r.poser) continue;
      if (watching_ && r.poser->needs_measured_root()) MeasureRoot(r);
      std::lock_guard slot_lock(r.slot->mutex);
      if (r.slot->received == r.slot_seen) continue;
      frame.samples_received += r.slot->received - r.slot_seen;
      r.slot_seen = r.slot->received;
      try {
        nlohmann::json s = r.poser->Pose(r.slot->sample);
        s["generation"] = r.generation;
        frame.states.push_back(JsonText(s));
        frame.poses.push_back(std::move(s));
      } catch (const Error& e) {
        r.message = e.what();
      }
    }
    frame.robots = {{"type", "robots"}, {"robots", list}};
  }
  drop.clear();
  return frame;
}

void RobotTracker::Impl::Panic(const std::string& robot, std::function<void(const std::string&)> done) {
  std::vector<std::thread> ended;  // joined outside the lock
  std::string refused;
  {
    std::lock_guard lock(mutex_);
    for (auto it = panics_.begin(); it != panics_.end();) {
      if (!it->second.finished) {
        ++it;
        continue;
      }
      ended.push_back(std::move(it->second.thread));
      it = panics_.erase(it);
    }
    if (auto in_flight = panics_.find(robot); in_flight != panics_.end()) {
      if (in_flight->second.next.size() < kMaxPanicWaiters)
        in_flight->second.next.push_back(std::move(done));
      else
        refused = "a panic of robot '" + robot + "' is already being sent and " +
                  std::to_string(kMaxPanicWaiters) + " requests wait for its answer; this one is not queued";
    } else {
      std::shared_ptr<RobotClient> client;
      if (auto it = robots_.find(robot); it != robots_.end()) client = it->second.client;
      if (!client) {
        refused = "robot '" + robot + "' is not connected";
      } else {
        PanicInFlight& p = panics_[robot];
        p.sending.push_back(std::move(done));
        p.thread = std::thread([this, client, robot] {
          for (bool again = true; again;) {
            std::string error;
            try {
              client->Panic();
            } catch (const std::exception& e) {
              error = e.what();
            }
            std::vector<PanicDone> answered;
            {
              std::lock_guard l(mutex_);
              PanicInFlight& mine = panics_.at(robot);
              answered.swap(mine.sending);
              mine.sending.swap(mine.next);
              again = !mine.sending.empty();
              mine.finished = !again;
            }
            for (PanicDone& w : answered) w(error);
          }
        });
      }
    }
  }
  for (std::thread& t : ended) t.join();
  if (!refused.empty()) done(refused);
}

RobotTracker::RobotTracker(const WebOptions& options) : impl_(std::make_unique<Impl>(options)) {}
RobotTracker::~RobotTracker() = default;
void RobotTracker::SetWatching(bool watching) { impl_->SetWatching(watching); }
void RobotTracker::SetOnSample(std::function<void()> on_sample) { impl_->SetOnSample(std::move(on_sample)); }
TrackerFrame RobotTracker::Poll() { return impl_->Poll(); }
void RobotTracker::Panic(const std::string& robot, std::function<void(const std::string&)> done) {
  impl_->Panic(robot, std::move(done));
}

}  // namespace robotalk::web
