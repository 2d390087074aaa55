// The herd's dashboard server (see herd_dashboard.hpp and docs/dashboard.md).

#include "animrt/runtime/herd_dashboard.hpp"

#include <fmt/format.h>
#include <httplib.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "animrt/controllers/herd/nav_world.hpp"
#include "animrt/runtime/dashboard.hpp"

namespace animrt {
namespace {

using nlohmann::json;

const char* kind_name(herd::GroupKind kind) {
  switch (kind) {
    case herd::GroupKind::crowd:
      return "crowd";
    case herd::GroupKind::unity:
      return "unity";
    case herd::GroupKind::reynolds:
      return "reynolds";
  }
  return "crowd";
}

json box_json(const herd::Box& b) {
  return {{"center", {b.center.x, b.center.y}}, {"size", {b.size.x, b.size.y}}, {"yaw", b.yaw_rad}};
}

// Whether a moving obstacle is scheduled down at time t (the navigation
// mesh may hold one back while agents stand in its way).
bool scheduled_down(const herd::MovingObstacle& m, double t) {
  const double u = t - m.phase_s;
  const double local = u - std::floor(u / m.period_s) * m.period_s;
  return local < m.down_fraction * m.period_s;
}

}  // namespace

struct HerdDashboardServer::Impl {
  HerdDashboardSetup setup;
  std::string token = new_dashboard_token();
  int port = 0;
  std::string info, scene;  // /api/info and /api/herd, built once
  httplib::Server server;
  std::thread listener;

  std::mutex mutex;
  std::condition_variable changed;
  std::shared_ptr<const std::string> state;
  std::uint64_t generation = 0;
  bool quit = false;
  bool stopped = false;
  int streams = 0;
  std::atomic<bool> stop_requested{false};

  explicit Impl(HerdDashboardSetup s) : setup(std::move(s)) {}

  void build(const herd::Herd& h) {
    const herd::HerdScene& s = h.scene();
    info = json{{"kind", "herd"},
                {"scene", s.name.empty() ? s.file : s.name},
                {"agents", h.agents().size()},
                {"groups", s.groups.size()},
                {"step_s", s.step_s},
                {"duration_s", s.duration_s},
                {"speed", setup.speed},
                {"replay", false}}
               .dump();
    json walls = json::array(), obstacles = json::array(), groups = json::array(),
         targets = json::array(), agents = json::array();
    for (const herd::Box& w : s.walls) walls.push_back(box_json(w));
    for (const herd::MovingObstacle& m : s.moving_obstacles) {
      json o = box_json(m.footprint);
      o["period_s"] = m.period_s;
      o["down_fraction"] = m.down_fraction;
      o["phase_s"] = m.phase_s;
      obstacles.push_back(o);
    }
    for (std::size_t g = 0; g < s.groups.size(); ++g) {
      const herd::GroupSpec& spec = s.groups[g];
      json target = nullptr;
      if (spec.target_m) {
        target = {spec.target_m->x, spec.target_m->y};
        targets.push_back({{"group", g}, {"pos", target}});
      }
      groups.push_back({{"name", spec.name},
                        {"kind", kind_name(spec.kind)},
                        {"figure", spec.figure},
                        {"count", spec.count},
                        {"target", target}});
    }
    for (std::size_t i = 0; i < h.agents().size(); ++i) {
      const herd::Agent& a = h.agents()[i];
      agents.push_back(
          {{"name", h.agent_name(static_cast<int>(i))}, {"group", a.group}, {"radius", a.radius}});
    }
    scene = json{{"bounds", {s.bounds_m.xmin, s.bounds_m.ymin, s.bounds_m.xmax, s.bounds_m.ymax}},
                 {"walls", walls},
                 {"obstacles", obstacles},
                 {"groups", groups},
                 {"targets", targets},
                 {"agents", agents}}
                .dump();
  }

  std::string state_json(const herd::Herd& h, const char* phase) const {
    json agents = json::array();
    for (const herd::Agent& a : h.agents()) {
      agents.push_back({{"x", a.position.x},
                        {"y", a.position.y},
                        {"heading", a.heading},
                        {"speed", a.speed},
                        {"group", a.group}});
    }
    json obstacles = json::array();
    const herd::HerdScene& s = h.scene();
    for (std::size_t i = 0; i < s.moving_obstacles.size(); ++i) {
      const bool down =
          h.nav() ? h.nav()->obstacle_down(i) : scheduled_down(s.moving_obstacles[i], h.time());
      obstacles.push_back({{"down", down}});
    }
    json leaders = json::array();
    for (std::size_t g = 0; g < s.groups.size(); ++g) {
      const auto l = h.leader(static_cast<int>(g));
      leaders.push_back(l ? json{l->x, l->y} : json(nullptr));
    }
    return json{{"t_s", h.time()},
                {"phase", phase},
                {"agents", agents},
                {"obstacles", obstacles},
                {"leaders", leaders}}
        .dump();
  }

  void put(std::string text) {
    auto frame = std::make_shared<const std::string>(std::move(text));
    std::lock_guard lock(mutex);
    state = std::move(frame);
    ++generation;
    changed.notify_all();
  }

  bool authorized(const httplib::Request& req) const {
    const std::string header = req.get_header_value("Authorization");
    const std::string bearer = "Bearer ";
    if (header.rfind(bearer, 0) == 0) {
      return same_dashboard_token(header.substr(bearer.size()), token);
    }
    return req.has_param("token") && same_dashboard_token(req.get_param_value("token"), token);
  }

  static void answer(httplib::Response& res, int status, const json& body) {
    res.status = status;
    res.set_content(body.dump(), "application/json");
  }

  void routes() {
    server.set_pre_routing_handler([](const httplib::Request& req, httplib::Response&) {
      const_cast<httplib::Request&>(req).headers.erase("Accept-Encoding");
      return httplib::Server::HandlerResponse::Unhandled;
    });
    server.Get("/api/info", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(info, "application/json");
    });
    server.Get("/api/herd", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(scene, "application/json");
    });
    server.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
      std::shared_ptr<const std::string> frame;
      {
        std::lock_guard lock(mutex);
        frame = state;
      }
      res.set_content(*frame, "application/json");
    });
    server.Get("/api/stream", [this](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      auto seen = std::make_shared<std::uint64_t>(0);
      {
        std::lock_guard lock(mutex);
        ++streams;
      }
      res.set_chunked_content_provider(
          "text/event-stream",
          [this, seen](std::size_t, httplib::DataSink& sink) {
            std::shared_ptr<const std::string> frame;
            {
              std::unique_lock lock(mutex);
              changed.wait(lock, [&] { return quit || generation != *seen; });
              if (generation == *seen) {
                sink.done();
                return true;
              }
              *seen = generation;
              frame = state;
            }
            const std::string event = "data: " + *frame + "\n\n";
            return sink.write(event.data(), event.size());
          },
          [this](bool) {
            {
              std::lock_guard lock(mutex);
              --streams;
            }
            changed.notify_all();
          });
    });
    server.Post("/api/stop", [this](const httplib::Request& req, httplib::Response& res) {
      if (!authorized(req)) {
        return answer(res, 401, {{"ok", false}, {"error", "a valid token is needed for controls"}});
      }
      stop_requested = true;
      answer(res, 200, {{"ok", true}});
    });
    for (const char* path : {"/api/manual", "/api/jog", "/api/steer", "/api/show", "/api/seek"}) {
      server.Post(path, [](const httplib::Request&, httplib::Response& res) {
        answer(res, 409, {{"ok", false}, {"error", "a herd has no such control"}});
      });
    }
    server.set_file_extension_and_mimetype_mapping("js", "text/javascript");
    server.set_file_extension_and_mimetype_mapping("mjs", "text/javascript");
    if (!setup.www_dir.empty()) server.set_mount_point("/", setup.www_dir);
    const std::string three = setup.lib_dir + "/three";
    const std::string chart = setup.lib_dir + "/chart.js";
    server.set_mount_point("/lib/three", three);
    server.set_mount_point("/lib/chart.js", chart);
    const auto file = [](const std::string& path) {
      return [path](const httplib::Request&, httplib::Response& res) {
        std::ifstream in(path, std::ios::binary);
        if (!in) return answer(res, 404, {{"ok", false}, {"error", path + " is not installed"}});
        res.set_content(std::string(std::istreambuf_iterator<char>(in), {}), "text/javascript");
      };
    };
    server.Get("/lib/three.module.js", file(three + "/three.module.js"));
    server.Get("/lib/chart.umd.js", file(chart + "/chart.min.js"));
  }
};

HerdDashboardServer::HerdDashboardServer(const herd::Herd& herd, HerdDashboardSetup setup)
    : impl_(std::make_unique<Impl>(std::move(setup))) {
  Impl& m = *impl_;
  if (!m.setup.remote && !is_loopback_host(m.setup.host)) {
    throw std::invalid_argument("--dashboard " + m.setup.host +
                                " is not a loopback address; add --dashboard-remote to serve "
                                "other machines");
  }
  m.build(herd);
  m.state = std::make_shared<const std::string>(m.state_json(herd, "running"));
  m.routes();
  m.server.set_write_timeout(2, 0);
  if (m.setup.port == 0) {
    m.port = m.server.bind_to_any_port(m.setup.host);
  } else {
    m.port = m.server.bind_to_port(m.setup.host, m.setup.port) ? m.setup.port : -1;
  }
  if (m.port <= 0) {
    throw std::runtime_error(
        fmt::format("dashboard: cannot listen on {}:{}", m.setup.host, m.setup.port));
  }
  m.listener = std::thread([&m] { m.server.listen_after_bind(); });
}

HerdDashboardServer::~HerdDashboardServer() { stop(); }

int HerdDashboardServer::port() const { return impl_->port; }
const std::string& HerdDashboardServer::token() const { return impl_->token; }

std::string HerdDashboardServer::url() const {
  const std::string& host = impl_->setup.host;
  const bool v6 = host.find(':') != std::string::npos;
  return fmt::format("http://{}:{}/?token={}", v6 ? "[" + host + "]" : host, impl_->port,
                     impl_->token);
}

void HerdDashboardServer::publish(const herd::Herd& herd) {
  impl_->put(impl_->state_json(herd, "running"));
}

bool HerdDashboardServer::stop_requested() const { return impl_->stop_requested.load(); }

void HerdDashboardServer::stop() {
  Impl& m = *impl_;
  {
    std::unique_lock lock(m.mutex);
    if (m.stopped) return;
    m.stopped = true;
    // The last state again, as ended.
    if (m.state) {
      json last = json::parse(*m.state);
      last["phase"] = "ended";
      m.state = std::make_shared<const std::string>(last.dump());
      ++m.generation;
    }
    m.quit = true;
    m.changed.notify_all();
    m.changed.wait_for(lock, std::chrono::seconds(1), [&m] { return m.streams == 0; });
  }
  m.server.stop();
  if (m.listener.joinable()) m.listener.join();
}

}  // namespace animrt
