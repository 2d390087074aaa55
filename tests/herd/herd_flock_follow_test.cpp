// The shipped flock scenes walked by the calibrated pony, whose slowest walk
// (0.086 m/s) is faster than a boid's pull on it one step after it stopped:
// a flock must follow its leader for as long as the leader walks, not stand.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt::herd {
namespace {

GroupMetrics run_flock_scene(const std::string& name, std::uint64_t seed) {
  const auto no_gait = [](const std::string&) -> std::string { return ""; };
  Herd herd(load_herd_scene(std::string(ANIMRT_SOURCE_DIR) + "/configs/herd/" + name), no_gait,
            seed);
  const long steps = std::lround(herd.scene().duration_s / herd.scene().step_s);
  herd.record_metrics();
  for (long k = 1; k <= steps; ++k) {
    herd.step();
    if (k % 10 == 0) herd.record_metrics();
  }
  const HerdMetrics m = herd.metrics();
  EXPECT_EQ(m.collisions, 0) << name << " seed " << seed;
  const GroupMetrics g = m.groups.at(0);
  std::printf("%s seed %llu: speed %.4f of leader's %.4f m/s, centre to leader %.2f m (max %.2f)\n",
              name.c_str(), static_cast<unsigned long long>(seed), g.speed_mean_mps,
              g.leader_speed_mean_mps, g.leader_distance_mean_m, g.leader_distance_max_m);
  return g;
}

// The Unity-sample flock stood (0.0004 m/s against its leader's 0.11, 6.6 m
// behind): each step began from the figures' walked velocity, and figures
// knotted nose to a neighbour could not turn out of the knot. It walks at
// 60 % of its leader's speed or more, its centre within 3 m of its leader
// on every seed: the boids are carried by their leader's move, as the
// text's are children of the controller, and a figure the contact guard
// stops turns on the spot out of the way (before: 2.1-3.4 m).
// Seeds 1-5; the sanitizer build, many times slower (43 s for five), seed 1:
// every seed runs the same code.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::uint64_t kLastSeed = 1;
#else
constexpr std::uint64_t kLastSeed = 5;
#endif

TEST(HerdFlockFollow, GoalUnityFlockKeepsUpWithItsLeader) {
  for (std::uint64_t seed = 1; seed <= kLastSeed; ++seed) {
    const GroupMetrics g = run_flock_scene("unity.yaml", seed);
    EXPECT_FALSE(g.standing) << "seed " << seed;
    EXPECT_GE(g.speed_mean_mps, 0.6 * g.leader_speed_mean_mps) << "seed " << seed;
    EXPECT_LT(g.leader_distance_mean_m, 3.0) << "seed " << seed;
  }
}

}  // namespace
}  // namespace animrt::herd
