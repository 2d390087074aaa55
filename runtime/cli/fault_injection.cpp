#include "fault_injection.hpp"

#include <pthread.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

namespace animrt::cli {
namespace {

// SECONDS from the environment variable, or a negative number when absent.
double seconds_of(const char* name) {
  const char* text = std::getenv(name);
  if (text == nullptr) return -1.0;
  const double seconds = std::strtod(text, nullptr);
  return std::isfinite(seconds) && seconds >= 0.0 ? seconds : -1.0;
}

// The stalled thread waits in its signal handler until the process ends.
void stall_here(int) {
  for (;;) ::pause();
}

void stall_loop_after(double seconds) {
  struct sigaction action {};
  action.sa_handler = stall_here;
  sigemptyset(&action.sa_mask);
  sigaction(SIGRTMIN, &action, nullptr);
  const pthread_t loop = ::pthread_self();
  std::thread([seconds, loop] {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    ::pthread_kill(loop, SIGRTMIN);
  }).detach();
}

}  // namespace

void start_fault_injection() {
  if (const double seconds = seconds_of("ANIMRT_TEST_STALL_LOOP_AFTER_S"); seconds >= 0.0) {
    stall_loop_after(seconds);
  }
  if (const double seconds = seconds_of("ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S"); seconds >= 0.0) {
    std::thread([seconds] {
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
      throw std::runtime_error("injected by ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S");
    }).detach();
  }
  if (const double seconds = seconds_of("ANIMRT_TEST_BAD_WRITE_AFTER_S"); seconds >= 0.0) {
    std::thread([seconds] {
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
      // A page mapped without access, not a null pointer: the store is
      // defined to the compiler and to UBSan (which would stop a null store
      // itself), and only the MMU refuses it, as with a stray pointer.
      void* page = ::mmap(nullptr, 4096, PROT_NONE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (page == MAP_FAILED) return;
      volatile int* volatile target = static_cast<int*>(page);
      *target = 1;
    }).detach();
  }
}

void slow_exit_for_test() {
  if (const double seconds = seconds_of("ANIMRT_TEST_SLOW_EXIT_S"); seconds >= 0.0) {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  }
}

double transition_delay_for_test() {
  return std::max(0.0, seconds_of("ANIMRT_TEST_TRANSITION_DELAY_S"));
}

}  // namespace animrt::cli
