// Crowd step cost: our CrowdGroup path (sync every figure into the crowd,
// plan, read the desired velocities) against a bare DetourCrowd update on
// the same navigation mesh, for 50, 200 and 1000 agents crossing a walled
// field in two teams.

#include <DetourCrowd.h>
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "animrt/controllers/herd/crowd.hpp"
#include "animrt/controllers/herd/nav_world.hpp"

using namespace animrt::herd;

namespace {

NavWorldConfig field() {
  NavWorldConfig c;
  c.bounds = {-40, -20, 40, 20};
  c.walls = {{{0, -13}, {0.5, 14}, 0.0}, {{0, 2}, {0.5, 8}, 0.0}, {{0, 15}, {0.5, 10}, 0.0}};
  return c;
}

std::vector<Agent> teams(int n) {
  std::vector<Agent> a;
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> ux(-36, -20), uy(-18, 18);
  for (int i = 0; i < n; ++i) {
    Agent g;
    g.position = {ux(rng), uy(rng)};
    g.group = i % 2;
    if (g.group == 1) g.position.x = -g.position.x;
    g.heading = g.group == 0 ? 0.0 : M_PI;
    a.push_back(g);
  }
  return a;
}

void BM_CrowdGroupStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NavWorld world(field());
  std::vector<Agent> agents = teams(n);
  Crowd crowd(world, agents);
  std::vector<int> red, blue;
  for (int i = 0; i < n; ++i)
    (agents[static_cast<std::size_t>(i)].group == 0 ? red : blue).push_back(i);
  CrowdGroup g0(crowd, agents, red, {{30, 0}, 0.15, 0.25, 1});
  CrowdGroup g1(crowd, agents, blue, {{-30, 0}, 0.15, 0.25, 2});
  std::vector<Vec2> desired(agents.size());
  double t = 0.0;
  for (auto _ : state) {
    g0.steer(t, 0.1, agents, desired);
    g1.steer(t, 0.1, agents, desired);
    for (std::size_t i = 0; i < agents.size(); ++i) {  // the figures walk exactly as asked
      agents[i].position += desired[i] * 0.1;
      agents[i].speed = norm(desired[i]);
      if (agents[i].speed > 0) agents[i].heading = std::atan2(desired[i].y, desired[i].x);
    }
    t += 0.1;
  }
}

void BM_BareDetourCrowd(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  NavWorld world(field());
  const std::vector<Agent> agents = teams(n);
  dtCrowd* crowd = dtAllocCrowd();
  crowd->init(n, 0.35f, world.navmesh());
  for (const Agent& a : agents) {
    dtCrowdAgentParams ap{};
    ap.radius = 0.35f;
    ap.height = 1.0f;
    ap.maxAcceleration = 0.3f;
    ap.maxSpeed = 0.2f;
    ap.collisionQueryRange = 12 * 0.35f;
    ap.pathOptimizationRange = 30 * 0.35f;
    ap.updateFlags = DT_CROWD_ANTICIPATE_TURNS | DT_CROWD_OBSTACLE_AVOIDANCE |
                     DT_CROWD_OPTIMIZE_VIS | DT_CROWD_OPTIMIZE_TOPO;
    const auto p = NavWorld::to_recast(a.position);
    const int idx = crowd->addAgent(p.data(), &ap);
    const auto tgt = NavWorld::to_recast(a.group == 0 ? Vec2{30, 0} : Vec2{-30, 0});
    dtPolyRef ref = 0;
    float nearest[3];
    const float ext[3] = {1, 2, 1};
    world.query()->findNearestPoly(tgt.data(), ext, &world.filter(), &ref, nearest);
    crowd->requestMoveTarget(idx, ref, nearest);
  }
  for (auto _ : state) crowd->update(0.1f, nullptr);
  dtFreeCrowd(crowd);
}

}  // namespace

BENCHMARK(BM_CrowdGroupStep)->Arg(50)->Arg(200)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BareDetourCrowd)->Arg(50)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
