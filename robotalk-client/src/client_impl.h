// RobotClient::Impl: the state behind RobotClient, shared by the caller
// threads and the ReadDaemon thread (read_daemon.cpp).
//
// Locking: `mu_` guards everything marked GUARDED_BY(mu_); the ReturnCache
// has its own lock and is never called with `mu_` held in a way that could
// wait. Nothing is published to LCM while `mu_` is held.
#pragma once

#include "clock_sync.h"
#include "config_store.h"
#include "link_loss.h"
#include "outstanding_packages.h"
#include "return_cache.h"
#include "robotalk/channels.h"
#include "robotalk/robot_client.h"
#include "server_trust.h"

#include "robotalk/keys.h"
#include "robotalk/request.h"
#include "robotalk/session_auth.h"
#include "robotalk/transport.h"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <exception>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace robotalk {

namespace client {
/// A server's answer as a failed call's exception names it: its signal and
/// its message, the message's control characters as \xNN (EscapeControls):
/// a server's text never reaches whoever prints the exception raw.
std::string Answered(const Reply& reply);
/// The model hash a CONFIG reply's message carries (hexadecimal, 1-16
/// digits, nothing else); throws ProtocolError naming the message escaped.
std::uint64_t ParseConfigHash(const Reply& reply, const std::string& call);
}  // namespace client

/// What a package says besides its items (docs/protocol.md, Modes).
struct PackageOptions {
  bool panic = false;
  /// MODE_DIRECT for single calls and direct sequences, MODE_DELAY for delay
  /// sequences, MODE_PLAYBACK (with `playback`) for playback sequences.
  RequestMode mode = RequestMode::kDirect;
  PlaybackDeclaration playback;  ///< kPlayback: the sequence (id from NewId)
  /// kPlayback: this package also waits for the server's delay reply (id =
  /// playback.id): the client re-asks through it until that reply is in.
  bool ask_for_delay = false;
  /// A CLOCK query: the ack of a package sent once is a clock sample.
  bool clock_query = false;
  /// Nobody collects its replies: they are neither filed nor counted as
  /// ignored (the clock samples' own).
  bool replies_unwaited = false;
  /// How its timed set-points join into trajectories (request.h).
  Interpolation interpolation = Interpolation::kStep;
  /// The package's deadline (Request::max_late); nullopt: ClientOptions::max_late.
  std::optional<Duration> max_late;
  /// kPlayback: how long after its arrival the package's earliest frame is
  /// due (the server's chosen delay, 0 before the delay reply, + the frame's
  /// offset ahead of the sequence's clock). The automatic redundancy
  /// (kPlaybackCopiesAuto) compares it with the retransmission timeout.
  std::optional<Duration> playback_headroom;
};

namespace client {
struct PlannedSend;
}

/// A sequence on its way (RunSequence, SendTrajectory): the options of its
/// packages and the server time of its offset 0.
struct SequenceSend {
  CommandMode mode = CommandMode::kDelay;
  PackageOptions package;
  TimePoint server_start{};  ///< delay: from the start; playback: once the delay reply is in
  bool start_known = false;
  TimePoint t0{};                        ///< offset 0 on the client's clock (the first send)
  std::optional<Duration> chosen_delay;  ///< playback: the server's delay after the first frame arrived
};

class RobotClient::Impl {
 public:
  explicit Impl(ClientOptions options);
  ~Impl();

  struct Sent {
    std::int64_t sequence = 0;
    std::vector<CommandId> ids;
  };
  /// Builds one Request, encodes it with EncodeRequest (request.h), seals it
  /// (keyed mode), registers it for retransmission and publishes it. Assigns
  /// the ids of `commands` / `queries` (returned in order). Throws
  /// ClientError (not connected, too large, no session), ProtocolError (a
  /// start time EncodeRequest refuses); nothing is consumed when it throws.
  Sent SendPackage(std::vector<Command> commands, std::vector<robotalk::Query> queries,
                   const PackageOptions& options = {});
  /// How many copies of a playback package leave at `now`
  /// (ClientOptions::playback_copies; kPlaybackCopiesAuto: LinkLoss's rule).
  /// REQUIRES: mu_ held.
  int PlaybackCopies(TimePoint now, std::optional<Duration> headroom) const;
  /// A fresh id from the client's command-id space (for a playback sequence).
  CommandId NewId();
  /// Opens a sequence of `frames` frames whose last offset is `duration`,
  /// started at `t0` on the client's clock. Playback: declares it, and
  /// `delay_reply` waits for the server's delay reply.
  SequenceSend BeginSequence(const SequenceOptions& options, std::size_t frames, Duration duration,
                             TimePoint t0, std::optional<PendingReply>* delay_reply);
  /// Sends one planned package: the commands of `send.frames` (moved out of
  /// `frames`) with their start times; one PendingReply per frame, in order.
  std::vector<PendingReply> SendPlanned(std::vector<TimedCommand>& frames, const client::PlannedSend& send,
                                        SequenceSend& sequence);
  /// Tells the retransmission bookkeeping when items will run (server clock).
  void SetStartTimes(const std::vector<std::pair<CommandId, TimePoint>>& server_starts);
  void OnState(std::span<const std::uint8_t> bytes);
  /// Subscribes ROBOTALK/<robot>/STATE (once) and sets the sample callback.
  void SubscribeState(std::function<void(const StateSample&)> on_sample);
  /// Wakes the ReadDaemon (a new deadline, or closing). Thread-safe.
  void WakeDaemon();
  PendingReply MakePending(CommandId id, std::string what);

  /// Subscribes the robot's channels (REPLY/<client>, CONFIG).
  void Attach(const std::string& robot);
  /// The server's explicit answer to a panic package (ReplyBatch::panic).
  struct PanicAnswer {
    bool taken = false;
    std::string refusal;           ///< not taken: the server's reason
    bool session_unknown = false;  ///< not taken because the server had no such session
  };
  /// Blocks until the server has answered the panic package `sequence`;
  /// nullopt on timeout.
  std::optional<PanicAnswer> WaitPanicAnswer(std::int64_t sequence,
                                             std::chrono::steady_clock::time_point deadline);
  /// Waits until a configuration with `hash` has been received.
  std::shared_ptr<const RobotModel> WaitModel(std::uint64_t hash,
                                              std::chrono::steady_clock::time_point deadline);
  void RethrowDaemonError();
  std::string LastConfigError() const;

  const ClientOptions options_;
  SteadyClock steady_clock_;
  const Clock& clock_;  // options_.clock or steady_clock_
  std::int64_t client_id_ = 0;
  std::shared_ptr<client::ReturnCache> cache_;

  mutable std::mutex mu_;
  std::condition_variable cv_;               // panic answers, sessions, configurations
  client::OutstandingPackages outstanding_;  // GUARDED_BY(mu_)
  client::LinkLoss link_loss_;               // GUARDED_BY(mu_)
  client::ClockSync clock_sync_;             // GUARDED_BY(mu_)
  std::int64_t next_sequence_ = 1;           // GUARDED_BY(mu_)
  CommandId next_id_ = 1;                    // GUARDED_BY(mu_)
  TimePoint last_send_{};                    // GUARDED_BY(mu_)
  TimePoint last_clock_query_{};             // GUARDED_BY(mu_)
  // Ids of items whose replies nobody collects (PackageOptions::
  // replies_unwaited), newest last; bounded: a lost reply's id goes in time.
  static constexpr std::size_t kMaxUnwaitedIds = 16;
  std::deque<CommandId> unwaited_ids_;                           // GUARDED_BY(mu_)
  std::string robot_;                                            // GUARDED_BY(mu_); set once by Attach
  std::string request_channel_;                                  // GUARDED_BY(mu_)
  bool connected_ = false;                                       // GUARDED_BY(mu_)
  std::shared_ptr<const RobotModel> model_;                      // GUARDED_BY(mu_)
  client::ConfigStore configs_;                                  // GUARDED_BY(mu_)
  std::string last_config_error_;                                // GUARDED_BY(mu_)
  std::unordered_set<std::int64_t> clock_packages_;              // GUARDED_BY(mu_)
  std::unordered_map<std::int64_t, TimePoint> ack_waited_;       // GUARDED_BY(mu_): panics, when sent
  std::unordered_map<std::int64_t, PanicAnswer> panic_answers_;  // GUARDED_BY(mu_)
  std::exception_ptr daemon_error_;                              // GUARDED_BY(mu_)
  ClientStats stats_;                                            // GUARDED_BY(mu_)
  std::unique_ptr<Subscription> state_subscription_;             // GUARDED_BY(mu_)
  std::function<void(const StateSample&)> on_state_;             // GUARDED_BY(mu_)

  // The session (docs/protocol.md, Sessions): opened by a hello, named in
  // every package; lost when the server no longer knows it.
  std::int64_t session_id_ = 0;                   // GUARDED_BY(mu_); 0 = none yet
  std::int64_t server_id_ = 0;                    // GUARDED_BY(mu_); the instance that opened it
  TimePoint session_opened_at_{};                 // GUARDED_BY(mu_); its hello answered (clock_)
  std::optional<SessionKeys> session_keys_;       // GUARDED_BY(mu_); keyed mode
  std::unique_ptr<ClientHandshake> handshake_;    // GUARDED_BY(mu_); keyed: the hello in flight
  Nonce hello_nonce_{};                           // GUARDED_BY(mu_)
  bool hello_due_ = false;                        // GUARDED_BY(mu_)
  TimePoint next_hello_{};                        // GUARDED_BY(mu_)
  std::string hello_refusal_;                     // GUARDED_BY(mu_); non-empty: no session possible
  bool resync_ = false;                           // GUARDED_BY(mu_); new instance: re-sync clock, config
  std::optional<CommandId> resync_config_query_;  // GUARDED_BY(mu_)
  std::optional<std::uint64_t> resync_hash_;      // GUARDED_BY(mu_): the new instance's config
  std::optional<KeyPair> identity_;               // keyed mode; set at construction
  std::optional<client::ServerTrust> trust_;      // GUARDED_BY(mu_); keyed mode; loaded by Attach
  std::string trust_error_;                       // GUARDED_BY(mu_); the last answer of an untrusted key
  // Keyed: the newest authentic STATE sample's time, per server instance: an
  // older one (a replay inside the instance) is refused.
  std::optional<std::int64_t> last_state_us_;  // GUARDED_BY(mu_)
  Nonce last_state_instance_{};                // GUARDED_BY(mu_)

  /// Waits for a session (REQUIRES: `lock` holds mu_). Throws ClientError
  /// when the server refused the hello, TimeoutError when none answered.
  void WaitSession(std::unique_lock<std::mutex>& lock);

 private:
  void Run();  // the ReadDaemon
  void Tick(TimePoint now);
  void Publish(const std::string& channel, const std::vector<std::uint8_t>& bytes);
  void OnReplyPackage(std::span<const std::uint8_t> bytes);
  // When the message being dispatched arrived, on clock_: the transport's
  // stamp (the socket's, before this process handled it) when clock_ is the
  // steady clock; else `now`.
  TimePoint ArrivalTime(TimePoint now) const;
  void OnConfig(std::span<const std::uint8_t> bytes);
  /// Keyed mode, while a panic waits for its answer: an ANNOUNCE signed by
  /// the trusted server key that serves this robot from another instance
  /// than the session's says the session is gone (a restart), even when a
  /// flood of packages naming made-up sessions keeps the server's signed
  /// SESSION_UNKNOWN answers from reaching this client (their budget,
  /// ServerDaemonOptions::unknown_answers_per_second). The waiting panic is
  /// answered "session unknown": RobotClient::Panic says hello and sends it
  /// again in a new session. At other times ANNOUNCE is not read (nothing
  /// verified): a replayed ANNOUNCE of an older instance could otherwise
  /// end live sessions.
  void OnAnnounce(std::span<const std::uint8_t> bytes);
  /// Fails the items of a lost session (outside mu_) and wakes the
  /// ReadDaemon to say hello again.
  void FailLost(const std::vector<CommandId>& lost);
  /// Keyed mode: the bytes of a STATE or CONFIG message received on
  /// `channel` without their signature suffix when signed by the trusted
  /// server key for the live session's instance; else nullopt (counted).
  /// Open mode: the bytes without any suffix, unchecked.
  std::optional<std::span<const std::uint8_t>> Authentic(const std::string& channel,
                                                         std::span<const std::uint8_t> bytes);
  Duration IdleWait(TimePoint now);
  /// A package of this client's session with the next sequence number,
  /// sent at `now` (REQUIRES: mu_ held). The caller takes the number
  /// (++next_sequence_) once the package is encoded.
  Request NextRequest(TimePoint now) const;
  /// EncodeRequest, the size limit, and in keyed mode the MAC over the
  /// encoded bytes (MacCoveredBytes / WriteMacField) (REQUIRES: mu_ held).
  std::vector<std::uint8_t> EncodeSealed(const Request& request) const;
  void OnHelloAnswer(std::span<const std::uint8_t> bytes);
  /// The hello to publish now, or empty (REQUIRES: mu_ held).
  std::vector<std::uint8_t> DueHello(TimePoint now);
  /// The server no longer knows the session: fails every outstanding item as
  /// an unknown outcome and says hello again (REQUIRES: mu_ held); returns
  /// the ids to fail (outside the lock).
  std::vector<CommandId> LoseSession(TimePoint now);
  /// Files the answer to a waited-for panic package (REQUIRES: mu_ held);
  /// true when one was filed.
  bool NotePanicAnswer(const ReplyBatch& batch);
  /// True when a reply package belongs to the live session (REQUIRES: mu_ held).
  bool AcceptReplyPackage(const ReplyBatch& batch, std::span<const std::uint8_t> bytes, TimePoint now,
                          std::vector<CommandId>& lost);
  void LoadKeys();
  void Resync();  // after a new server instance: clock samples, configuration
  // A CLOCK round trip whose reply nobody waits for: its ack is the sample.
  void SendClockSample();
  void NoteResyncReplies(const std::vector<Reply>& replies);
  void AttachLocked(const std::string& robot);  // REQUIRES: mu_ held
  std::unique_ptr<Transport> own_transport_;
  Transport* transport_ = nullptr;
  std::vector<std::unique_ptr<Subscription>> subscriptions_;  // GUARDED_BY(mu_)
  int wake_fd_ = -1;       // eventfd: SendPackage and Close wake the ReadDaemon
  int transport_fd_ = -1;  // transport_->fileno(), read before the ReadDaemon starts
  std::mutex fault_mu_;
  std::mt19937_64 fault_rng_;  // GUARDED_BY(fault_mu_)
  std::atomic<bool> stop_{false};
  std::thread daemon_;
};

}  // namespace robotalk
