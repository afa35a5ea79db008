#include "output_lines.h"

#include "robotalk/log_writer.h"  // WriteFully, DetachWithSignalsBlocked

#include <fcntl.h>
#include <unistd.h>

namespace robotalk::cli {

void OutputLines::State::Run() {
  std::unique_lock lock(mu);
  for (;;) {
    work.wait(lock, [&] { return stop || !queue.empty(); });
    if (queue.empty()) return;  // stopped, nothing left
    std::string text = std::move(queue.front());
    queue.pop_front();
    queued_bytes -= text.size();
    writing = true;
    lock.unlock();
    const bool ok = WriteFully(fd, text);
    lock.lock();
    writing = false;
    if (!ok) {  // its reader is gone (EPIPE) or it refused: the rest is lost too
      failed = true;
      lost += 1 + queue.size();
      queue.clear();
      queued_bytes = 0;
    }
    if (queue.empty()) idle.notify_all();
  }
}

OutputLines::OutputLines(int fd) : state_(std::make_shared<State>()) {
  state_->fd = fd;
  DetachWithSignalsBlocked([state = state_] { state->Run(); });
}

OutputLines::~OutputLines() {
  std::lock_guard lock(state_->mu);
  state_->stop = true;
  state_->work.notify_all();
}

void OutputLines::Add(std::string text) {
  State& s = *state_;
  std::lock_guard lock(s.mu);
  if (s.failed || s.queued_bytes + text.size() > kMaxQueuedBytes) {
    ++s.lost;
    return;
  }
  s.queued_bytes += text.size();
  s.queue.push_back(std::move(text));
  s.work.notify_one();
}

bool OutputLines::idle() const {
  std::lock_guard lock(state_->mu);
  return state_->queue.empty() && !state_->writing;
}

std::uint64_t OutputLines::Finish() {
  State& s = *state_;
  std::unique_lock lock(s.mu);
  s.idle.wait(lock, [&] { return s.queue.empty() && !s.writing; });
  return s.lost;
}

TtyProgress::TtyProgress() {
  if (isatty(STDERR_FILENO) != 1) return;
  if (const char* name = ttyname(STDERR_FILENO))
    fd_ = open(name, O_WRONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
}

TtyProgress::~TtyProgress() {
  if (fd_ >= 0) close(fd_);
}

void TtyProgress::Show(const std::string& text) const {
  if (fd_ < 0) return;
  const ssize_t written = write(fd_, text.data(), text.size());
  (void)written;  // what the terminal did not take is lost
}

}  // namespace robotalk::cli
