// Gait evaluation throughput: raw mj_step on each model, evaluations per
// second of the fitness (walk + measures) on 1 and 2 threads, the fitness
// overhead over raw stepping, and the thread speed-up.
//
//   build/bin/bench_evolve [evaluations per measurement, default 24]

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace animrt;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void bench_model(const char* name, int evaluations) {
  const std::string root = ANIMRT_SOURCE_DIR;
  sim::MujocoGaitSimulatorFactory factory(root + "/configs/models/" + name + ".xml");
  const GaitFile seed = load_gait_file(root + "/configs/gaits/" + name + "_seed.yaml");
  const evolve::WalkSettings walk;  // the run files' defaults

  // Raw stepping of the same motion: the seed gait's targets precomputed,
  // then only ctrl copies and mj_step are timed.
  const sim::MujocoModel& mm = factory.model();
  auto data = sim::make_mujoco_data(mm);
  std::vector<JointSpec> specs;
  for (const auto& j : mm.actuated_joints) specs.push_back({j, {-kPi, kPi, 100, 1e4}, 0.0});
  const auto source = make_gait_source(seed, specs);
  const long raw_steps = 4000;
  const auto nu = static_cast<std::size_t>(mm.model->nu);
  std::vector<double> ctrl(static_cast<std::size_t>(raw_steps) * nu);
  for (long i = 0; i < raw_steps; ++i) {
    source->sample(static_cast<double>(i) * mm.model->opt.timestep,
                   std::span<double>(&ctrl[static_cast<std::size_t>(i) * nu], nu));
  }
  sim::place_standing(mm, data.get(), ctrl.data());
  auto t0 = Clock::now();
  for (long i = 0; i < raw_steps; ++i) {
    std::copy_n(&ctrl[static_cast<std::size_t>(i) * nu], nu, data->ctrl);
    mj_step(mm.model.get(), data.get());
  }
  const double raw_rate = raw_steps / seconds_since(t0);

  std::vector<const GaitFile*> gaits(static_cast<std::size_t>(evaluations), &seed);
  std::vector<evolve::GaitMeasures> out(gaits.size());
  double rate[3] = {0, 0, 0};
  long steps_per_eval = 0;
  for (int threads : {1, 2}) {
    evolve::ThreadEvaluator evaluator(factory, threads);
    t0 = Clock::now();
    evaluator.walk_all(gaits, walk, out);
    rate[threads] = evaluations / seconds_since(t0);
    steps_per_eval = out.front().steps;
  }
  const double fitness_steps = rate[1] * static_cast<double>(steps_per_eval);
  std::printf(
      "%-10s raw mj_step %8.0f steps/s | fitness: %ld steps/eval, %6.2f evals/s (1 thread) = "
      "%8.0f steps/s, overhead %4.1f%% | 2 threads %6.2f evals/s, speed-up %.2fx\n",
      name, raw_rate, steps_per_eval, rate[1], fitness_steps,
      100.0 * (raw_rate / fitness_steps - 1.0), rate[2], rate[2] / rate[1]);
}

}  // namespace

int main(int argc, char** argv) {
  const int evaluations = argc > 1 ? std::atoi(argv[1]) : 24;
  bench_model("quadruped", evaluations);
  bench_model("horse", evaluations);
  return 0;
}
