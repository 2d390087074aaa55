#pragma once
// The dashboard (docs/dashboard.md): an HTTP server that shows a run live
// and takes its controls. A reader of the run, never part of the cycle: a
// sampler thread reads the RunMonitor at the stream rate, keeps the loop
// statistics and the fault log, poses the figure, and builds the JSON every
// client gets; controls reach the cycle only through RunControls, and need
// the run's token.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "animrt/controllers/gait/gait_steering.hpp"
#include "animrt/runtime/figure_kinematics.hpp"
#include "animrt/runtime/run_controls.hpp"
#include "animrt/runtime/run_monitor.hpp"

namespace animrt {

struct DashboardSetup {
  std::string host = "127.0.0.1";
  int port = 0;         // 0: a free port
  bool remote = false;  // allow a host that is not loopback
  double rate_hz = 30.0;
  std::string www_dir;                            // the page (index.html, ...)
  std::string lib_dir = "/usr/share/javascript";  // Debian's three.js and Chart.js
  // For /api/info.
  std::string robot;
  std::string backend;
  std::vector<std::string> bus_protocols;  // per bus of the model
  std::string motion_kind;                 // gait, show, head, layers
  std::string motion_name;                 // the motion file's stem
  std::optional<GaitSteering> steering;    // a steerable gait's range
  bool show = false;                       // the motion plays a show: POST /api/show
  double show_duration_s = 0.0;            // its length
  double duration_s = 0.0;                 // 0: until stopped
  FigureKinematics* figure = nullptr;      // the figure's model, if any
  // A figure in service (`animrt serve`): POST /api/cue {"cue": NAME} asks
  // for a cue (`cue` is false for a name the cue file lacks), {"pause":
  // true|false} pauses or resumes. Unset: the run plays no cues (409).
  std::function<bool(const std::string& name)> cue;
  std::function<void(bool paused)> pause_cues;
  // A replay (`animrt view`): POST /api/seek calls `seek` (no token: it
  // moves no robot), and the run's controls answer 409.
  bool replay = false;
  std::function<void(double t_s, bool playing)> seek;
  double replay_start_s = 0.0, replay_end_s = 0.0;  // the recording's times
  // Every row's time: the Loop panel of a replay is the recorded run's
  // (rate, cycles, periods); what the recording does not hold is null.
  std::vector<double> replay_times_s;
};

// A new random token (32 hex characters), and whether `given` is `token`,
// compared in time that depends only on the lengths.
std::string new_dashboard_token();
bool same_dashboard_token(const std::string& given, const std::string& token);

// Whether `host` names the loopback interface: an IP address in 127.0.0.0/8
// or ::1, or localhost when every address it resolves to is one. A DNS name
// is not, whatever it resolves to today (127.0.0.1.nip.io is not).
bool is_loopback_host(const std::string& host);

// Whether a request's Host header names the dashboard served at
// served_host:served_port: an IP address, localhost or the served name, with
// the served port; with `remote`, also this machine's name (and NAME.local).
// Any other name is a page whose DNS name was rebound to this machine.
bool dashboard_host_allowed(const std::string& host_header, const std::string& served_host,
                            int served_port, bool remote);

// Splits "HOST:PORT" ("[::1]:8080" for IPv6). Throws std::invalid_argument
// with a message saying what was expected.
std::pair<std::string, int> parse_host_port(const std::string& text);

class DashboardServer {
 public:
  // Binds the port and starts serving. Throws std::runtime_error when the
  // address cannot be bound, std::invalid_argument for a host that is not
  // loopback without setup.remote.
  DashboardServer(RunMonitor& monitor, RunControls& controls, DashboardSetup setup);
  ~DashboardServer();  // stops
  DashboardServer(const DashboardServer&) = delete;
  DashboardServer& operator=(const DashboardServer&) = delete;

  int port() const;
  const std::string& token() const;
  // http://HOST:PORT/?token=TOKEN
  std::string url() const;
  // Stops the streams and the server (idempotent).
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animrt
