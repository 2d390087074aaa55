// The evolve run's dashboard API, against a real search of the demo
// quadruped (short walks, a small population): the snapshot has every
// generation in order and the best gait so far playing on the figure (its
// angles at the playback's time, the figure posed from them); a
// stop without the token is refused and changes nothing; a stop with it
// ends the search after the generation being evaluated, with that
// generation's best as the result; a stream client that never reads holds
// up neither the search's publishing nor the other clients.

#include "animrt/runtime/evolve_dashboard.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/core/joint.hpp"
#include "animrt/learn/evolve/evaluator.hpp"
#include "animrt/sim/mujoco/mujoco_figure.hpp"
#include "animrt/sim/mujoco/mujoco_gait_sim.hpp"
#include "support/eventually.hpp"
#include "support/files.hpp"

namespace animrt {
namespace {

using nlohmann::json;

evolve::RunConfig tiny_run(int generations) {
  evolve::RunConfig c =
      evolve::load_run_config(kSourceRoot + "/configs/evolve/quadruped_sinusoidal.yaml");
  c.search.population = 8;
  c.search.generations = generations;
  c.search.elites = 2;
  c.search.init.max_depth = 6;
  c.walk.settle_s = 0.1;
  c.walk.warmup_cycles = 1;
  c.walk.measure_cycles = 1;
  return c;
}

// The real evaluator, with a gate: the walk of generation `hold` waits
// until the test opens it (walk_all runs once per generation).
class GatedEvaluator final : public evolve::Evaluator {
 public:
  explicit GatedEvaluator(evolve::Evaluator& inner) : inner_(inner) {}
  void walk_all(std::span<const GaitFile* const> gaits, const evolve::WalkSettings& settings,
                std::span<evolve::GaitMeasures> out) override {
    std::unique_lock lock(mutex_);
    const int generation = calls_++;
    changed_.notify_all();
    changed_.wait(lock, [&] { return generation != hold_ || open_; });
    lock.unlock();
    inner_.walk_all(gaits, settings, out);
  }
  int workers() const override { return inner_.workers(); }
  void hold(int generation) {
    std::lock_guard lock(mutex_);
    hold_ = generation;
  }
  // Waits until the held generation is being evaluated.
  void wait_held() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return calls_ > hold_; });
  }
  void open() {
    std::lock_guard lock(mutex_);
    open_ = true;
    changed_.notify_all();
  }

 private:
  evolve::Evaluator& inner_;
  std::mutex mutex_;
  std::condition_variable changed_;
  int calls_ = 0;
  int hold_ = -1;
  bool open_ = false;
};

// A search of the quadruped with its dashboard.
struct EvolveRig {
  explicit EvolveRig(int generations)
      : config(tiny_run(generations)),
        factory(config.model),
        info{factory.model().actuated_joints, factory.model().hip_height_m,
             factory.model().mass_kg},
        serial(factory, 1),
        gated(serial),
        figure(config.model, info.joints, Location{config.file, 0, 0}) {
    EvolveDashboardSetup setup;
    setup.name = config.name;
    setup.generations = config.search.generations;
    setup.population = config.search.population;
    setup.joints = info.joints;
    setup.figure = &figure;
    setup.rate_hz = 50.0;
    server = std::make_unique<EvolveDashboardServer>(setup);
  }

  evolve::SearchResult search() {
    evolve::Search s(config, evolve::Grammar::load_file(config.grammar),
                     load_gait_file(config.seed_gait), info, gated);
    evolve::SearchHooks hooks;
    hooks.generation = [this](const evolve::GenerationStats& st, const evolve::Individual& best) {
      server->publish(st, best);
    };
    hooks.stop = [this] { return server->stop_requested(); };
    return s.run(hooks);
  }

  json get(const std::string& path) {
    httplib::Client c("127.0.0.1", server->port());
    auto res = c.Get(path.c_str());
    EXPECT_TRUE(res) << path;
    if (!res) return json();
    EXPECT_EQ(res->status, 200) << path;
    return json::parse(res->body);
  }
  int post(const std::string& path, const std::string& token) {
    httplib::Client c("127.0.0.1", server->port());
    httplib::Headers headers;
    if (!token.empty()) headers.emplace("Authorization", "Bearer " + token);
    auto res = c.Post(path.c_str(), headers, "{}", "application/json");
    EXPECT_TRUE(res) << path;
    return res ? res->status : -1;
  }
  // The sampler builds the frames at 50 Hz: polls until the state shows
  // `completed` generations (a bound for the wait, not a timing check).
  json state_after(int completed) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    for (;;) {
      json state = get("/api/state");
      if (state["completed"] == completed) return state;
      if (std::chrono::steady_clock::now() > give_up) {
        ADD_FAILURE() << "never " << completed
                      << " generations; last: " << state.dump().substr(0, 300);
        return state;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
  }

  evolve::RunConfig config;
  sim::MujocoGaitSimulatorFactory factory;
  evolve::ModelInfo info;
  evolve::ThreadEvaluator serial;
  GatedEvaluator gated;
  sim::MujocoFigure figure;
  std::unique_ptr<EvolveDashboardServer> server;
};

TEST(EvolveDashboard, TheSnapshotHasTheGenerationsInOrderAndTheBestGaitPlays) {
  EvolveRig rig(3);
  const json info = rig.get("/api/info");
  EXPECT_EQ(info["kind"], "evolve");
  EXPECT_EQ(info["generations"], 3);
  EXPECT_EQ(info["joints"].size(), rig.info.joints.size());
  ASSERT_TRUE(info["model"].is_object());
  const std::size_t bodies = info["model"]["bodies"].size();
  EXPECT_EQ(bodies, rig.figure.bodies().size());
  // Before the first generation: no curves, nothing to play.
  const json before = rig.get("/api/state");
  EXPECT_EQ(before["phase"], "running");
  EXPECT_EQ(before["history"].size(), 0u);
  EXPECT_TRUE(before["best"].is_null());
  EXPECT_FALSE(before.contains("bodies"));

  const evolve::SearchResult result = rig.search();
  ASSERT_FALSE(result.stopped);
  ASSERT_EQ(result.history.size(), 4u);
  const json state = rig.state_after(4);
  EXPECT_EQ(state["phase"], "running");  // the command has not finished it yet
  EXPECT_EQ(state["generation"], 3);
  EXPECT_EQ(state["completed"], 4);
  EXPECT_EQ(state["generations"], 3);
  ASSERT_EQ(state["history"].size(), 4u);
  double best_so_far = 1e300;
  int best_generation = -1;
  for (std::size_t g = 0; g < 4; ++g) {
    const json& h = state["history"][g];
    const evolve::GenerationStats& s = result.history[g];
    EXPECT_EQ(h["generation"], static_cast<int>(g));
    EXPECT_DOUBLE_EQ(h["best"].get<double>(), s.best);
    EXPECT_DOUBLE_EQ(h["average"].get<double>(), s.average);
    EXPECT_EQ(h["fell"], s.fell);
    EXPECT_EQ(h["invalid"], s.invalid);
    if (s.best < best_so_far) {
      best_so_far = s.best;
      best_generation = static_cast<int>(g);
    }
  }
  EXPECT_EQ(state["last"], state["history"][3]);
  // The best so far plays: the first generation with the lowest best.
  ASSERT_TRUE(state["best"].is_object());
  EXPECT_EQ(state["best"]["generation"], best_generation);
  EXPECT_DOUBLE_EQ(state["best"]["fitness"].get<double>(), best_so_far);
  ASSERT_TRUE(state["playback"].is_object());
  const double period = state["playback"]["period_s"].get<double>();
  EXPECT_NEAR(period, 1.0 / result.best.gait.stride_frequency(), 1e-9);
  EXPECT_GE(state["playback"]["t_s"].get<double>(), 0.0);
  EXPECT_LT(state["playback"]["t_s"].get<double>(), period);
  EXPECT_EQ(state["playback"]["angles"].size(), rig.info.joints.size());
  ASSERT_EQ(state["bodies"]["measured"].size(), bodies);
  // What plays is the best gait at the playback's time, and the figure is
  // posed from those angles; a quarter stride later, again.
  ASSERT_EQ(state["best"]["phenotype"], result.best.phenotype);
  std::vector<JointSpec> specs;
  for (const std::string& name : rig.info.joints) {
    JointSpec spec;
    spec.name = name;
    spec.limits = {-kPi, kPi, 100.0, 10000.0};
    specs.push_back(spec);
  }
  const auto gait = make_gait_source(result.best.gait, specs);
  sim::MujocoFigure figure(rig.config.model, rig.info.joints,
                           Location{});  // the sampler has its own
  std::vector<BodyPose> poses(bodies);
  const auto check_frame = [&](const json& s) {
    std::vector<double> expected(specs.size(), 0.0);
    gait->sample(s["playback"]["t_s"].get<double>(), expected);
    const auto angles = s["playback"]["angles"].get<std::vector<double>>();
    ASSERT_EQ(angles.size(), expected.size());
    for (std::size_t j = 0; j < angles.size(); ++j) EXPECT_NEAR(angles[j], expected[j], 1e-12);
    figure.pose(angles, poses);
    for (std::size_t b = 0; b < bodies; ++b) {
      for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_NEAR(s["bodies"]["measured"][b]["pos"][k].get<double>(), poses[b].pos[k], 1e-12);
      }
    }
  };
  check_frame(state);
  json later;
  EXPECT_TRUE(test::eventually([&] {
    later = rig.get("/api/state");
    return later["playback"]["t_s"] != state["playback"]["t_s"];
  }));
  check_frame(later);

  // The tail of the curves for a page that has the rest.
  const json tail = rig.get("/api/history?from=2");
  EXPECT_EQ(tail["from"], 2);
  ASSERT_EQ(tail["generations"].size(), 2u);
  EXPECT_EQ(tail["generations"][0]["generation"], 2);
  EXPECT_EQ(tail["generations"][1]["generation"], 3);
  EXPECT_EQ(rig.get("/api/history?from=9")["generations"].size(), 0u);
  httplib::Client c("127.0.0.1", rig.server->port());
  auto bad = c.Get("/api/history?from=x");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
}

TEST(EvolveDashboard, AStopWithoutTheTokenIsRefusedAndChangesNothing) {
  EvolveRig rig(2);
  rig.gated.hold(0);
  evolve::SearchResult result;
  std::thread search([&] { result = rig.search(); });
  rig.gated.wait_held();
  EXPECT_EQ(rig.post("/api/stop", ""), 401);
  EXPECT_EQ(rig.post("/api/stop", std::string(32, '0')), 401);
  EXPECT_EQ(rig.post("/api/stop?token=" + rig.server->token() + "x", ""), 401);
  // A herd's or a run's controls are none of an evolve run's.
  EXPECT_EQ(rig.post("/api/manual", rig.server->token()), 409);
  EXPECT_EQ(rig.post("/api/steer", rig.server->token()), 409);
  EXPECT_FALSE(rig.server->stop_requested());
  std::this_thread::sleep_for(std::chrono::milliseconds(50));  // frames after the refusals
  EXPECT_EQ(rig.get("/api/state")["phase"], "running");
  rig.gated.open();
  search.join();
  EXPECT_FALSE(result.stopped);
  ASSERT_EQ(result.history.size(), 3u);  // generations 0, 1 and 2
  EXPECT_EQ(rig.state_after(3)["phase"], "running");
}

TEST(EvolveDashboard, AStopWithTheTokenEndsTheRunAfterTheCurrentGeneration) {
  EvolveRig rig(6);
  rig.gated.hold(2);
  evolve::SearchResult result;
  std::thread search([&] { result = rig.search(); });
  rig.gated.wait_held();  // generation 2 is being evaluated
  EXPECT_EQ(rig.post("/api/stop", rig.server->token()), 200);
  EXPECT_TRUE(rig.server->stop_requested());
  json stopping = rig.state_after(2);
  for (int i = 0; i < 3000 && stopping["phase"] == "running"; ++i) {  // the next frame
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    stopping = rig.get("/api/state");
  }
  EXPECT_EQ(stopping["phase"], "stopping");
  EXPECT_EQ(stopping["completed"], 2);
  EXPECT_EQ(stopping["evaluating"], 2);
  rig.gated.open();
  search.join();
  // Generation 2 was finished, and the search ended there.
  EXPECT_TRUE(result.stopped);
  ASSERT_EQ(result.history.size(), 3u);
  EXPECT_EQ(result.history.back().generation, 2);
  EXPECT_TRUE(result.best.valid);
  EXPECT_DOUBLE_EQ(result.best.fitness, result.history.back().best);

  // A client on the stream gets the last state, ended and stopped.
  json last;
  std::atomic<bool> connected{false};
  std::thread client([&] {
    httplib::Client c("127.0.0.1", rig.server->port());
    c.set_read_timeout(10, 0);
    std::string buffer;
    c.Get("/api/stream", [&](const char* data, std::size_t length) {
      buffer.append(data, length);
      for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
        last = json::parse(buffer.substr(6, end - 6));
        buffer.erase(0, end + 2);
      }
      connected = true;
      return true;
    });
  });
  // Finished once the client is on the stream, however late its thread runs.
  EXPECT_TRUE(test::eventually([&] { return connected.load(); }));
  rig.server->finish(result.stopped);
  client.join();
  ASSERT_TRUE(last.is_object());
  EXPECT_EQ(last["phase"], "ended");
  EXPECT_EQ(last["stopped"], true);
  EXPECT_EQ(last["completed"], 3);
  EXPECT_TRUE(last["evaluating"].is_null());
}

TEST(EvolveDashboard, AStreamClientThatNeverReadsHoldsUpNeitherPublishingNorOthers) {
  EvolveRig rig(1);
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  const int small = 4096;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(rig.server->port()));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string request =
      "GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(rig.server->port()) +
      "\r\n\r\n";
  ASSERT_EQ(::send(fd, request.data(), request.size(), 0), static_cast<ssize_t>(request.size()));
  const evolve::SearchResult result = rig.search();  // frames pile up unread meanwhile
  // Publishing never waits for a client: a thousand generations' worth.
  evolve::GenerationStats stats = result.history.back();
  const auto t0 = std::chrono::steady_clock::now();
  for (int g = 2; g < 1002; ++g) {
    stats.generation = g;
    rig.server->publish(stats, result.best);
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_EQ(rig.state_after(1002)["history"].size(), 1002u);
  rig.server->finish(false);
  ::close(fd);
}

TEST(EvolveDashboard, OnlyLoopbackUnlessRemoteIsAllowed) {
  EvolveDashboardSetup setup;
  setup.host = "0.0.0.0";
  EXPECT_THROW(EvolveDashboardServer{setup}, std::invalid_argument);
  setup.host = "127.0.0.1";
  setup.rate_hz = 0.0;
  EXPECT_THROW(EvolveDashboardServer{setup}, std::invalid_argument);
}

}  // namespace
}  // namespace animrt
