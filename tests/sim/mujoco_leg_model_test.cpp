// The balance reflex's legs on the runtime (the figure's model posed at the
// joints and the IMU's attitude) against the same legs on the physics.

#include "animrt/sim/mujoco/mujoco_leg_model.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {

// The horse stepped a while from a standing pose with a hind leg lifted and
// the trunk tipped: the runtime's legs, posed from the physics' joint angles
// and its trunk's attitude, have the physics' legs, Jacobians and feet on
// the ground.
TEST(MujocoLegModel, TheRuntimesLegsAreThePhysicsLegs) {
  const std::string path = kSourceRoot + "/configs/models/horse.xml";
  const sim::MujocoModel mm = sim::load_mujoco_model(path);
  const mjModel* m = mm.model.get();
  sim::MujocoData data = sim::make_mujoco_data(mm);
  mjData* d = data.get();
  std::vector<double> stand(static_cast<std::size_t>(m->nu), 0.0);
  sim::place_standing(mm, d, stand.data());
  sim::MujocoLegModel physics(mm, d);
  for (int a = 0; a < m->nu; ++a) {
    if (mm.actuated_joints[static_cast<std::size_t>(a)] == "lh_stifle") d->ctrl[a] = -1.2;
  }
  for (int i = 0; i < 150; ++i) mj_step(m, d);
  mj_forward(m, d);  // the kinematics and contacts of the stepped joints

  sim::MujocoLegModel runtime(path, mm.actuated_joints, Location{path, 0, 0});
  std::vector<double> q(mm.actuator_qpos.size());
  for (std::size_t a = 0; a < q.size(); ++a) q[a] = d->qpos[mm.actuator_qpos[a]];
  const int root = m->jnt_qposadr[m->body_jntadr[mm.torso_body]];
  const std::array<double, 4> trunk{d->qpos[root + 3], d->qpos[root + 4], d->qpos[root + 5],
                                    d->qpos[root + 6]};
  ASSERT_GT(std::abs(trunk[1]) + std::abs(trunk[2]), 1e-3) << "the trunk should tip";
  physics.pose({}, {});
  runtime.pose(q, trunk);

  ASSERT_EQ(runtime.leg_count(), 4u);
  ASSERT_EQ(physics.leg_count(), runtime.leg_count());
  int down = 0;
  for (std::size_t leg = 0; leg < runtime.leg_count(); ++leg) {
    EXPECT_EQ(physics.where(leg).front, runtime.where(leg).front) << leg;
    EXPECT_EQ(physics.where(leg).left, runtime.where(leg).left) << leg;
    const auto pj = physics.joints(leg), rj = runtime.joints(leg);
    ASSERT_EQ(std::vector<int>(pj.begin(), pj.end()), std::vector<int>(rj.begin(), rj.end()));
    std::vector<double> pd(pj.size()), rd(rj.size());
    physics.down_per_rad(leg, pd);
    runtime.down_per_rad(leg, rd);
    for (std::size_t i = 0; i < pd.size(); ++i) EXPECT_NEAR(pd[i], rd[i], 1e-9) << leg;
    EXPECT_EQ(physics.on_ground(leg), runtime.on_ground(leg)) << leg;
    down += runtime.on_ground(leg) ? 1 : 0;
  }
  // Both answers were compared: some feet carry the figure, the lifted one does not.
  EXPECT_GE(down, 1);
  EXPECT_LE(down, 3);
}

}  // namespace
}  // namespace animrt
