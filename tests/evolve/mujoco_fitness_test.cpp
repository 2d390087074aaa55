// The MuJoCo fitness: models load, the seed gaits stand and walk, a falling
// phenotype gets the worst score, bad models are refused with a clear error.

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "animrt/controllers/evolve/fitness.hpp"
#include "animrt/controllers/evolve/phenotype.hpp"
#include "animrt/controllers/gait/gait_file.hpp"
#include "animrt/core/error.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"

namespace animrt::evolve {
namespace {

const std::string kRoot = ANIMRT_SOURCE_DIR;

struct ModelCase {
  const char* model;
  const char* seed;
};

class SeedGait : public ::testing::TestWithParam<ModelCase> {};

TEST_P(SeedGait, StandsAndMovesForward) {
  sim::MujocoGaitSimulatorFactory factory(kRoot + "/configs/models/" + GetParam().model);
  auto sim = factory.make();
  const GaitFile seed = load_gait_file(kRoot + "/configs/gaits/" + GetParam().seed);
  WalkSettings w;
  w.settle_s = 0.3;
  w.warmup_cycles = 1;
  w.measure_cycles = 2;
  const GaitMeasures m = sim->walk(seed, w);
  const GaitTargets t = froude_targets(seed.froude->number, seed.froude->hip_height_m);
  std::cout << GetParam().model << ": speed " << m.speed << " (target " << t.speed << "), stride "
            << m.stride_length << " (" << t.stride_length << "), duty " << m.duty_factor << " ("
            << t.duty_factor << "), energy " << m.energy_per_cycle << " J/cycle, score "
            << score(m, t, {}, sim->info().mass_kg) << "\n";
  EXPECT_FALSE(m.fell);
  EXPECT_GT(m.speed, 0.1 * t.speed);  // it walks forward
  EXPECT_GT(m.duty_factor, 0.2);
  EXPECT_LT(m.duty_factor, 1.0);  // feet leave the ground
  EXPECT_GT(m.stride_length, 0.0);
  EXPECT_GT(m.energy_per_cycle, 0.0);
  EXPECT_LT(score(m, t, {}, sim->info().mass_kg), kWorstFitness);
}

INSTANTIATE_TEST_SUITE_P(Models, SeedGait,
                         ::testing::Values(ModelCase{"quadruped.xml", "quadruped_seed.yaml"},
                                           ModelCase{"horse.xml", "horse_seed.yaml"}));

TEST(MujocoModel, BadModelsAreRefusedWithTheFileNamed) {
  const std::string bad = ::testing::TempDir() + "/animrt_bad_model.xml";
  std::ofstream(bad) << "<mujoco>\n  <worldbody>\n    <body><geom type=\"nonsense\"/></body>\n"
                        "  </worldbody>\n</mujoco>\n";
  try {
    sim::load_mujoco_model(bad);
    FAIL() << "loaded a broken model";
  } catch (const InputError& e) {
    EXPECT_EQ(e.where().file, bad);
    EXPECT_NE(std::string(e.what()).find("invalid MJCF model"), std::string::npos) << e.what();
  }
  // Valid MJCF without the conventions the evolver needs.
  std::ofstream(bad)
      << "<mujoco><worldbody><geom type=\"plane\" size=\"1 1 1\"/></worldbody></mujoco>";
  EXPECT_THROW(sim::load_mujoco_model(bad), InputError);
  EXPECT_THROW(sim::load_mujoco_model("/nonexistent/model.xml"), InputError);
}

}  // namespace
}  // namespace animrt::evolve
