#pragma once
// Replaying a recorded run (`animrt view TELEMETRY.csv`): the CSV that
// `animrt run --telemetry` writes, played in real time into a RunMonitor, so
// the dashboard shows it through the same API as a live run, with a time
// slider (seek) instead of controls.

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/run_monitor.hpp"

namespace animrt {

struct TelemetryRecording {
  std::string file;
  std::vector<std::string> joints;
  std::vector<double> t;          // per row, s
  std::vector<double> cmd, meas;  // per row, per joint (row-major)
  std::size_t rows() const { return t.size(); }
};

// Reads `time_s,<joint>_cmd_rad...,<joint>_meas_rad...`. Throws InputError
// naming the file, line and column of the first problem (a header of another
// shape, a row of the wrong width, a number that is not one, time going
// backwards, no rows).
TelemetryRecording load_telemetry_csv(const std::string& path);

// Reads the /joint_states and /joint_commands channels of an MCAP recording
// (`animrt run --record`): times from the recording's start (its "animrt"
// metadata, else its first message). Throws InputError naming the file and
// what is wrong (mcap_reader.hpp's checks, a missing channel, a message
// that is not a JointStates of the recording's joints).
TelemetryRecording load_telemetry_mcap(const std::string& path);

// Either: an MCAP file by its magic, else a CSV.
TelemetryRecording load_telemetry(const std::string& path);

// The model a replay is shown with: the recording's joints, with the robot
// file's limits and home where it has the joint (else +-pi and 0), and the
// robot's buses when every one of its joints is in the recording. Throws
// InputError when the recording has a joint the robot file does not.
RobotModel replay_model(const TelemetryRecording& recording, const RobotConfig* robot);

class TelemetryReplay {
 public:
  // Starts playing at the first row, in real time, looping at the end.
  TelemetryReplay(const TelemetryRecording& recording, RunMonitor& monitor);
  ~TelemetryReplay();
  TelemetryReplay(const TelemetryReplay&) = delete;
  TelemetryReplay& operator=(const TelemetryReplay&) = delete;

  // Jumps to the last row at or before `t_s` (clamped to the recording) and
  // publishes it at once; `playing` false holds there.
  void seek(double t_s, bool playing);

 private:
  void loop();
  void publish(std::size_t row);

  const TelemetryRecording& recording_;
  RunMonitor& monitor_;
  std::vector<double> vel_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::size_t row_ = 0;
  bool playing_ = true;
  bool moved_ = false;
  bool quit_ = false;
  std::thread thread_;
};

}  // namespace animrt
