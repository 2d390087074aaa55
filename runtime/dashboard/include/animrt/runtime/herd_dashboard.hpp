#pragma once
// The herd's dashboard (docs/dashboard.md, "A herd"): an HTTP server that
// shows a running herd from above. The herd's loop (`animrt herd
// --dashboard`) is not a real-time cycle: it publishes each state it wants
// shown, and the server streams the latest to every client. The page's
// files and Debian's libraries are served as for a run, under the same
// token and loopback rules.

#include <memory>
#include <string>

#include "animrt/controllers/herd/herd.hpp"

namespace animrt {

struct HerdDashboardSetup {
  std::string host = "127.0.0.1";
  int port = 0;         // 0: a free one
  bool remote = false;  // allow a host that is not loopback
  std::string www_dir;
  std::string lib_dir = "/usr/share/javascript";
  double speed = 1.0;  // the herd's pace, in multiples of real time (for /api/info)
};

class HerdDashboardServer {
 public:
  // Binds the port and starts serving the scene of `herd` (its agents,
  // groups, walls and obstacles are read here, once). Throws like
  // DashboardServer.
  HerdDashboardServer(const herd::Herd& herd, HerdDashboardSetup setup);
  ~HerdDashboardServer();  // stops
  HerdDashboardServer(const HerdDashboardServer&) = delete;
  HerdDashboardServer& operator=(const HerdDashboardServer&) = delete;

  int port() const;
  const std::string& token() const;
  std::string url() const;  // http://HOST:PORT/?token=TOKEN

  // The herd's state now (from the herd's thread, between steps).
  void publish(const herd::Herd& herd);
  // POST /api/stop arrived (with the token).
  bool stop_requested() const;
  // The run is over: the last state goes out with phase "ended", the
  // streams end, the server stops (idempotent).
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace animrt
