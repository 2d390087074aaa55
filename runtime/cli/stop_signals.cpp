#include "stop_signals.hpp"

#include <poll.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>

namespace animrt::cli {
namespace {

constexpr StopSignal kStopSignals[] = {
    {SIGINT, "SIGINT", true},    {SIGTERM, "SIGTERM", true},     {SIGHUP, "SIGHUP", true},
    {SIGQUIT, "SIGQUIT", true},  {SIGUSR1, "SIGUSR1", true},     {SIGUSR2, "SIGUSR2", true},
    {SIGALRM, "SIGALRM", true},  {SIGVTALRM, "SIGVTALRM", true}, {SIGPROF, "SIGPROF", true},
    {SIGXCPU, "SIGXCPU", false}, {SIGPIPE, "SIGPIPE", false},    {SIGXFSZ, "SIGXFSZ", false},
};

RunControls* g_controls = nullptr;
SecondSignal g_second = SecondSignal::cut_torque;
// Counted on their own: a stop that came another way (the dashboard, the end
// of --duration) is not the first signal, so one signal during its ramp does
// not drop the figure.
std::atomic<int> g_counted{0};
static_assert(std::atomic<int>::is_always_lock_free);

bool counts(int sig) {
  for (const StopSignal& s : kStopSignals) {
    if (s.number == sig) return s.counts;
  }
  return false;
}

// Whether fd is a pipe, FIFO or socket whose reader has gone (poll reports
// POLLERR on a pipe's write end without readers, POLLHUP on a closed
// socket). poll is async-signal-safe.
bool reader_gone(int fd) {
  pollfd p{fd, 0, 0};
  return ::poll(&p, 1, 0) == 1 && (p.revents & (POLLERR | POLLHUP)) != 0;
}

void on_stop_signal(int sig) {
  const int saved = errno;
  if (sig == SIGPIPE && !reader_gone(STDOUT_FILENO) && !reader_gone(STDERR_FILENO)) {
    errno = saved;
    return;
  }
  if (counts(sig) && g_counted.fetch_add(1) > 0) {
    if (g_second == SecondSignal::end_process) {
      // The default action, delivered when this handler returns (the signal
      // is held while it runs).
      struct sigaction dfl {};
      dfl.sa_handler = SIG_DFL;
      sigemptyset(&dfl.sa_mask);
      sigaction(sig, &dfl, nullptr);
      raise(sig);
    }
    g_controls->abort.store(true);
  }
  g_controls->stop.store(true);
  errno = saved;
}

}  // namespace

std::span<const StopSignal> stop_signals() { return kStopSignals; }

void install_stop_signals(RunControls& controls, SecondSignal second) {
  g_controls = &controls;
  g_second = second;
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  // Every stop signal is held while one handler runs: the count stays exact.
  for (const StopSignal& s : kStopSignals) sigaddset(&action.sa_mask, s.number);
  for (const StopSignal& s : kStopSignals) sigaction(s.number, &action, nullptr);
}

void add_counting_stop_signals(sigset_t& set) {
  for (const StopSignal& s : kStopSignals) {
    if (s.counts) sigaddset(&set, s.number);
  }
}

}  // namespace animrt::cli
