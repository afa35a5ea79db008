#include "interrupt.h"

#include <pthread.h>
#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <stop_token>
#include <thread>

namespace robotalk::cli {
namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_installed{false};
std::atomic<bool> g_defer{false};
// Never destroyed (as Drake's never_destroyed): the signal thread is
// detached and may still be inside notify_all() when main() returns and
// static destructors run (TSan saw exactly that race after a Ctrl-C).
std::mutex& Mu() {
  static auto* mu = new std::mutex;
  return *mu;
}
std::condition_variable& Cv() {
  static auto* cv = new std::condition_variable;
  return *cv;
}
std::stop_source& Stop() {
  static auto* source = new std::stop_source;
  return *source;
}

sigset_t Signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

void WaitForSignals() {
  const sigset_t set = Signals();
  for (;;) {
    int sig = 0;
    if (sigwait(&set, &sig) != 0) continue;
    if (g_signal.load() != 0 || !g_defer.load()) {
      // Nothing to stop yet, or the second signal: the user does not want to
      // wait. No flush: a stdout that takes nothing would hold the exit too
      // (the tools flush each line as they write it).
      std::_Exit(128 + sig);
    }
    {
      std::lock_guard lock(Mu());
      g_signal.store(sig);
    }
    Cv().notify_all();
    Stop().request_stop();
  }
}

}  // namespace

void Interrupter::Install() {
  if (g_installed.exchange(true)) return;
  Mu();  // constructed here, before the signal thread can need them
  Cv();
  Stop();
  const sigset_t set = Signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread(WaitForSignals).detach();
}

void Interrupter::Defer(bool defer) { g_defer.store(defer); }

int Interrupter::Signal() { return g_signal.load(); }

std::stop_token Interrupter::StopToken() { return Stop().get_token(); }

int Interrupter::WaitFor(Duration d) {
  std::unique_lock lock(Mu());
  Cv().wait_for(lock, d, [] { return g_signal.load() != 0; });
  return g_signal.load();
}

const char* Interrupter::Name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    default:
      return "a signal";
  }
}

}  // namespace robotalk::cli
