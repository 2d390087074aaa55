// Thread-parallel evaluation (see evaluator.hpp).

#include "animrt/learn/evolve/evaluator.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

namespace animrt::evolve {

ThreadEvaluator::ThreadEvaluator(const GaitSimulatorFactory& factory, int threads) {
  const int n = std::max(1, threads);
  for (int i = 0; i < n; ++i) simulators_.push_back(factory.make());
}

void ThreadEvaluator::walk_all(std::span<const GaitFile* const> gaits, const WalkSettings& settings,
                               std::span<GaitMeasures> out) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&](GaitSimulator& sim) {
    for (std::size_t i = next++; i < gaits.size(); i = next++) {
      try {
        out[i] = sim.walk(*gaits[i], settings);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
      }
    }
  };
  const std::size_t n = std::min(simulators_.size(), std::max<std::size_t>(gaits.size(), 1));
  if (n <= 1) {
    work(*simulators_.front());
  } else {
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < n; ++t) pool.emplace_back(work, std::ref(*simulators_[t]));
    work(*simulators_.front());
    for (auto& th : pool) th.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace animrt::evolve
