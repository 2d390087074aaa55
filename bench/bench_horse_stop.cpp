// The horse's stop from its seed walk, in lockstep on the physics: for each
// walking time from 2 s to 7 s in steps of 0.25 s, one run stopped dead (the
// ramp home at the request) and one whose walk winds down first. Prints the
// falls and when each stop ended (docs/results/horse_stop.md).
//
//   build/bin/bench_horse_stop [--stop-deadline S] [--stops N]
//
// --stop-deadline sets safety.stop_deadline_s (default the robot file's,
// 6 s): under 5.1 s the walk is granted less than its two strides and winds
// down faster. --stops N runs the first N walking times only.

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>

#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/mujoco/mujoco_physics.hpp"
#include "animrt/sim/simulated_backend.hpp"

namespace {

using namespace animrt;
const std::string kRoot = ANIMRT_SOURCE_DIR;

// The robot's motion, except that it does not wind down at a stop.
class StopsDead final : public MotionSource {
 public:
  explicit StopsDead(std::unique_ptr<MotionSource> motion) : motion_(std::move(motion)) {}
  std::span<const int> driven_joints() const override { return motion_->driven_joints(); }
  void sample(double t, std::span<double> targets) const override { motion_->sample(t, targets); }
  void sense(const Sensors& sensors) override { motion_->sense(sensors); }
  void start(const MotionClock& clock) override { motion_->start(clock); }
  void stop() override { motion_->stop(); }

 private:
  std::unique_ptr<MotionSource> motion_;
};

void replace_all(std::string& text, const std::string& from, const std::string& to) {
  for (auto at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
}

// configs/robots/horse.yaml with absolute paths, without wire-time emulation,
// with `deadline` as its stop deadline if not empty.
std::string write_horse(const std::string& deadline) {
  std::ifstream in(kRoot + "/configs/robots/horse.yaml");
  std::string robot((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  replace_all(robot, "file: ../gaits/", "file: " + kRoot + "/configs/gaits/");
  replace_all(robot, "model: ../models/horse.xml", "model: " + kRoot + "/configs/models/horse.xml");
  replace_all(robot, "wire_time: true", "wire_time: false");
  if (!deadline.empty()) {
    replace_all(robot, "  stop_ramp_s: 0.5", "  stop_ramp_s: 0.5\n  stop_deadline_s: " + deadline);
  }
  const std::string path = std::filesystem::temp_directory_path() /
                           ("bench_horse_stop_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(path) << robot;
  return path;
}

struct Stop {
  int falls = 0;
  double first_fall_s = -1.0;
  double ended_s = 0.0;  // physics time at the end of the run
  std::size_t unreached = 0;
  std::string named;  // the joints not home at torque off
};

Stop run(const std::string& file, double walk_s, bool wind_down) {
  LoadedRobot robot = load_robot(file);
  if (!wind_down) robot.motion = std::make_unique<StopsDead>(std::move(robot.motion));
  SimulatedBackend simulated(
      SimulatedBackend::Settings{kRoot + "/configs/models/horse.xml", nullptr});
  FigureOptions lockstep;
  lockstep.lockstep = true;
  Figure figure(std::move(robot), simulated, lockstep);
  RunOptions options = figure.run_options();
  options.duration_s = walk_s;
  options.raise_device_threads = nullptr;
  const RunSummary summary = figure.run(options);
  const sim::PhysicsMeasures m = simulated.mujoco_physics()->measures();
  Stop stop{m.falls, m.first_fall_s, m.simulated_s, summary.stop_warnings.size(), ""};
  for (const std::string& w : summary.stop_warnings) {
    stop.named += " " + w.substr(0, w.find(" when torque"));
  }
  return stop;
}

}  // namespace

int main(int argc, char** argv) {
  std::string deadline;
  int stops = 21;
  for (int i = 1; i < argc; i += 2) {
    // An option without its value gets the usage below.
    const std::string option = i + 1 < argc ? argv[i] : "";
    if (option == "--stop-deadline") {
      deadline = argv[i + 1];
    } else if (option == "--stops") {
      stops = std::clamp(std::atoi(argv[i + 1]), 1, 21);
    } else {
      std::fprintf(stderr, "usage: bench_horse_stop [--stop-deadline S] [--stops N]\n");
      return 1;
    }
  }
  const std::string file = write_horse(deadline);
  int dead_falls = 0, wound_falls = 0, runs = 0;
  std::printf(
      "walk_s  dead: falls first_fall_s end_s  wound down: falls first_fall_s end_s unreached\n");
  for (int i = 0; i < stops; ++i) {
    const double walk = 2.0 + 0.25 * i;
    const Stop dead = run(file, walk, false);
    const Stop wound = run(file, walk, true);
    std::printf("%5.2f  %d %6.2f %6.2f  %d %6.2f %6.2f %zu%s\n", walk, dead.falls,
                dead.first_fall_s, dead.ended_s, wound.falls, wound.first_fall_s, wound.ended_s,
                wound.unreached, wound.named.c_str());
    dead_falls += dead.falls > 0;
    wound_falls += wound.falls > 0;
    ++runs;
  }
  std::printf("fell: stopped dead %d of %d, wound down %d of %d\n", dead_falls, runs, wound_falls,
              runs);
  std::filesystem::remove(file);
  return 0;
}
