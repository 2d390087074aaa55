// The figure builder (figure.hpp): a robot and a backend that cannot go
// together are refused with one clear error before any device starts, and a
// figure built on the simulated backend runs in lockstep on its devices.

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "animrt/core/error.hpp"
#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "support/sim_rig.hpp"

namespace animrt::figure_builder_test {
namespace {

const std::string kRobots = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/";

// A backend that keeps the wall's clock (as hardware does) and counts what
// the builder asked of it.
class CountingBackend final : public FigureBackend {
 public:
  std::string name() const override { return "counting"; }
  bool keeps_run_clock() const override { return false; }
  std::vector<std::string> start(RobotConfig& config, const Clock& clock) override {
    (void)config;
    (void)clock;
    ++starts;
    return {};
  }
  int starts = 0;
};

TEST(FigureBuilder, LockstepOnABackendThatKeepsTheWallClockIsRefusedBeforeItStarts) {
  CountingBackend backend;
  FigureOptions options;
  options.lockstep = true;
  try {
    Figure figure(load_robot(kRobots + "quadruped.yaml"), backend, options);
    FAIL() << "a lockstep figure was built on a backend that keeps the wall clock";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lockstep"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("counting"), std::string::npos) << e.what();
  }
  EXPECT_EQ(backend.starts, 0);
}

TEST(FigureBuilder, PhysicsBehindANonDynamixelBusIsRefusedBeforeAnythingStarts) {
  // The CAN quadruped has the quadruped's joints, so its model would load;
  // physics drives Dynamixel servos only.
  SimulatedBackend::Settings settings;
  settings.physics_model = std::string(ANIMRT_SOURCE_DIR) + "/configs/models/quadruped.xml";
  SimulatedBackend simulated(settings);
  FigureOptions options;
  options.lockstep = true;
  const std::string robot_file = kRobots + "quadruped_can.yaml";
  try {
    Figure figure(load_robot(robot_file), simulated, options);
    FAIL() << "physics was put behind a CAN bus";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, robot_file);
    EXPECT_GT(e.where().line, 0);
    EXPECT_EQ(e.key(), "protocol");
    EXPECT_NE(e.message().find("dynamixel2"), std::string::npos) << e.what();
  }
  // Refused before the model loaded or a device started.
  EXPECT_EQ(simulated.mujoco_physics(), nullptr);
  EXPECT_TRUE(simulated.devices().empty());
}

// One lockstep run of the quadruped built on the simulated backend, with
// its telemetry in `csv`.
RunSummary lockstep_run(const std::string& csv) {
  SimulatedBackend simulated;
  FigureOptions options;
  options.lockstep = true;
  options.edit = [](RobotConfig& config) {
    config.safety.start_ramp_s = 0.5;
    config.safety.stop_ramp_s = 0.5;
  };
  Figure figure(load_robot(kRobots + "quadruped.yaml"), simulated, options);
  EXPECT_EQ(figure.config().safety.start_ramp_s, 0.5);
  // The buses were opened at the devices the backend started for them.
  EXPECT_EQ(simulated.devices().size(), figure.config().buses.size());
  for (std::size_t b = 0; b < figure.config().buses.size(); ++b) {
    EXPECT_EQ(figure.config().buses[b].port, simulated.devices()[b]->endpoint());
    // Lockstep timeouts are widened as the CLI's are.
    EXPECT_GE(figure.config().buses[b].timeout_s, kLockstepMinTimeoutS);
  }
  RunOptions run = figure.run_options();
  EXPECT_NE(run.lockstep_clock, nullptr);
  EXPECT_EQ(run.lockstep_clock, &figure.clock());
  run.duration_s = 1.0;
  run.request_realtime = false;
  run.telemetry_path = csv;
  const RunSummary summary = figure.run(run);
  // The lockstep clock moved one period per cycle after the first (at 0),
  // and no further: the devices kept it, not the wall's.
  const Nanos period = from_seconds(1.0 / figure.config().rate_hz);
  EXPECT_EQ(figure.clock().now(), static_cast<Nanos>(summary.cycles - 1) * period);
  return summary;
}

TEST(FigureBuilder, ASimulatedQuadrupedRunsInLockstepTheSameTwice) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string a = (dir / "figure_builder_a.csv").string();
  const std::string b = (dir / "figure_builder_b.csv").string();
  const RunSummary first = lockstep_run(a);
  const RunSummary second = lockstep_run(b);
  for (const RunSummary* s : {&first, &second}) {
    EXPECT_EQ(s->end_reason, EndReason::duration);
    EXPECT_EQ(s->backend, "sim");
    EXPECT_EQ(test::lockstep_problems(*s), "");
    // One second of motion at 200 Hz and the ramps around it.
    EXPECT_GE(s->cycles, 200u);
    EXPECT_EQ(s->telemetry_records, s->cycles);
  }
  EXPECT_EQ(first.cycles, second.cycles);
  EXPECT_EQ(test::first_difference(a, b), "");
}

}  // namespace
}  // namespace animrt::figure_builder_test
