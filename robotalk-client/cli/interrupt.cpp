#include "interrupt.h"

#include <pthread.h>
#include <atomic>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

namespace robotalk::cli {
namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_installed{false};
std::atomic<bool> g_defer{false};
std::mutex g_mu;
std::condition_variable g_cv;

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
      // Nothing to stop yet, or the second signal: the user does not want to wait.
      std::fflush(stdout);
      std::_Exit(128 + sig);
    }
    {
      std::lock_guard lock(g_mu);
      g_signal.store(sig);
    }
    g_cv.notify_all();
  }
}

}  // namespace

void Interrupter::Install() {
  if (g_installed.exchange(true)) return;
  const sigset_t set = Signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread(WaitForSignals).detach();
}

void Interrupter::Defer(bool defer) { g_defer.store(defer); }

int Interrupter::Signal() { return g_signal.load(); }

int Interrupter::WaitFor(Duration d) {
  std::unique_lock lock(g_mu);
  g_cv.wait_for(lock, d, [] { return g_signal.load() != 0; });
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
