#pragma once
// The plumbing every dashboard server shares (a run's, a herd's, an evolve
// run's; docs/dashboard.md): the loopback rule, the per-run token and its
// constant-time check, the latest published frame behind GET /api/state,
// the Server-Sent Events loop of GET /api/stream, the page's files and
// Debian's three.js and Chart.js, binding (port 0: a free one), the URL of
// the startup line, and an orderly end (every open stream gets the frame
// published last and its final chunk before the server stops).
//
// A dashboard owns one DashboardCore, adds its own routes to server(), then
// calls start(). Frames are whole JSON texts; publish() never blocks on a
// client (a stream copies the pointer and writes outside the lock).

#include <httplib.h>

#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "dashboard_http_server.hpp"

namespace animrt {

// A number for the page; NaN and infinity (no value) become null.
inline nlohmann::json nullable(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

struct DashboardListen {
  std::string host = "127.0.0.1";
  int port = 0;         // 0: a free one
  bool remote = false;  // allow a host that is not loopback
  std::string www_dir;  // the page; "" serves none
  std::string lib_dir = "/usr/share/javascript";
};

class DashboardCore {
 public:
  // Open /api/stream clients beyond this are refused with 503 (a browser tab
  // holds one; /api/state answers everyone).
  static constexpr int kMaxStreams = 50;

  // Throws std::invalid_argument for a host that is not loopback without
  // `remote` (the message names --dashboard-remote).
  explicit DashboardCore(DashboardListen listen);
  ~DashboardCore();  // stops
  DashboardCore(const DashboardCore&) = delete;
  DashboardCore& operator=(const DashboardCore&) = delete;

  httplib::Server& server() { return server_; }
  const std::string& token() const { return token_; }
  // The token as `Authorization: Bearer TOKEN` or a `token` query parameter.
  bool authorized(const httplib::Request& req) const;

  // The latest frame (GET /api/state), and the next one for every stream.
  void publish(std::shared_ptr<const std::string> frame);
  void publish(std::string frame) {
    publish(std::make_shared<const std::string>(std::move(frame)));
  }
  std::shared_ptr<const std::string> latest() const;
  // GET /api/state answers `build(latest frame)` instead of the frame itself
  // (a dashboard whose snapshot holds more than its stream's frames). Before
  // start().
  void state_from(std::function<std::string(const std::string& frame)> build) {
    state_from_ = std::move(build);
  }

  // Adds GET /api/state and /api/stream, the page and the libraries, binds
  // and starts listening on its own thread. A frame must have been
  // published. Throws std::runtime_error when the address cannot be bound.
  void start();
  int port() const { return port_; }
  const std::string& host() const { return listen_.host; }
  // http://HOST:PORT/?token=TOKEN
  std::string url() const;

  // Every stream gets the frame published last and ends; waits up to 1 s
  // for them (a client that does not read is not waited for longer), then
  // stops the server (idempotent).
  void stop();

  // JSON answers: `body` with `status`; an error as {"ok": false, "error"}.
  static void answer(httplib::Response& res, int status, const nlohmann::json& body);
  static void error(httplib::Response& res, int status, const std::string& message);
  // A request's body as a JSON object ({} when empty); nullopt, with what is
  // wrong in `problem` (the parser's words, a key given twice, not an
  // object), otherwise.
  static std::optional<nlohmann::json> object_body(const std::string& text, std::string& problem);
  // POST `path`: 401 without the token, 400 unless the body is empty or a
  // JSON object, then `act` with the body ({} when empty).
  void control(const std::string& path,
               std::function<void(const nlohmann::json&, httplib::Response&)> act);
  // POST `path` answers 409 with `why` (a control this dashboard lacks).
  void refuse(const std::string& path, const std::string& why);

 private:
  void routes();
  void route_stream();
  void route_files();

  DashboardListen listen_;
  std::string token_;
  int port_ = 0;
  DashboardHttpServer server_;
  std::thread listener_;
  std::function<std::string(const std::string&)> state_from_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::shared_ptr<const std::string> frame_;
  std::uint64_t generation_ = 0;
  bool quit_ = false;  // the streams end (after the frame published last)
  bool stopped_ = false;
  int streams_ = 0;  // open /api/stream responses
};

}  // namespace animrt
