// `animrt view`: a telemetry CSV replayed through the dashboard's API, with
// seek instead of controls.

#include <gtest/gtest.h>
#include <httplib.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "animrt/runtime/dashboard.hpp"
#include "animrt/runtime/telemetry_replay.hpp"

namespace animrt {
namespace {

using nlohmann::json;

std::string write_csv(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "animrt_replay_" + name + ".csv";
  std::ofstream(path) << text;
  return path;
}

const char* const kRecording =
    "time_s,a_cmd_rad,b_cmd_rad,a_meas_rad,b_meas_rad\n"
    "0,0,0,0,0\n"
    "0.1,0.1,-0.1,0.05,-0.05\n"
    "0.2,0.2,-0.2,0.15,-0.15\n"
    "0.3,0.3,-0.3,0.25,-0.25\n";

TEST(Replay, ARecordingLoadsAndBadOnesAreErrorsAtTheirPlace) {
  const TelemetryRecording rec = load_telemetry_csv(write_csv("good", kRecording));
  EXPECT_EQ(rec.joints, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(rec.rows(), 4u);
  EXPECT_DOUBLE_EQ(rec.cmd[2 * 2 + 1], -0.2);
  EXPECT_DOUBLE_EQ(rec.meas[3 * 2 + 0], 0.25);

  const auto error = [](const std::string& name, const std::string& text) {
    const std::string path = write_csv(name, text);
    try {
      (void)load_telemetry_csv(path);
    } catch (const InputError& e) {
      return std::string(e.what()).substr(path.size());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("number", "time_s,a_cmd_rad,a_meas_rad\n0,0,0\n0.1,x,0\n"),
            ":3:5: expected a number, found \"x\"");
  EXPECT_EQ(error("width", "time_s,a_cmd_rad,a_meas_rad\n0,0\n"),
            ":2:1: expected 3 fields, found 2");
  EXPECT_EQ(error("back", "time_s,a_cmd_rad,a_meas_rad\n1,0,0\n0.5,0,0\n"),
            ":3:1: time goes backwards (\"0.5\" after 1)");
  EXPECT_EQ(error("nan_time", "time_s,a_cmd_rad,a_meas_rad\n0,0,0\nnan,0,0\n"),
            ":3:1: expected a finite number, found \"nan\"");
  EXPECT_EQ(error("inf_joint", "time_s,a_cmd_rad,a_meas_rad\n0,0,0\n0.1,0,-inf\n"),
            ":3:7: expected a finite number, found \"-inf\"");
  // Lines ended CR LF (saved on Windows) load as the same recording.
  std::string crlf = kRecording;
  for (std::size_t at = crlf.find('\n'); at != std::string::npos; at = crlf.find('\n', at + 2)) {
    crlf.insert(at, "\r");
  }
  const TelemetryRecording windows = load_telemetry_csv(write_csv("crlf", crlf));
  EXPECT_EQ(windows.joints, rec.joints);
  EXPECT_EQ(windows.meas, rec.meas);
  EXPECT_EQ(error("header", "t,a,b\n"),
            ":1:1: expected the header time_s,<joint>_cmd_rad,...,<joint>_meas_rad,... of animrt "
            "run --telemetry, found \"t,a,b\"");
  EXPECT_EQ(error("empty", "time_s,a_cmd_rad,a_meas_rad\n"),
            ":1: expected at least one row after the header");
}

// A run that read device health writes five columns per device after the
// joints'; a replay reads the joints' and leaves those.
TEST(Replay, ARecordingWithHealthColumnsLoads) {
  const TelemetryRecording rec = load_telemetry_csv(write_csv(
      "health",
      "time_s,a_cmd_rad,a_meas_rad,a_temp_c,a_current_a,a_voltage_v,a_torque_nm,a_error_bits\n"
      "0,0.1,0.05,36,0.05,11.9,nan,0\n"
      "0.1,0.2,0.15,37,nan,11.8,nan,4\n"));
  EXPECT_EQ(rec.joints, (std::vector<std::string>{"a"}));
  ASSERT_EQ(rec.rows(), 2u);
  EXPECT_DOUBLE_EQ(rec.cmd[1], 0.2);
  EXPECT_DOUBLE_EQ(rec.meas[1], 0.15);
  const std::string bad =
      write_csv("health_bad", "time_s,a_cmd_rad,a_meas_rad,a_colour\n0,0,0,1\n");
  try {
    (void)load_telemetry_csv(bad);
    ADD_FAILURE() << "an unknown extra column was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).substr(bad.size()),
              ":1: expected a device health column (<joint>_temp_c, _current_a, _voltage_v, "
              "_torque_nm or _error_bits) or an IMU column (<imu>_qw, _qx, _qy, _qz, "
              "_rate_x_rad_s, _rate_y_rad_s, _rate_z_rad_s) as column 4, found \"a_colour\"");
  }
}

// A figure with an IMU writes seven columns per IMU after the health columns.
TEST(Replay, ARecordingWithImuColumnsLoads) {
  const TelemetryRecording rec = load_telemetry_csv(write_csv(
      "imu",
      "time_s,a_cmd_rad,a_meas_rad,trunk_qw,trunk_qx,trunk_qy,trunk_qz,trunk_rate_x_rad_s,"
      "trunk_rate_y_rad_s,trunk_rate_z_rad_s\n"
      "0,0.1,0.05,nan,nan,nan,nan,nan,nan,nan\n"
      "0.1,0.2,0.15,1,0,0,0,0,0,0\n"));
  EXPECT_EQ(rec.joints, (std::vector<std::string>{"a"}));
  ASSERT_EQ(rec.rows(), 2u);
  EXPECT_DOUBLE_EQ(rec.meas[1], 0.15);
}

TEST(Replay, SeekShowsTheRecordedRowAndControlsAreRefused) {
  const TelemetryRecording rec = load_telemetry_csv(write_csv("api", kRecording));
  const RobotModel model = replay_model(rec, nullptr);
  RunMonitor monitor(model);
  TelemetryReplay replay(rec, monitor);
  RunControls controls;
  DashboardSetup setup;
  setup.replay = true;
  setup.replay_start_s = rec.t.front();
  setup.replay_end_s = rec.t.back();
  setup.replay_times_s = rec.t;
  setup.seek = [&replay](double t, bool playing) { replay.seek(t, playing); };
  DashboardServer server(monitor, controls, setup);
  httplib::Client client("127.0.0.1", server.port());

  auto info = client.Get("/api/info");
  ASSERT_TRUE(info);
  const json i = json::parse(info->body);
  EXPECT_TRUE(i["replay"].get<bool>());
  EXPECT_EQ(i["replay_range_s"], json({0.0, 0.3}));
  EXPECT_EQ(i["joints"].size(), 2u);

  // No token needed to seek: it moves no robot.
  auto seek = client.Post("/api/seek", R"({"t_s": 0.25, "playing": false})", "application/json");
  ASSERT_TRUE(seek);
  EXPECT_EQ(seek->status, 200);
  json state;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  do {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    state = json::parse(client.Get("/api/state")->body);
  } while (state["t_s"].get<double>() != 0.2 && std::chrono::steady_clock::now() < give_up);
  EXPECT_EQ(state["t_s"].get<double>(), 0.2);  // the last row at or before 0.25
  EXPECT_EQ(state["joints"][0]["cmd"].get<double>(), 0.2);
  EXPECT_EQ(state["joints"][1]["meas"].get<double>(), -0.15);
  EXPECT_NEAR(state["joints"][0]["vel"].get<double>(), 1.0, 1e-9);

  // The Loop panel is the recorded run's: 4 rows 0.1 s apart, 10 Hz; what
  // the recording does not hold is null (n/a), not 0.
  const json& loop = state["loop"];
  EXPECT_EQ(loop["cycles"].get<int>(), 4);
  EXPECT_NEAR(loop["rate_hz"].get<double>(), 10.0, 1e-9);
  EXPECT_NEAR(loop["period_ms"]["p50"].get<double>(), 100.0, 0.01);
  EXPECT_NEAR(loop["period_ms"]["max"].get<double>(), 100.0, 0.01);
  EXPECT_TRUE(loop["jitter_ms"].is_null());
  EXPECT_TRUE(loop["overruns"].is_null());

  EXPECT_EQ(client.Post("/api/seek", R"({"t": 1})", "application/json")->status, 400);
  httplib::Headers bearer{{"Authorization", "Bearer " + server.token()}};
  EXPECT_EQ(client.Post("/api/stop", bearer, "{}", "application/json")->status, 409);
  EXPECT_EQ(client.Post("/api/stop", "{}", "application/json")->status, 401);
  EXPECT_FALSE(controls.stop.load());
}

}  // namespace
}  // namespace animrt
