// The herd's dashboard server (see herd_dashboard.hpp and docs/dashboard.md).

#include "animrt/runtime/herd_dashboard.hpp"

#include <fmt/format.h>
#include <httplib.h>

#include <atomic>
#include <cmath>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "animrt/controllers/herd/nav_world.hpp"
#include "animrt/runtime/dashboard.hpp"
#include "dashboard_core.hpp"

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
  DashboardCore core;
  std::string info, scene;  // /api/info and /api/herd, built once
  std::mutex mutex;
  bool stopped = false;
  std::atomic<bool> stop_requested{false};

  explicit Impl(HerdDashboardSetup s)
      : setup(std::move(s)),
        core(DashboardListen{setup.host, setup.port, setup.remote, setup.www_dir, setup.lib_dir}) {}

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

  void routes() {
    httplib::Server& server = core.server();
    server.Get("/api/info", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(info, "application/json");
    });
    server.Get("/api/herd", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(scene, "application/json");
    });
    // The token only: the body is not read.
    server.Post("/api/stop", [this](const httplib::Request& req, httplib::Response& res) {
      if (!core.authorized(req)) {
        return DashboardCore::error(res, 401, "a valid token is needed for controls");
      }
      stop_requested = true;
      DashboardCore::answer(res, 200, {{"ok", true}});
    });
    for (const char* path : {"/api/manual", "/api/jog", "/api/steer", "/api/show", "/api/seek"}) {
      core.refuse(path, "a herd has no such control");
    }
  }
};

HerdDashboardServer::HerdDashboardServer(const herd::Herd& herd, HerdDashboardSetup setup)
    : impl_(std::make_unique<Impl>(std::move(setup))) {
  Impl& m = *impl_;
  m.build(herd);
  m.core.publish(m.state_json(herd, "running"));
  m.routes();
  m.core.start();
}

HerdDashboardServer::~HerdDashboardServer() { stop(); }

int HerdDashboardServer::port() const { return impl_->core.port(); }
const std::string& HerdDashboardServer::token() const { return impl_->core.token(); }
std::string HerdDashboardServer::url() const { return impl_->core.url(); }

void HerdDashboardServer::publish(const herd::Herd& herd) {
  impl_->core.publish(impl_->state_json(herd, "running"));
}

bool HerdDashboardServer::stop_requested() const { return impl_->stop_requested.load(); }

void HerdDashboardServer::stop() {
  Impl& m = *impl_;
  {
    std::lock_guard lock(m.mutex);
    if (m.stopped) return;
    m.stopped = true;
  }
  // The last state again, as ended.
  if (const auto state = m.core.latest()) {
    json last = json::parse(*state);
    last["phase"] = "ended";
    m.core.publish(last.dump());
  }
  m.core.stop();
}

}  // namespace animrt
