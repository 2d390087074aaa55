#pragma once
// Waiting for what another thread (a simulated device, a server) has done
// rather than for a fixed time: on a loaded machine such a thread can stay
// off the CPU for longer than any short wait a test could afford.

#include <chrono>
#include <thread>

namespace animrt::test {

// True once `done()` holds; false if it still does not after `limit`.
template <class Done>
bool eventually(Done&& done, std::chrono::milliseconds limit = std::chrono::seconds(10)) {
  const auto give_up = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= give_up) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace animrt::test
