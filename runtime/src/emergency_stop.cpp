#include "animrt/runtime/emergency_stop.hpp"

#include <signal.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <iterator>

#include "emergency_slots.hpp"
#include "futex.hpp"

namespace animrt {
namespace {

// More buses than any figure has; a bus beyond them runs without the path.
constexpr std::size_t kSlots = 64;
std::array<EmergencySlot, kSlots> g_slots;
std::atomic<std::uint32_t> g_done{0};  // bumped (and woken) by every switched-off bus
thread_local EmergencySlot* t_own_slot = nullptr;

Nanos monotonic_now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<Nanos>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Async-signal-safe output: write(2) of fixed text and small numbers.
void say(const char* text) {
  std::size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = ::write(STDERR_FILENO, text, left);
    if (n <= 0 && errno != EINTR) return;
    if (n > 0) {
      text += n;
      left -= static_cast<std::size_t>(n);
    }
  }
}

void say_number(int value) {
  char digits[12];
  int i = sizeof digits - 1;
  digits[i] = '\0';
  if (value <= 0) digits[--i] = '0';
  while (value > 0 && i > 0) {
    digits[--i] = static_cast<char>('0' + value % 10);
    value /= 10;
  }
  say(digits + i);
}

// Switches the buses off and says so, once per process (a terminate handler
// ends in abort(), whose SIGABRT comes here again).
std::atomic<bool> g_reported{false};

void torque_off_and_report(const char* why) {
  const EmergencyResult r = emergency_torque_off();
  if (r.buses == 0 || g_reported.exchange(true)) return;
  say("fatal: ");
  say(why);
  say(": torque switched off on ");
  say_number(r.switched_off);
  say(" of ");
  say_number(r.buses);
  say(r.buses == 1 ? " bus" : " buses");
  say(" before the process ends\n");
}

const char* signal_name(int sig) {
  switch (sig) {
    case SIGABRT:
      return "SIGABRT (an assertion or abort)";
    case SIGSEGV:
      return "SIGSEGV";
    case SIGBUS:
      return "SIGBUS";
    case SIGFPE:
      return "SIGFPE";
    case SIGILL:
      return "SIGILL";
    default:
      return "a fatal signal";
  }
}

constexpr int kFatalSignals[] = {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL};
// What each fatal signal did before (the default action, or a sanitizer's
// report), put back once the buses are off.
struct sigaction g_previous[std::size(kFatalSignals)];

void on_fatal_signal(int sig, siginfo_t* info, void*) {
  const int saved = errno;
  torque_off_and_report(signal_name(sig));
  // A fault (si_code > 0): the previous action again, and returning runs the
  // faulting instruction again, which meets it with its own siginfo (the
  // default's core dump, or a sanitizer's report of the real address). A
  // signal that was sent (kill, raise, abort: si_code <= 0) ends the process
  // by its default action, so its status names the signal; a sanitizer's
  // handler would report a memory error that never happened.
  const bool sent = info == nullptr || info->si_code <= 0;
  for (std::size_t i = 0; i < std::size(kFatalSignals); ++i) {
    if (kFatalSignals[i] != sig) continue;
    if (sent) {
      struct sigaction fallback {};
      fallback.sa_handler = SIG_DFL;
      sigemptyset(&fallback.sa_mask);
      sigaction(sig, &fallback, nullptr);
    } else {
      sigaction(sig, &g_previous[i], nullptr);
    }
  }
  errno = saved;
  if (sent) raise(sig);
}

std::terminate_handler g_previous_terminate = nullptr;

[[noreturn]] void on_terminate() {
  torque_off_and_report("uncaught exception");
  // The standard handler names the exception, then aborts.
  if (g_previous_terminate != nullptr) g_previous_terminate();
  std::abort();
}

}  // namespace

EmergencySlot* claim_emergency_slot() {
  for (EmergencySlot& slot : g_slots) {
    std::uint32_t free = 0;
    if (slot.claimed.compare_exchange_strong(free, 1, std::memory_order_acq_rel)) return &slot;
  }
  return nullptr;
}

void release_emergency_slot(EmergencySlot* slot) {
  if (slot == nullptr) return;
  // Reset while still claimed: a free slot is always clean for the next claim.
  slot->request.store(0, std::memory_order_relaxed);
  slot->done.store(0, std::memory_order_relaxed);
  slot->claimed.store(0, std::memory_order_release);
  // A handler waiting for this bus stops waiting: its thread is gone.
  g_done.fetch_add(1, std::memory_order_release);
  futex_wake_all(g_done);
}

void report_emergency_done(EmergencySlot& slot) {
  slot.done.store(1, std::memory_order_release);
  g_done.fetch_add(1, std::memory_order_release);
  futex_wake_all(g_done);
}

void set_thread_emergency_slot(EmergencySlot* slot) { t_own_slot = slot; }

EmergencyResult emergency_torque_off(Nanos wait) {
  const Nanos deadline = monotonic_now() + wait;
  for (EmergencySlot& slot : g_slots) {
    if (slot.claimed.load(std::memory_order_acquire) == 0) continue;
    slot.request.store(1, std::memory_order_release);
    slot.wake.fetch_add(1, std::memory_order_release);
    futex_wake_all(slot.wake);
  }
  EmergencyResult result;
  for (;;) {
    const std::uint32_t seen = g_done.load(std::memory_order_acquire);
    result = EmergencyResult{};
    bool waiting = false;
    for (EmergencySlot& slot : g_slots) {
      if (slot.claimed.load(std::memory_order_acquire) == 0) continue;
      ++result.buses;
      if (slot.done.load(std::memory_order_acquire) != 0) {
        ++result.switched_off;
      } else if (&slot != t_own_slot) {
        waiting = true;  // a thread that crashed cannot switch its own bus off
      }
    }
    if (!waiting || monotonic_now() >= deadline) return result;
    futex_wait_until(g_done, seen, deadline);
  }
}

void install_fatal_error_handlers() {
  // An alternate stack for the main thread: a stack overflow's SIGSEGV
  // cannot run its handler on the stack that overflowed.
  static char alternate_stack[1 << 16];
  stack_t ss{};
  ss.ss_sp = alternate_stack;
  ss.ss_size = sizeof alternate_stack;
  sigaltstack(&ss, nullptr);
  struct sigaction action {};
  action.sa_sigaction = on_fatal_signal;
  action.sa_flags = SA_ONSTACK | SA_SIGINFO;
  sigemptyset(&action.sa_mask);
  for (std::size_t i = 0; i < std::size(kFatalSignals); ++i) {
    sigaction(kFatalSignals[i], &action, &g_previous[i]);
  }
  g_previous_terminate = std::set_terminate(on_terminate);
}

}  // namespace animrt
