#include "fault_injection.hpp"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>

namespace animrt::cli {

void start_fault_injection() {
  const char* after = std::getenv("ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S");
  if (after == nullptr) return;
  const double seconds = std::strtod(after, nullptr);
  if (!std::isfinite(seconds) || seconds < 0.0) return;
  std::thread([seconds] {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    throw std::runtime_error("injected by ANIMRT_TEST_UNCAUGHT_EXCEPTION_AFTER_S");
  }).detach();
}

}  // namespace animrt::cli
