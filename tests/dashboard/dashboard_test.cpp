// The dashboard's API against a lockstep run of the simulated quadruped:
// what it shows, its stream, its controls and their token, and that a
// client that never reads cannot hold up the loop.

#include "animrt/runtime/dashboard.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <httplib.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <thread>

#include "animrt/sim/mujoco/mujoco_figure.hpp"
#include "support/alloc_counter.hpp"
#include "support/sim_rig.hpp"

namespace animrt {
namespace {

using nlohmann::json;
const std::string kQuadruped = std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/quadruped.yaml";
// Plays a looping keyframe show (configs/shows/hello.yaml) over a gait.
const std::string kAnimatronic =
    std::string(ANIMRT_SOURCE_DIR) + "/configs/robots/animatronic.yaml";
constexpr auto kPatience = std::chrono::seconds(30);  // a bound for waits, not a timing check

// A run of the quadruped (or another robot) on its own thread, with a
// dashboard on a free loopback port.
class DashboardRun {
 public:
  explicit DashboardRun(double duration_s, bool steerable = true,
                        const std::function<void(test::SimRig&)>& before = {},
                        const std::string& robot_file = kQuadruped,
                        const test::RigSettings& settings = {})
      : rig_(robot_file, settings) {
    if (before) before(rig_);
    monitor_ = std::make_unique<RunMonitor>(rig_.runner().model());
    DashboardSetup setup;
    setup.robot = rig_.config().name;
    setup.backend = "sim";
    for (const auto& bus : rig_.config().buses) setup.bus_protocols.push_back(bus.protocol);
    setup.motion_kind = rig_.config().motion.type;
    setup.motion_name = "walk";
    if (steerable) setup.steering = rig_.robot.steering;
    const ShowPosition show = rig_.probe->show_position(0.0);
    setup.show = show.show;
    setup.show_duration_s = show.duration_s;
    setup.duration_s = duration_s;
    std::vector<std::string> names;
    for (const auto& joint : rig_.config().joints) names.push_back(joint.name);
    if (!rig_.config().model.empty()) {
      figure_ = std::make_unique<sim::MujocoFigure>(rig_.config().model, names,
                                                    rig_.config().model_where);
      setup.figure = figure_.get();
    }
    server_ = std::make_unique<DashboardServer>(*monitor_, controls_, setup);
    RunOptions options = rig_.options(duration_s);
    options.controls = &controls_;
    options.monitor = monitor_.get();
    thread_ = std::thread([this, options] {
      summary_ = rig_.run(options);
      done_ = true;
    });
  }
  ~DashboardRun() {
    controls_.stop = true;
    if (thread_.joinable()) thread_.join();
    server_->stop();
  }

  httplib::Client client() const {
    httplib::Client c("127.0.0.1", server_->port());
    c.set_read_timeout(10, 0);
    return c;
  }
  json get(const std::string& path) const {
    auto res = client().Get(path.c_str());
    EXPECT_TRUE(res);
    if (!res) return json();
    EXPECT_EQ(res->status, 200) << path;
    return json::parse(res->body);
  }
  // POST with the token (as a bearer header), or with `token` when given.
  int post(const std::string& path, const json& body,
           const std::optional<std::string>& token = std::nullopt, json* answer = nullptr) const {
    httplib::Headers headers;
    if (!token) headers.emplace("Authorization", "Bearer " + server_->token());
    std::string target = path;
    if (token && !token->empty()) target += "?token=" + *token;
    auto res = client().Post(target.c_str(), headers, body.dump(), "application/json");
    EXPECT_TRUE(res);
    if (!res) return -1;
    if (answer) *answer = json::parse(res->body, nullptr, false);
    return res->status;
  }
  // POSTs `body` as it is (with the token); the status, and the answer's error.
  int post_raw(const std::string& path, const std::string& body, std::string* error) const {
    httplib::Headers headers{{"Authorization", "Bearer " + server_->token()}};
    auto res = client().Post(path.c_str(), headers, body, "application/json");
    EXPECT_TRUE(res);
    if (!res) return -1;
    const json answer = json::parse(res->body, nullptr, false);
    if (error && answer.is_object() && answer.contains("error")) *error = answer["error"];
    return res->status;
  }
  // Polls /api/state until `pred` holds (or fails the test after kPatience).
  json wait_state(const std::function<bool(const json&)>& pred) const {
    const auto give_up = std::chrono::steady_clock::now() + kPatience;
    for (;;) {
      json state = get("/api/state");
      if (pred(state)) return state;
      if (std::chrono::steady_clock::now() > give_up) {
        ADD_FAILURE() << "state never reached; last: " << state.dump().substr(0, 400);
        return state;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  const RunSummary& finish() {
    thread_.join();
    return summary_;
  }

  test::SimRig rig_;
  std::unique_ptr<sim::MujocoFigure> figure_;
  RunControls controls_;
  std::unique_ptr<RunMonitor> monitor_;
  std::unique_ptr<DashboardServer> server_;
  std::thread thread_;
  RunSummary summary_;
  std::atomic<bool> done_{false};
};

bool in_motion(const json& s) { return s["phase"] == "motion"; }

TEST(Dashboard, InfoAndStateShowEveryJointAndDevice) {
  DashboardRun run(0.0);
  const json info = run.get("/api/info");
  const RobotConfig& config = run.rig_.config();
  ASSERT_EQ(info["joints"].size(), config.joints.size());
  for (std::size_t j = 0; j < config.joints.size(); ++j) {
    EXPECT_EQ(info["joints"][j]["name"], config.joints[j].name);
    EXPECT_DOUBLE_EQ(info["joints"][j]["max"].get<double>(), config.joints[j].limits.max_position);
  }
  ASSERT_EQ(info["buses"].size(), 1u);
  EXPECT_EQ(info["buses"][0]["protocol"], "dynamixel2");
  EXPECT_EQ(info["buses"][0]["devices"].size(), 12u);
  EXPECT_TRUE(info["motion"]["steerable"].get<bool>());
  const json& bodies = info["model"]["bodies"];
  ASSERT_EQ(bodies.size(), run.figure_->bodies().size());
  EXPECT_EQ(bodies[0]["name"], "torso");
  EXPECT_EQ(bodies[0]["parent"], -1);
  EXPECT_EQ(bodies[0]["geoms"][0]["type"], "box");
  // No IMU: an empty IMU section and no tilt watch.
  ASSERT_TRUE(info.contains("imus") && info.contains("tilt_limit_deg")) << info.dump();
  EXPECT_TRUE(info["imus"].is_array() && info["imus"].empty());
  EXPECT_TRUE(info["tilt_limit_deg"].is_null());

  const json state = run.wait_state(
      [](const json& s) { return in_motion(s) && s["loop"]["cycles"].get<std::uint64_t>() > 100; });
  ASSERT_EQ(state["joints"].size(), config.joints.size());
  for (std::size_t j = 0; j < config.joints.size(); ++j) {
    EXPECT_EQ(state["joints"][j]["name"], config.joints[j].name);
    EXPECT_TRUE(state["joints"][j]["cmd"].is_number());
    EXPECT_TRUE(state["joints"][j]["meas"].is_number());
  }
  ASSERT_EQ(state["devices"].size(), 12u);
  for (std::size_t d = 0; d < 12; ++d) {
    EXPECT_EQ(state["devices"][d]["id"], static_cast<int>(d + 1));
    EXPECT_EQ(state["devices"][d]["health"], "ok");
    EXPECT_GT(state["devices"][d]["transactions"].get<std::uint64_t>(), 0u);
  }
  EXPECT_EQ(state["loop"]["late"]["legs"], 0);
  ASSERT_TRUE(state.contains("imus")) << state.dump().substr(0, 400);
  EXPECT_TRUE(state["imus"].is_array() && state["imus"].empty());
  EXPECT_EQ(state["bodies"]["measured"].size(), bodies.size());
  EXPECT_EQ(state["bodies"]["commanded"].size(), bodies.size());
  // Lockstep: every period is exactly the loop's.
  EXPECT_NEAR(state["loop"]["period_ms"]["p50"].get<double>(), 5.0, 0.001);
  EXPECT_NEAR(state["loop"]["rate_hz"].get<double>(), 200.0, 0.1);
  std::uint64_t histogram = 0;
  for (const json& c : state["loop"]["jitter_hist"]["counts"]) histogram += c.get<std::uint64_t>();
  EXPECT_GT(histogram, 100u);
}

// A trunk IMU pushed into a 0.3 rad roll (no physics: the simulated part
// reports the scripted attitude).
test::RigSettings with_pushed_imu() {
  test::RigSettings settings;
  settings.edit = [](RobotConfig& c) {
    ImuConfig imu;
    imu.name = "trunk";
    imu.protocol = "bno08x_rvc";
    imu.stale_timeout_s = 0.5;
    imu.sim_push = ImuConfig::Push{true, false, 0.1, 2.0, 0.3};
    c.imus.push_back(imu);
    c.safety.tilt_limit_rad = 1.0;  // not reached
  };
  return settings;
}

TEST(Dashboard, TheImuSectionShowsItsAttitudeRatesAndCounts) {
  DashboardRun run(0.0, true, {}, kQuadruped, with_pushed_imu());
  const json info = run.get("/api/info");
  ASSERT_TRUE(info.contains("imus") && info.contains("tilt_limit_deg")) << info.dump();
  ASSERT_EQ(info["imus"].size(), 1u);
  EXPECT_EQ(info["imus"][0]["name"], "trunk");
  EXPECT_DOUBLE_EQ(info["imus"][0]["rate_hz"].get<double>(), 100.0);
  EXPECT_NEAR(info["tilt_limit_deg"].get<double>(), 57.2958, 1e-3);

  const json state = run.wait_state([](const json& s) {
    if (!s.contains("imus") || s["imus"].size() != 1) return false;
    const json& imu = s["imus"][0];
    return in_motion(s) && imu["roll_deg"].is_number() && imu["roll_deg"].get<double>() > 17.0;
  });
  const json& imu = state["imus"][0];
  EXPECT_EQ(imu["name"], "trunk");
  EXPECT_NEAR(imu["roll_deg"].get<double>(), 17.19, 0.2);  // 0.3 rad
  EXPECT_NEAR(imu["pitch_deg"].get<double>(), 0.0, 0.2);
  EXPECT_NEAR(imu["yaw_deg"].get<double>(), 0.0, 0.2);
  ASSERT_EQ(imu["rate_dps"].size(), 3u);
  EXPECT_TRUE(imu["age_s"].is_number());
  EXPECT_NE(imu["health"], "waiting");
  EXPECT_NE(imu["health"], "stale");
  EXPECT_TRUE(imu["late_cycles"].is_number_unsigned());
  EXPECT_TRUE(imu["missing_reports"].is_number_unsigned());
}

TEST(Dashboard, TheStreamDeliversStatesWithIncreasingTimes) {
  DashboardRun run(0.0);
  std::string buffer;
  std::vector<double> times;
  auto res = run.client().Get("/api/stream", [&](const char* data, std::size_t length) {
    buffer.append(data, length);
    for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
      const std::string event = buffer.substr(0, end);
      buffer.erase(0, end + 2);
      EXPECT_EQ(event.rfind("data: ", 0), 0u);
      const json state = json::parse(event.substr(6));
      if (state["phase"] != "configure") times.push_back(state["t_s"].get<double>());
    }
    return times.size() < 6;
  });
  ASSERT_GE(times.size(), 6u);
  for (std::size_t i = 1; i < times.size(); ++i) EXPECT_GE(times[i], times[i - 1]);
  EXPECT_GT(times.back(), times.front());
}

TEST(Dashboard, TheStreamEndsCompleteWithTheRunsLastState) {
  DashboardRun run(0.5);
  std::string buffer, last;
  std::atomic<bool> connected{false};
  httplib::Result result{nullptr, httplib::Error::Unknown};
  std::thread client([&] {
    result = run.client().Get("/api/stream", [&](const char* data, std::size_t length) {
      connected = true;
      buffer.append(data, length);
      for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
        last = buffer.substr(6, end - 6);
        buffer.erase(0, end + 2);
      }
      return true;
    });
  });
  while (!connected) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_EQ(run.finish().end_reason, EndReason::duration);
  run.server_->stop();  // as the CLI does when the run has ended
  client.join();
  ASSERT_TRUE(result) << httplib::to_string(result.error());  // the last chunk arrived
  EXPECT_TRUE(buffer.empty());
  EXPECT_EQ(json::parse(last)["phase"], "ended");
}

TEST(Dashboard, AFaultReachesTheFaultLogWithItsTimeAndItsDevice) {
  DashboardRun run(0.0, true, [](test::SimRig& rig) {
    rig.probe->on_sample = [&rig](double t) {
      if (t >= 0.5) rig.sims[0]->set_device_hardware_error(9, 0x04);  // lh_ankle overheating
    };
  });
  const json state = run.wait_state([](const json& s) { return s["phase"] == "ended"; });
  EXPECT_EQ(run.finish().end_reason, EndReason::fault);
  ASSERT_EQ(state["faults"].size(), 1u);
  const json& fault = state["faults"][0];
  EXPECT_EQ(fault["text"], "legs id 9 (lh_ankle): hardware error");
  // Motion time 0.5 s is run time 2.5 s (after the 2 s start ramp); the
  // error is read within a cycle or two.
  EXPECT_GE(fault["t_s"].get<double>(), 2.5);
  EXPECT_LE(fault["t_s"].get<double>(), 2.52);
  for (const json& d : state["devices"]) {
    EXPECT_EQ(d["faulted"].get<bool>(), d["id"] == 9) << d["id"];
    EXPECT_EQ(d["last_fault"], d["id"] == 9 ? fault["text"] : json(nullptr)) << d["id"];
  }
}

TEST(Dashboard, AControlWithoutTheTokenIsRefusedAndChangesNothing) {
  DashboardRun run(0.0);
  run.wait_state(in_motion);
  const std::string wrong(run.server_->token().size(), '0');
  EXPECT_EQ(run.post("/api/stop", json::object(), std::string()), 401);  // no token at all
  EXPECT_EQ(run.post("/api/stop", json::object(), wrong), 401);
  EXPECT_EQ(run.post("/api/manual", {{"on", true}}, wrong), 401);
  EXPECT_EQ(run.post("/api/steer", {{"speed_mps", 0.1}, {"turn_rps", 0.0}}, wrong), 401);
  EXPECT_FALSE(run.controls_.stop.load());
  EXPECT_FALSE(run.controls_.manual.load());
  const auto cycles = run.get("/api/state")["loop"]["cycles"].get<std::uint64_t>();
  const json later = run.wait_state(
      [&](const json& s) { return s["loop"]["cycles"].get<std::uint64_t>() > cycles + 200; });
  EXPECT_EQ(later["phase"], "motion");
  EXPECT_FALSE(later["manual"]["on"].get<bool>());
  EXPECT_FALSE(run.done_.load());
  // The token as a query parameter works as the header does.
  EXPECT_EQ(run.post("/api/stop", json::object(), run.server_->token()), 200);
  EXPECT_EQ(run.finish().end_reason, EndReason::signal);
}

// A control's body that is no one JSON object is refused saying what is
// wrong: a key given twice (it was taken as its last value), the parser's
// own words (a number past a double's range and a lone surrogate were both
// "expected a JSON object"), an array. Nothing changes.
TEST(Dashboard, ABodyThatIsNoOneObjectIsRefusedSayingWhy) {
  DashboardRun run(0.0);
  run.wait_state(in_motion);
  std::string error;
  EXPECT_EQ(run.post_raw("/api/manual", R"({"on": true, "on": false})", &error), 400);
  EXPECT_EQ(error, "the key \"on\" is given twice");
  EXPECT_EQ(run.post_raw("/api/manual", R"({"on": {"a": 1, "a": 2}})", &error), 400);
  EXPECT_EQ(error, "the key \"a\" is given twice");
  EXPECT_EQ(run.post_raw("/api/manual", R"({"a": {"on": 1}, "on": true})", &error), 200);
  EXPECT_EQ(run.post_raw("/api/manual", R"({"on": false})", &error), 200);
  EXPECT_EQ(run.post_raw("/api/steer", R"({"speed_mps": 1e999})", &error), 400);
  EXPECT_EQ(error.rfind("the body is no JSON: ", 0), 0u) << error;
  EXPECT_NE(error.find("1e999"), std::string::npos) << error;
  EXPECT_EQ(run.post_raw("/api/steer", R"({"joint": "\ud800"})", &error), 400);
  EXPECT_NE(error.find("surrogate"), std::string::npos) << error;
  EXPECT_EQ(run.post_raw("/api/stop", "[1]", &error), 400);
  EXPECT_EQ(error, "expected a JSON object as the body");
  EXPECT_FALSE(run.controls_.stop.load());
  EXPECT_EQ(run.post("/api/stop", json::object()), 200);
  EXPECT_EQ(run.finish().end_reason, EndReason::signal);
}

TEST(Dashboard, StopWithTheTokenEndsTheRunThroughTheRampAtHome) {
  DashboardRun run(0.0);
  run.wait_state(in_motion);
  EXPECT_EQ(run.post("/api/stop", json::object()), 200);
  const json ramp = run.wait_state([](const json& s) { return s["phase"] != "motion"; });
  EXPECT_TRUE(ramp["phase"] == "stop_ramp" || ramp["phase"] == "ended");
  const RunSummary& summary = run.finish();
  EXPECT_EQ(summary.end_reason, EndReason::signal);
  EXPECT_TRUE(summary.torque_cut.empty());
  EXPECT_TRUE(summary.faults.empty());
  run.server_->stop();  // the monitor has one reader
  RunView view;
  run.monitor_->read(view);
  EXPECT_EQ(view.phase, RunPhaseView::ended);
  const RobotModel& model = run.rig_.runner().model();
  for (std::size_t j = 0; j < model.joint_count(); ++j) {
    EXPECT_NEAR(view.cmd[j], model.home[j], 1e-3) << model.joint_names[j];
    EXPECT_NEAR(view.meas[j], model.home[j], 0.02) << model.joint_names[j];
  }
}

TEST(Dashboard, AJogCannotPushAJointPastItsLimit) {
  DashboardRun run(0.0);
  run.wait_state(in_motion);
  const RobotModel& model = run.rig_.runner().model();
  const double limit = model.limits[0].max_position;  // lf_hip
  // Outside manual mode a jog is refused.
  EXPECT_EQ(run.post("/api/jog", {{"joint", "lf_hip"}, {"position", 0.1}}), 409);
  EXPECT_EQ(run.post("/api/jog", {{"joint", "no_such_joint"}, {"position", 0.1}}), 400);
  EXPECT_EQ(run.post("/api/manual", {{"on", true}}), 200);
  json answer;
  EXPECT_EQ(run.post("/api/jog", {{"joint", "lf_hip"}, {"position", 3.0}}, std::nullopt, &answer),
            200);
  EXPECT_DOUBLE_EQ(answer["position"].get<double>(), limit);
  const json held = run.wait_state([&](const json& s) {
    return s["manual"]["on"].get<bool>() &&
           std::abs(s["joints"][0]["cmd"].get<double>() - limit) < 1e-6;
  });
  EXPECT_EQ(held["manual"]["positions"]["lf_hip"].get<double>(), limit);
  EXPECT_FALSE(held["motion"]["playing"].get<bool>());
  // It stays there, never beyond.
  const auto cycles = held["loop"]["cycles"].get<std::uint64_t>();
  const json later = run.wait_state(
      [&](const json& s) { return s["loop"]["cycles"].get<std::uint64_t>() > cycles + 100; });
  EXPECT_LE(later["joints"][0]["cmd"].get<double>(), limit);
  EXPECT_NEAR(later["joints"][0]["meas"].get<double>(), limit, 0.02);
  // Back to the motion.
  EXPECT_EQ(run.post("/api/manual", {{"on", false}}), 200);
  run.wait_state([](const json& s) { return s["motion"]["playing"].get<bool>(); });
  EXPECT_EQ(run.post("/api/stop", json::object()), 200);
  const RunSummary& summary = run.finish();
  EXPECT_EQ(summary.end_reason, EndReason::signal);
  EXPECT_TRUE(summary.faults.empty());
}

TEST(Dashboard, SteeringReachesASteerableGaitAndIsRefusedOtherwise) {
  {
    DashboardRun run(0.0);
    run.wait_state(in_motion);
    const json range = run.get("/api/info")["motion"];
    const double top = range["speed_mps"][1].get<double>();
    const double leftmost = range["turn_rps"][0].get<double>();
    ASSERT_GT(top, 0.0);
    ASSERT_LT(leftmost, 0.0);
    EXPECT_EQ(run.post("/api/steer", {{"speed_mps", 0.1}}), 400);
    EXPECT_EQ(run.post("/api/steer", {{"speed_mps", top / 2}, {"turn_rps", leftmost / 2}}), 200);
    const json steered =
        run.wait_state([](const json& s) { return !s["motion"]["speed_mps"].is_null(); });
    EXPECT_DOUBLE_EQ(steered["motion"]["speed_mps"].get<double>(), top / 2);
    EXPECT_DOUBLE_EQ(steered["motion"]["turn_rps"].get<double>(), leftmost / 2);
    // Beyond the range /api/info gives, held to its ends: the answer and
    // the state say what the figure is asked (1e308 was shown as asked).
    json answer;
    EXPECT_EQ(
        run.post("/api/steer", {{"speed_mps", 1e308}, {"turn_rps", -1e308}}, std::nullopt, &answer),
        200);
    EXPECT_EQ(answer["speed_mps"].get<double>(), top);
    EXPECT_EQ(answer["turn_rps"].get<double>(), leftmost);
    run.wait_state([&](const json& s) {
      return s["motion"]["speed_mps"].get<double>() == top &&
             s["motion"]["turn_rps"].get<double>() == leftmost;
    });
    EXPECT_EQ(
        run.post("/api/steer", {{"speed_mps", -1.0}, {"turn_rps", 0.0}}, std::nullopt, &answer),
        200);
    EXPECT_EQ(answer["speed_mps"].get<double>(), 0.0);
  }
  DashboardRun run(0.0, /*steerable=*/false);
  run.wait_state(in_motion);
  EXPECT_EQ(run.post("/api/steer", {{"speed_mps", 0.1}, {"turn_rps", 0.0}}), 409);
}

// A client that asks for the stream and never reads: the loop runs its
// cycles as it would without it (lockstep: the count is fixed by the
// duration and the ramps), the other clients are still served, and the
// reader keeps up with every cycle's timing.
TEST(Dashboard, ShowControlsPauseSeekAndPlayTheShowWithTheToken) {
  DashboardRun run(0.0, false, {}, kAnimatronic);
  const json info = run.get("/api/info");
  EXPECT_TRUE(info["motion"]["show"].get<bool>());
  EXPECT_EQ(info["motion"]["kind"], "layers");
  json state = run.wait_state(in_motion);
  EXPECT_EQ(state["motion"]["duration_s"], 6.0);  // hello.yaml's
  EXPECT_TRUE(state["motion"]["playing"].get<bool>());

  // Without the token: refused, and the show plays on.
  EXPECT_EQ(run.post("/api/show", {{"action", "pause"}}, std::string("")), 401);
  EXPECT_EQ(run.post("/api/show", {{"action", "pause"}}, std::string("0123")), 401);
  EXPECT_EQ(run.post("/api/show", {{"action", "seek"}}), 400);  // no t_s
  EXPECT_EQ(run.post("/api/show", {{"action", "rewind"}}), 400);
  state = run.get("/api/state");
  EXPECT_TRUE(state["motion"]["playing"].get<bool>());

  // Pause, then seek: the show holds at the new time.
  EXPECT_EQ(run.post("/api/show", {{"action", "pause"}}), 200);
  json answer;
  ASSERT_EQ(run.post("/api/show", {{"action", "seek"}, {"t_s", 2.5}}, std::nullopt, &answer), 200);
  EXPECT_EQ(answer["t_s"], 2.5);
  state = run.wait_state([](const json& s) {
    return !s["motion"]["playing"].get<bool>() && s["motion"]["position_s"] == 2.5;
  });
  const std::uint64_t cycles = state["loop"]["cycles"].get<std::uint64_t>();
  state = run.wait_state(
      [&](const json& s) { return s["loop"]["cycles"].get<std::uint64_t>() > cycles + 20; });
  EXPECT_EQ(state["motion"]["position_s"], 2.5);
  EXPECT_FALSE(state["motion"]["playing"].get<bool>());

  // Play: the show's time advances again from there.
  EXPECT_EQ(run.post("/api/show", {{"action", "play"}}), 200);
  state = run.wait_state([](const json& s) {
    return s["motion"]["playing"].get<bool>() && s["motion"]["position_s"].get<double>() > 2.5;
  });
  EXPECT_EQ(state["phase"], "motion");
}

TEST(Dashboard, ShowControlsAreRefusedForAMotionThatIsNotAShow) {
  DashboardRun run(0.0);
  EXPECT_FALSE(run.get("/api/info")["motion"]["show"].get<bool>());
  const json state = run.wait_state(in_motion);
  EXPECT_TRUE(state["motion"]["duration_s"].is_null());
  EXPECT_EQ(run.post("/api/show", {{"action", "pause"}}), 409);
  EXPECT_EQ(run.post("/api/show", {{"action", "seek"}, {"t_s", 1.0}}), 409);
}

TEST(Dashboard, AStreamClientThatNeverReadsDoesNotHoldUpTheLoop) {
  std::uint64_t alone = 0;
  {
    test::SimRig rig(kQuadruped);
    alone = rig.run(2.0).cycles;
  }
  DashboardRun run(2.0);
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  const int small = 4096;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof small);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(run.server_->port()));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const std::string request =
      "GET /api/stream HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(run.server_->port()) +
      "\r\n\r\n";
  ASSERT_EQ(::send(fd, request.data(), request.size(), 0), static_cast<ssize_t>(request.size()));
  // Others are served meanwhile, with fresh states.
  const double t0 = run.get("/api/state")["t_s"].get<double>();
  run.wait_state([&](const json& s) { return s["t_s"].get<double>() > t0; });
  const RunSummary& summary = run.finish();
  ::close(fd);
  EXPECT_EQ(summary.end_reason, EndReason::duration);
  EXPECT_EQ(summary.cycles, alone);
  EXPECT_EQ(summary.overruns, 0u);
  EXPECT_EQ(summary.buses[0].late_cycles, 0u);
  EXPECT_EQ(run.monitor_->timing_dropped(), 0u);
}

// Resident memory of this process, in KiB.
long resident_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

// A body far larger than any control takes (a stop's is empty, a cue's a
// name) is not read into memory, with or without a length: the server stops
// reading it, holds no copy, and the run and the dashboard go on. It was read
// whole, without the token, until the request's deadline (gigabytes a
// connection).
TEST(Dashboard, ABodyLargerThanAnyControlIsNeitherReadNorHeld) {
  DashboardRun run(60.0);
  run.wait_state(in_motion);
  const long before = resident_kib();
  constexpr std::size_t kOffered = std::size_t{64} << 20;
  for (const char* framing : {"Content-Length: 20000000000", "Transfer-Encoding: chunked"}) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    ASSERT_GE(fd, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_port = htons(static_cast<std::uint16_t>(run.server_->port()));
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    const bool chunked = std::string(framing).find("chunked") != std::string::npos;
    std::string data =
        "POST /api/stop HTTP/1.1\r\nHost: 127.0.0.1:" + std::to_string(run.server_->port()) +
        "\r\nContent-Type: application/json\r\n" + framing + "\r\n\r\n";
    const std::string piece(65536, '0');
    std::size_t sent = 0;
    while (sent < kOffered) {
      data += chunked ? "10000\r\n" + piece + "\r\n" : piece;
      const ssize_t n = ::send(fd, data.data(), data.size(), MSG_NOSIGNAL);
      if (n < 0) break;  // the server closed the connection
      sent += static_cast<std::size_t>(n);
      data.erase(0, static_cast<std::size_t>(n));
    }
    ::close(fd);
    EXPECT_LT(sent, kOffered) << framing << ": the server read the whole body";
  }
  EXPECT_LT(resident_kib() - before, 16 * 1024);
  EXPECT_TRUE(in_motion(run.get("/api/state")));  // no stop taken, the dashboard answers
}

// Publishing to the dashboard and taking its controls adds no allocation to
// the run's threads, with a client streaming, manual targets arriving and an
// IMU published.
TEST(Dashboard, TheCycleStillDoesNotAllocate) {
  test::RigSettings settings = with_pushed_imu();
  settings.edit = [edit = settings.edit](RobotConfig& c) {
    edit(c);
    c.safety.start_ramp_s = 0.3;
    c.safety.stop_ramp_s = 0.3;
  };
  test::SimRig rig(kQuadruped, settings);
  RunMonitor monitor(rig.runner().model());
  RunControls controls;
  DashboardSetup setup;
  setup.rate_hz = 200.0;  // read the monitor as often as the loop writes it
  DashboardServer server(monitor, controls, setup);
  std::atomic<bool> quit{false};
  std::atomic<int> frames{0};
  std::thread client([&] {
    httplib::Client c("127.0.0.1", server.port());
    c.Get("/api/stream", [&](const char*, std::size_t) {
      ++frames;
      return !quit.load();
    });
  });
  while (frames.load() == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  test::RunAllocationWatch watch;
  int sample = 0;
  rig.probe->on_sample = [&](double t) {  // outside the window: the test's own calls
    const bool open = watch.is_open();
    watch.close();
    if (t > 0.2) controls.manual.store(true);
    const double target[2] = {0.0, 0.1 * (++sample % 7)};
    controls.manual_targets.push(target);
    if (t > 0.6) controls.manual.store(false);
    if (open) watch.open();
  };
  RunOptions options = rig.options(1.0);
  options.controls = &controls;
  options.monitor = &monitor;
  const RunSummary s = rig.run_watching(watch, options);
  quit = true;
  server.stop();
  client.join();
  EXPECT_EQ(s.end_reason, EndReason::duration);
  ASSERT_TRUE(watch.was_opened());
  EXPECT_GT(rig.cycles_in(test::RunPhase::motion), 100u);
  EXPECT_EQ(watch.counted(), 0u) << watch.where();
}

// A server stopped as soon as it was made: its listening thread may not have
// begun to accept yet, and must still end (httplib's own stop() is ignored
// until that thread has started, so the stop waited for ever).
TEST(Dashboard, AServerStoppedBeforeItsListenerStartedEnds) {
  test::SimRig rig(kQuadruped);
  RunMonitor monitor(rig.runner().model());
  RunControls controls;
  std::atomic<int> stopped{0};
  std::thread worker([&] {
    for (int i = 0; i < 200; ++i) {
      DashboardServer server(monitor, controls, DashboardSetup{});
      server.stop();
      ++stopped;
    }
  });
  for (int waited = 0; stopped.load() < 200 && waited < 600; ++waited)
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (stopped.load() < 200) {
    ADD_FAILURE() << "a stop hung after " << stopped.load() << " servers";
    std::fflush(nullptr);
    std::_Exit(1);  // the hung listener cannot be joined
  }
  worker.join();
  // And the server still serves after all that.
  DashboardServer server(monitor, controls, DashboardSetup{});
  httplib::Client client("127.0.0.1", server.port());
  const auto info = client.Get("/api/info");
  ASSERT_TRUE(info);
  EXPECT_EQ(info->status, 200);
}

TEST(Dashboard, OnlyLoopbackUnlessRemoteIsAllowed) {
  EXPECT_TRUE(is_loopback_host("127.0.0.1"));
  EXPECT_TRUE(is_loopback_host("localhost"));
  EXPECT_TRUE(is_loopback_host("::1"));
  EXPECT_FALSE(is_loopback_host("0.0.0.0"));
  EXPECT_FALSE(is_loopback_host("192.168.1.5"));
  EXPECT_TRUE(is_loopback_host("127.0.0.5"));
  // A DNS name is not loopback, whatever it resolves to today.
  EXPECT_FALSE(is_loopback_host("127.0.0.1.nip.io"));
  EXPECT_FALSE(is_loopback_host("127.evil.example"));
  EXPECT_FALSE(is_loopback_host("::ffff:10.0.0.1"));
  test::SimRig rig(kQuadruped);
  RunMonitor monitor(rig.runner().model());
  RunControls controls;
  DashboardSetup setup;
  setup.host = "0.0.0.0";
  EXPECT_THROW(DashboardServer(monitor, controls, setup), std::invalid_argument);
  EXPECT_EQ(parse_host_port("127.0.0.1:0"), (std::pair<std::string, int>{"127.0.0.1", 0}));
  EXPECT_EQ(parse_host_port("[::1]:8080"), (std::pair<std::string, int>{"::1", 8080}));
  EXPECT_THROW(parse_host_port("127.0.0.1"), std::invalid_argument);
  EXPECT_THROW(parse_host_port("127.0.0.1:70000"), std::invalid_argument);
  EXPECT_THROW(parse_host_port("127.0.0.1:x"), std::invalid_argument);
}

// A page whose DNS name was rebound to 127.0.0.1 sends its own name as Host.
TEST(Dashboard, AnotherHostNameIsRefusedAsARebinding) {
  DashboardRun run(0.0);
  const std::string port = std::to_string(run.server_->port());
  auto c = run.client();
  for (const std::string& host :
       std::vector<std::string>{"127.0.0.1:" + port, "localhost:" + port, "[::1]:" + port}) {
    auto res = c.Get("/api/state", {{"Host", host}});
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 200) << host;
  }
  for (const std::string& host :
       std::vector<std::string>{"attacker.example:" + port, "127.0.0.1.nip.io:" + port,
                                "127.0.0.1:1" + port, "127.0.0.1"}) {
    for (const char* path : {"/api/state", "/api/info", "/"}) {
      auto res = c.Get(path, {{"Host", host}});
      ASSERT_TRUE(res);
      EXPECT_EQ(res->status, 403) << host << path;
    }
    auto res =
        c.Post("/api/stop", {{"Host", host}, {"Authorization", "Bearer " + run.server_->token()}},
               "{}", "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 403) << host;
  }
  EXPECT_FALSE(run.controls_.stop.load());
}

TEST(Dashboard, HostRuleWithRemote) {
  EXPECT_TRUE(dashboard_host_allowed("192.168.1.5:8080", "0.0.0.0", 8080, true));
  EXPECT_TRUE(dashboard_host_allowed("[fe80::1]:8080", "0.0.0.0", 8080, true));
  EXPECT_TRUE(dashboard_host_allowed("Robot.Example:8080", "robot.example", 8080, true));
  EXPECT_FALSE(dashboard_host_allowed("attacker.example:8080", "0.0.0.0", 8080, true));
  EXPECT_FALSE(dashboard_host_allowed("192.168.1.5:8081", "0.0.0.0", 8080, true));
  EXPECT_TRUE(dashboard_host_allowed("192.168.1.5", "0.0.0.0", 80, true));
  EXPECT_FALSE(dashboard_host_allowed("", "127.0.0.1", 8080, false));
}

}  // namespace
}  // namespace animrt
