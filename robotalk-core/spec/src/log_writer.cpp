#include "robotalk/log_writer.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <pthread.h>
#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <csignal>
#include <deque>
#include <memory>
#include <mutex>
#include <new>
#include <thread>
#include <vector>

namespace robotalk {

namespace {

// A writer's state as fork() sees it. A process that forks after a LogWriter
// started (robotalk-walk-sweep's push children) has no writer thread in the
// child, and may fork while that thread holds the lock: every writer's lock is
// taken around fork() (its queue and counts consistent), and the child gets a
// writer thread of its own, its lock and condition variables new (the
// parent's waiters do not exist there), its queue empty (the parent's lines
// are the parent's to write).
struct ForkAware {
  virtual ~ForkAware() = default;
  virtual void LockForFork() = 0;
  virtual void UnlockInParent() = 0;
  virtual void RestartInChild(const std::shared_ptr<ForkAware>& self) = 0;
};

struct ForkRegistry {
  std::mutex mu;
  std::vector<std::weak_ptr<ForkAware>> writers;    // GUARDED_BY(mu)
  std::vector<std::shared_ptr<ForkAware>> forking;  // from prepare to parent/child; mu held meanwhile
};

ForkRegistry& Forks() {
  static ForkRegistry* const registry = [] {
    auto* r = new ForkRegistry;  // never destroyed: a fork may come during static destruction
    pthread_atfork(
        [] {
          ForkRegistry& f = Forks();
          f.mu.lock();
          for (const auto& weak : f.writers)
            if (auto writer = weak.lock()) f.forking.push_back(std::move(writer));
          for (const auto& writer : f.forking) writer->LockForFork();
        },
        [] {
          ForkRegistry& f = Forks();
          for (const auto& writer : f.forking) writer->UnlockInParent();
          f.forking.clear();
          f.mu.unlock();
        },
        [] {
          ForkRegistry& f = Forks();
          for (const auto& writer : f.forking) writer->RestartInChild(writer);
          f.forking.clear();
          f.mu.unlock();
        });
    return r;
  }();
  return *registry;
}

void RegisterForFork(const std::shared_ptr<ForkAware>& writer) {
  ForkRegistry& f = Forks();
  std::lock_guard lock(f.mu);
  std::erase_if(f.writers, [](const std::weak_ptr<ForkAware>& w) { return w.expired(); });
  f.writers.push_back(writer);
}

}  // namespace

struct LogWriter::State : ForkAware {
  std::string prefix;
  int fd = 2;
  std::mutex mu;
  std::condition_variable work;                         // lines queued, or stop
  std::condition_variable written;                      // a write ended
  std::deque<std::string> queue;                        // GUARDED_BY(mu): prefixed lines, "\n" ended
  std::size_t queued_bytes = 0;                         // GUARDED_BY(mu)
  std::uint64_t queued = 0;                             // GUARDED_BY(mu): lines queued or dropped so far
  std::uint64_t done = 0;                               // GUARDED_BY(mu): lines written or dropped so far
  std::uint64_t dropped = 0;                            // GUARDED_BY(mu)
  std::uint64_t dropped_unsaid = 0;                     // GUARDED_BY(mu): not yet said in a line
  bool tell_lost = false;                               // GUARDED_BY(mu): say dropped_unsaid now (Flush)
  bool writing = false;                                 // GUARDED_BY(mu)
  std::chrono::steady_clock::time_point write_began{};  // GUARDED_BY(mu)
  int writers = 0;                                      // GUARDED_BY(mu): LogWriters of this state
  bool stop = false;                                    // GUARDED_BY(mu)

  // Waits until `done()`, but at most kMaxWait, and not at all past kMaxWait
  // of the write in progress: a descriptor that takes nothing costs kMaxWait
  // once a spell. REQUIRES: `lock` holds mu.
  template <class Done>
  bool WaitFor(std::unique_lock<std::mutex>& lock, const Done& done) {
    const auto entry = std::chrono::steady_clock::now();
    while (!done()) {
      const auto now = std::chrono::steady_clock::now();
      auto until = entry + kMaxWait;
      if (writing) until = std::min(until, write_began + kMaxWait);
      if (now >= until) return false;
      written.wait_until(lock, until);
    }
    return true;
  }

  void Run() {
    std::unique_lock lock(mu);
    for (;;) {
      work.wait(lock, [&] { return stop || !queue.empty() || (tell_lost && dropped_unsaid > 0); });
      if (queue.empty() && !(tell_lost && dropped_unsaid > 0)) return;  // stop, and everything written
      tell_lost = false;
      std::string text;
      const std::uint64_t lost = dropped_unsaid;
      if (lost > 0) {
        text = prefix + std::to_string(lost) +
               " log lines lost: the log refused them, or took nothing while more than " +
               std::to_string(kMaxQueuedBytes >> 20) + " MiB waited\n";
        dropped_unsaid = 0;
      }
      std::uint64_t lines = 0;
      while (!queue.empty()) {
        text += queue.front();
        queue.pop_front();
        ++lines;
      }
      queued_bytes = 0;
      writing = true;
      write_began = std::chrono::steady_clock::now();
      lock.unlock();
      const bool failed = !WriteFully(fd, text);  // closed, EPIPE, no space: lost, the next may not be
      lock.lock();
      if (failed) dropped_unsaid += lost + lines;  // said by the next write that succeeds
      writing = false;
      done += lines;
      written.notify_all();
    }
  }

  void LockForFork() override { mu.lock(); }
  void UnlockInParent() override { mu.unlock(); }
  void RestartInChild(const std::shared_ptr<ForkAware>& self) override {
    // New, not unlocked or destroyed: the parent's threads that held or
    // waited on them do not exist here (glibc's broadcast could wait for them).
    new (&mu) std::mutex;
    new (&work) std::condition_variable;
    new (&written) std::condition_variable;
    queue.clear();
    queued_bytes = 0;
    done = queued;
    dropped_unsaid = 0;
    tell_lost = false;
    writing = false;
    if (stop) return;  // its last writer had ended: no thread to replace
    try {
      DetachWithSignalsBlocked([state = std::static_pointer_cast<State>(self)] { state->Run(); });
    } catch (...) {  // no thread to be had (a pids limit): the child's lines are lost, never its fork
      stop = true;
    }
  }
};

bool WriteFully(int fd, std::string_view text) {
  for (std::size_t at = 0; at < text.size();) {
    const ssize_t n = ::write(fd, text.data() + at, text.size() - at);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      // A non-blocking description (another process set O_NONBLOCK on the
      // stdio it shares: ssh, node) whose reader is behind: wait for it as a
      // blocking one makes this thread wait, never lose.
      pollfd out{fd, POLLOUT, 0};
      if (::poll(&out, 1, -1) >= 0 || errno == EINTR) continue;
    }
    if (n <= 0) return false;
    at += static_cast<std::size_t>(n);
  }
  return true;
}

void DetachWithSignalsBlocked(std::function<void()> run) {
  sigset_t every, before;
  sigfillset(&every);
  pthread_sigmask(SIG_BLOCK, &every, &before);
  struct Restore {  // the caller's mask back, also when the thread cannot start (it throws)
    const sigset_t& mask;
    ~Restore() { pthread_sigmask(SIG_SETMASK, &mask, nullptr); }
  } restore{before};
  std::thread(std::move(run)).detach();
}

std::vector<std::string> SplitLines(std::string_view text) {
  std::vector<std::string> lines;
  while (!text.empty()) {
    const std::size_t end = std::min(text.find('\n'), text.size());
    lines.emplace_back(text.substr(0, end));
    text.remove_prefix(std::min(end + 1, text.size()));
  }
  return lines;
}

void OpenStandardDescriptors() {
  for (int fd = 0; fd <= 2; ++fd) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    // The lowest descriptor free is fd: those below it are open by now.
    const int opened = ::open("/dev/null", O_RDWR);
    if (opened >= 0 && opened != fd) ::close(opened);  // fd was taken meanwhile (another thread)
  }
}

std::string EscapeControls(std::string_view text, bool ascii_only) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto u = static_cast<unsigned char>(text[i]);
    const bool c1 = !ascii_only && u == 0xc2 && i + 1 < text.size() &&
                    static_cast<unsigned char>(text[i + 1]) >= 0x80 &&
                    static_cast<unsigned char>(text[i + 1]) <= 0x9f;
    if (u >= 0x20 && u != 0x7f && !c1 && (!ascii_only || u < 0x80)) {
      out += text[i];
      continue;
    }
    constexpr char kHex[] = "0123456789abcdef";
    for (int k = 0; k < (c1 ? 2 : 1); ++k) {
      const auto b = static_cast<unsigned char>(text[i + static_cast<std::size_t>(k)]);
      out += "\\x";
      out += kHex[b >> 4];
      out += kHex[b & 0xf];
    }
    if (c1) ++i;
  }
  return out;
}

LogWriter::LogWriter(std::string prefix, int fd) : prefix_(prefix), state_(std::make_shared<State>()) {
  state_->prefix = std::move(prefix);
  state_->fd = fd;
  state_->writers = 1;
  // The thread blocks every signal: a descriptor whose reader went away
  // answers EPIPE, never SIGPIPE; and it takes no signal a program waits for
  // (SIGINT, SIGTERM), though it may start before the program blocks them.
  RegisterForFork(state_);  // before its thread: a fork in between restarts it in the child too
  DetachWithSignalsBlocked([state = state_] { state->Run(); });
}

LogWriter::LogWriter(std::string prefix, const LogWriter& shared)
    : prefix_(std::move(prefix)), state_(shared.state_) {
  std::lock_guard lock(state_->mu);
  ++state_->writers;
}

LogWriter& LogWriter::Stderr() {
  static LogWriter* const log = [] {
    auto* writer = new LogWriter(std::string(program_invocation_short_name) + ": ", 2);
    writer->prefix_.clear();  // the lines say who they are; the "lines lost" line names the program
    return writer;
  }();
  return *log;
}

LogWriter::~LogWriter() {
  Flush();  // what waits, and the count of lines lost, within kMaxWait of a write that hangs
  std::lock_guard lock(state_->mu);
  if (--state_->writers == 0) {
    state_->stop = true;
    state_->work.notify_all();
  }
}

bool LogWriter::Write(std::vector<std::string>& lines) {
  for (std::string& line : lines) line = EscapeControls(line);  // one line each, before the lock
  State& s = *state_;
  std::unique_lock lock(s.mu);
  for (std::string& line : lines) {
    ++s.queued;
    const std::size_t size = prefix_.size() + line.size() + 1;
    if (s.queued_bytes + size > kMaxQueuedBytes) {
      ++s.dropped;
      ++s.dropped_unsaid;
      ++s.done;
      continue;
    }
    s.queue.push_back(prefix_ + line + "\n");
    s.queued_bytes += size;
  }
  lines.clear();
  const std::uint64_t mine = s.queued;
  s.work.notify_one();
  return s.WaitFor(lock, [&] { return s.done >= mine; });
}

bool LogWriter::Write(std::string line) {
  std::vector<std::string> lines{std::move(line)};
  return Write(lines);
}

bool LogWriter::Flush() {
  State& s = *state_;
  std::unique_lock lock(s.mu);
  const std::uint64_t mine = s.queued;
  if (s.dropped_unsaid > 0) {
    s.tell_lost = true;
    s.work.notify_one();
  }
  return s.WaitFor(lock, [&] { return s.done >= mine && !s.tell_lost && !s.writing; }) &&
         s.dropped_unsaid == 0;
}

std::uint64_t LogWriter::dropped() const {
  std::lock_guard lock(state_->mu);
  return state_->dropped;
}

}  // namespace robotalk
