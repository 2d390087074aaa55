// The herd's dashboard API: the scene from above (bounds, walls, moving
// obstacles, groups, targets, every agent), a stream whose states carry
// every agent and move as the herd steps, and the token on its stop.

#include "animrt/runtime/herd_dashboard.hpp"

#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

namespace animrt {
namespace {

using nlohmann::json;
const std::string kGate = std::string(ANIMRT_SOURCE_DIR) + "/configs/herd/gate.yaml";

// gate.yaml's figures name gait files, never robot files.
std::string no_robots(const std::string& robot) {
  throw std::runtime_error("unexpected robot file " + robot);
}

json get(int port, const std::string& path) {
  httplib::Client c("127.0.0.1", port);
  auto res = c.Get(path.c_str());
  EXPECT_TRUE(res);
  if (!res) return json();
  EXPECT_EQ(res->status, 200) << path;
  return json::parse(res->body);
}

TEST(HerdDashboard, TheSceneListsEveryAgentGroupWallAndObstacle) {
  herd::Herd h(herd::load_herd_scene(kGate), no_robots);
  HerdDashboardServer server(h, HerdDashboardSetup{});
  const json info = get(server.port(), "/api/info");
  EXPECT_EQ(info["kind"], "herd");
  EXPECT_EQ(info["agents"], h.agents().size());
  const json scene = get(server.port(), "/api/herd");
  const herd::HerdScene& s = h.scene();
  EXPECT_EQ(scene["bounds"],
            json({s.bounds_m.xmin, s.bounds_m.ymin, s.bounds_m.xmax, s.bounds_m.ymax}));
  EXPECT_EQ(scene["walls"].size(), s.walls.size());
  EXPECT_EQ(scene["obstacles"].size(), s.moving_obstacles.size());
  ASSERT_EQ(scene["groups"].size(), s.groups.size());
  EXPECT_EQ(scene["groups"][0]["name"], s.groups[0].name);
  EXPECT_EQ(scene["targets"].size(), 1u);  // the crowd's
  ASSERT_EQ(scene["agents"].size(), h.agents().size());
  EXPECT_EQ(scene["agents"][0]["name"], h.agent_name(0));
}

TEST(HerdDashboard, TheStreamCarriesEveryAgentAndTheirPositionsChange) {
  herd::Herd h(herd::load_herd_scene(kGate), no_robots);
  HerdDashboardServer server(h, HerdDashboardSetup{});
  std::vector<json> states;
  std::atomic<std::size_t> received{0};
  std::thread client([&] {
    httplib::Client c("127.0.0.1", server.port());
    c.set_read_timeout(30, 0);
    std::string buffer;
    c.Get("/api/stream", [&](const char* data, std::size_t length) {
      buffer.append(data, length);
      for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
        states.push_back(json::parse(buffer.substr(6, end - 6)));
        buffer.erase(0, end + 2);
        ++received;
      }
      return true;
    });
  });
  // Step and publish until the client has seen a few states (a bound, not
  // a timing check: the stream may skip states, never reorder them).
  for (int i = 0; i < 2000 && received < 4; ++i) {
    for (int k = 0; k < 5; ++k) h.step();
    server.publish(h);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  server.stop();  // the streams end with the last state, as ended
  client.join();
  ASSERT_GE(states.size(), 3u);
  for (const json& state : states) {
    ASSERT_EQ(state["agents"].size(), h.agents().size());
    EXPECT_EQ(state["obstacles"].size(), h.scene().moving_obstacles.size());
    for (const json& a : state["agents"]) {
      EXPECT_TRUE(a["x"].is_number());
      EXPECT_TRUE(a["y"].is_number());
      EXPECT_TRUE(a["heading"].is_number());
      EXPECT_TRUE(a["group"].is_number_integer());
    }
  }
  EXPECT_EQ(states.back()["phase"], "ended");
  EXPECT_GT(states.back()["t_s"].get<double>(), states.front()["t_s"].get<double>());
  bool moved = false;
  for (std::size_t i = 0; i < h.agents().size(); ++i) {
    const json& a = states.front()["agents"][i];
    const json& b = states.back()["agents"][i];
    if (a["x"] != b["x"] || a["y"] != b["y"]) moved = true;
  }
  EXPECT_TRUE(moved);
  EXPECT_EQ(states.back()["agents"][0]["x"], h.agents()[0].position.x);
}

TEST(HerdDashboard, StopNeedsTheToken) {
  herd::Herd h(herd::load_herd_scene(kGate), no_robots);
  HerdDashboardServer server(h, HerdDashboardSetup{});
  httplib::Client c("127.0.0.1", server.port());
  auto refused = c.Post("/api/stop", "{}", "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 401);
  EXPECT_FALSE(server.stop_requested());
  auto steer = c.Post(("/api/steer?token=" + server.token()).c_str(), "{}", "application/json");
  ASSERT_TRUE(steer);
  EXPECT_EQ(steer->status, 409);
  auto stop = c.Post(("/api/stop?token=" + server.token()).c_str(), "{}", "application/json");
  ASSERT_TRUE(stop);
  EXPECT_EQ(stop->status, 200);
  EXPECT_TRUE(server.stop_requested());
}

TEST(HerdDashboard, OnlyLoopbackUnlessRemoteIsAllowed) {
  herd::Herd h(herd::load_herd_scene(kGate), no_robots);
  HerdDashboardSetup setup;
  setup.host = "0.0.0.0";
  EXPECT_THROW(HerdDashboardServer(h, setup), std::invalid_argument);
}

}  // namespace
}  // namespace animrt
