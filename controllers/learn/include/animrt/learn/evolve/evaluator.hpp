#pragma once
// Evaluating a batch of gaits: serially, on N threads (one simulator each),
// or (evolve/mpi) spread over MPI ranks. Results depend only on the gaits,
// never on how the batch was split, so every way gives the same run.

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "animrt/controllers/gait/gait_simulator.hpp"

namespace animrt::evolve {

class Evaluator {
 public:
  virtual ~Evaluator() = default;
  // out[i] = the walk of gaits[i].
  virtual void walk_all(std::span<const GaitFile* const> gaits, const WalkSettings& settings,
                        std::span<GaitMeasures> out) = 0;
  virtual int workers() const = 0;
};

// N worker threads, each with its own simulator from the factory; the batch
// is handed out one gait at a time. threads <= 1 runs on the calling thread.
class ThreadEvaluator final : public Evaluator {
 public:
  ThreadEvaluator(const GaitSimulatorFactory& factory, int threads);
  void walk_all(std::span<const GaitFile* const> gaits, const WalkSettings& settings,
                std::span<GaitMeasures> out) override;
  int workers() const override { return static_cast<int>(simulators_.size()); }

 private:
  std::vector<std::unique_ptr<GaitSimulator>> simulators_;
};

}  // namespace animrt::evolve
