// The dashboard's server (see dashboard.hpp and docs/dashboard.md).

#include "animrt/runtime/dashboard.hpp"

#include <fmt/format.h>
#include <httplib.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>
#include <thread>

#include "animrt/core/imu.hpp"
#include "animrt/runtime/loop_stats.hpp"
#include "dashboard_core.hpp"

namespace animrt {
namespace {

using nlohmann::json;

// Jitter histogram bins (ms); the last bin holds everything beyond.
constexpr std::array<double, 10> kJitterEdgesMs{0.0, 0.025, 0.05, 0.1, 0.25,
                                                0.5, 1.0,   2.5,  5.0, 10.0};
constexpr std::size_t kRecentPeriods = 256;  // the rate is their mean's inverse
constexpr std::size_t kFaultLogCapacity = 200;

// The loop's statistics, from every cycle's timing as the reader drains it.
struct LoopStats {
  MicrosHistogram period, jitter;
  std::array<std::uint64_t, kJitterEdgesMs.size()> jitter_bins{};
  std::array<double, kRecentPeriods> recent{};
  std::size_t recent_count = 0, recent_next = 0;

  void add(const CycleTiming& t) {
    jitter.add(std::max(0.0, t.jitter_s));
    const double ms = t.jitter_s * 1e3;
    std::size_t bin = 0;
    while (bin + 1 < kJitterEdgesMs.size() && ms >= kJitterEdgesMs[bin + 1]) ++bin;
    ++jitter_bins[bin];
    if (t.period_s >= 0.0) {
      period.add(t.period_s);
      recent[recent_next] = t.period_s;
      recent_next = (recent_next + 1) % recent.size();
      recent_count = std::min(recent_count + 1, recent.size());
    }
  }
  double rate_hz() const {
    double sum = 0.0;
    for (std::size_t i = 0; i < recent_count; ++i) sum += recent[i];
    return sum > 0.0 ? static_cast<double>(recent_count) / sum : 0.0;
  }
};

// A health value, or null when the device does not report it.
json health_number(double v) { return std::isnan(v) ? json() : json(v); }

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// An IMU's row: attitude and rates in degrees, the reading's age and the
// cycle's counts. Health as the cycle judges it: waiting (no reading yet),
// ok, late (older than one report and one loop period) or stale (silent
// past its stale timeout: faulted).
json imu_json(const ImuModel& model, const ImuView& v, double now_s, double dt) {
  const ImuReading& r = v.reading;
  const double age = now_s - r.time_s;
  const char* health = !v.valid                                ? "waiting"
                       : v.faulted                             ? "stale"
                       : age > 1.0 / model.rate_hz + dt + 1e-9 ? "late"
                                                               : "ok";
  json row = {{"name", model.name},
              {"health", health},
              {"late_cycles", v.late_cycles},
              {"missing_reports", v.missing_reports},
              {"roll_deg", nullptr},
              {"pitch_deg", nullptr},
              {"yaw_deg", nullptr},
              {"rate_dps", nullptr},
              {"age_s", nullptr}};
  if (!v.valid) return row;
  row["roll_deg"] = roll_of(r.quat) * kDegPerRad;
  row["pitch_deg"] = pitch_of(r.quat) * kDegPerRad;
  row["yaw_deg"] = yaw_of(r.quat) * kDegPerRad;
  row["rate_dps"] = {r.rate_rad_s[0] * kDegPerRad, r.rate_rad_s[1] * kDegPerRad,
                     r.rate_rad_s[2] * kDegPerRad};
  row["age_s"] = nullable(age);
  return row;
}

json timing_json(const MicrosHistogram& h) {
  return {{"p50", h.quantile(0.5) * 1e3}, {"p99", h.quantile(0.99) * 1e3}, {"max", h.max() * 1e3}};
}

// A replay's Loop panel: the recorded run's rate, cycles and periods. Its
// jitter, overruns and late cycles were not recorded: null (n/a), not 0.
json recorded_loop_json(const std::vector<double>& t) {
  MicrosHistogram period;
  for (std::size_t i = 1; i < t.size(); ++i) period.add(t[i] - t[i - 1]);
  const double span = t.size() > 1 ? t.back() - t.front() : 0.0;
  return {{"cycles", t.size()},
          {"rate_hz", span > 0.0 ? json(static_cast<double>(t.size() - 1) / span) : json(nullptr)},
          {"period_ms", period.count() ? timing_json(period) : json(nullptr)},
          {"jitter_ms", nullptr},
          {"overruns", nullptr},
          {"skipped", nullptr},
          {"late", json::object()},
          {"jitter_hist", nullptr}};
}

}  // namespace

struct DashboardServer::Impl {
  RunMonitor& monitor;
  RunControls& controls;
  DashboardSetup setup;
  const RobotModel& model;
  DashboardCore core;
  std::string info;    // /api/info, built once
  json recorded_loop;  // a replay's Loop panel, built once
  std::thread sampler;

  // The sampler's own state (its thread only).
  RunView view;
  LoopStats stats;
  std::vector<BodyPose> measured_bodies, commanded_bodies;

  // The sampler's end: it publishes a last frame and ends.
  std::mutex mutex;
  std::condition_variable changed;
  bool sampler_quit = false;
  std::vector<std::pair<double, std::string>> faults;  // the fault log (the sampler's)

  // Controls: one writer at a time for RunControls' single-writer channels.
  std::mutex controls_mutex;
  bool manual = false;
  std::atomic<RunPhaseView> phase{RunPhaseView::configure};  // the sampler's latest
  ShowCommand show;  // the show's transport as the controls last set it

  Impl(RunMonitor& m, RunControls& c, DashboardSetup s)
      : monitor(m),
        controls(c),
        setup(std::move(s)),
        model(m.model()),
        core(DashboardListen{setup.host, setup.port, setup.remote, setup.www_dir, setup.lib_dir}) {}

  std::string fault_text(const CycleEvent& e) const {
    const auto joint = [&](int j) {
      return j >= 0 && static_cast<std::size_t>(j) < model.joint_count()
                 ? model.joint_names[static_cast<std::size_t>(j)]
                 : std::string("?");
    };
    const auto device = [&] {
      const BusModel& bus = model.buses[e.bus];
      return fmt::format("{} id {} ({})", bus.name, bus.device_id[e.device], joint(e.joint));
    };
    switch (e.kind) {
      case EventKind::device_fault:
        return fmt::format("{}: {}", device(),
                           e.health == DeviceHealth::hardware_error
                               ? "hardware error"
                               : fmt::format("no valid answer (last: {})", to_string(e.health)));
      case EventKind::following_error:
        return fmt::format("{}: following error, RMS {:.4f} {}", device(), e.value,
                           model.prismatic[static_cast<std::size_t>(e.joint)] ? "m" : "rad");
      case EventKind::motion_fault:
        return fmt::format("motion fault: joint {} got a non-finite target", joint(e.joint));
      case EventKind::health_fault:
      case EventKind::health_warning:
        return fmt::format("{}: {} {} {:g}{}", device(), to_string(e.check),
                           e.kind == EventKind::health_fault ? "fault" : "warning", e.value,
                           e.kind == EventKind::health_fault ? ", switched off" : "");
      case EventKind::stop_deadline:
        return "the stop ramp ran over its deadline: torque switched off";
      case EventKind::aborted:
        return "abort: torque switched off";
      case EventKind::stop_unreached:
        return fmt::format("{}: not at its stop pose when torque went off ({:.4f} {} off)",
                           joint(e.joint), e.value,
                           model.prismatic[static_cast<std::size_t>(e.joint)] ? "m" : "rad");
      default:
        return {};
    }
  }

  std::string build_info() const {
    json joints = json::array();
    for (std::size_t j = 0; j < model.joint_count(); ++j) {
      joints.push_back({{"name", model.joint_names[j]},
                        {"kind", model.prismatic[j] ? "prismatic" : "revolute"},
                        {"min", model.limits[j].min_position},
                        {"max", model.limits[j].max_position},
                        {"max_velocity", model.limits[j].max_velocity},
                        {"home", model.home[j]}});
    }
    json buses = json::array();
    for (std::size_t b = 0; b < model.buses.size(); ++b) {
      json devices = json::array();
      for (std::size_t d = 0; d < model.buses[b].joint.size(); ++d) {
        devices.push_back(
            {{"id", model.buses[b].device_id[d]},
             {"joint", model.joint_names[static_cast<std::size_t>(model.buses[b].joint[d])]}});
      }
      buses.push_back({{"name", model.buses[b].name},
                       {"protocol", b < setup.bus_protocols.size() ? setup.bus_protocols[b] : ""},
                       {"devices", devices}});
    }
    json motion = {{"kind", setup.motion_kind},
                   {"name", setup.motion_name},
                   {"steerable", setup.steering.has_value()},
                   {"show", setup.show},
                   {"speed_mps", nullptr},
                   {"turn_rps", nullptr},
                   {"duration_s", setup.duration_s > 0 ? json(setup.duration_s) : json(nullptr)}};
    if (setup.steering) {
      motion["speed_mps"] = {0.0, setup.steering->max_speed_m_s()};
      motion["turn_rps"] = {-setup.steering->max_turn_rad_s, setup.steering->max_turn_rad_s};
    }
    json figure = nullptr;
    if (setup.figure) {
      json bodies = json::array();
      for (const FigureBody& body : setup.figure->bodies()) {
        json geoms = json::array();
        for (const FigureGeom& g : body.geoms) {
          geoms.push_back({{"type", g.type},
                           {"size", g.size},
                           {"pos", g.pos},
                           {"quat", g.quat},
                           {"rgba", g.rgba}});
        }
        bodies.push_back({{"name", body.name}, {"parent", body.parent}, {"geoms", geoms}});
      }
      figure = {{"bodies", bodies}};
    }
    return json{{"robot", setup.robot},
                {"backend", setup.backend},
                {"rate_hz", model.rate_hz},
                {"joints", joints},
                {"buses", buses},
                {"imus", imus_info_json()},
                {"tilt_limit_deg", model.safety.tilt_limit_rad > 0.0
                                       ? json(model.safety.tilt_limit_rad * kDegPerRad)
                                       : json(nullptr)},
                {"motion", motion},
                {"model", figure},
                {"replay", setup.replay},
                {"replay_range_s",
                 setup.replay ? json{setup.replay_start_s, setup.replay_end_s} : json(nullptr)}}
        .dump();
  }

  json imus_info_json() const {
    json imus = json::array();
    for (const ImuModel& imu : model.imus) {
      imus.push_back(
          {{"name", imu.name}, {"rate_hz", imu.rate_hz}, {"stale_timeout_s", imu.stale_timeout_s}});
    }
    return imus;
  }

  json imus_json() const {
    json imus = json::array();
    for (std::size_t i = 0; i < model.imus.size() && i < view.imus.size(); ++i) {
      imus.push_back(imu_json(model.imus[i], view.imus[i], view.t_s, model.dt));
    }
    return imus;
  }

  json poses_json(const std::vector<BodyPose>& poses) const {
    json out = json::array();
    for (const BodyPose& p : poses) out.push_back({{"pos", p.pos}, {"quat", p.quat}});
    return out;
  }

  // One frame: drain the rings, read the block, build the JSON.
  std::string build_state() {
    drain_rings();
    monitor.read(view);
    phase.store(view.phase, std::memory_order_relaxed);
    json manual_positions = json::object();
    json joints = joints_json(manual_positions);
    json devices = devices_json();
    json fault_log = fault_log_json(devices);
    json frame = {{"t_s", view.t_s},
                  {"phase", to_string(view.phase)},
                  {"joints", joints},
                  {"loop", loop_json()},
                  {"devices", devices},
                  {"imus", imus_json()},
                  {"faults", fault_log},
                  {"motion", motion_json()},
                  {"manual", {{"on", view.manual}, {"positions", manual_positions}}}};
    if (setup.figure && view.published) add_bodies(frame);
    return frame.dump();
  }

  // The cycle timings into the statistics, the events into the fault log.
  void drain_rings() {
    CycleTiming timing;
    while (monitor.pop_timing(timing)) stats.add(timing);
    CycleEvent event;
    while (monitor.pop_event(event)) {
      std::string text = fault_text(event);
      if (text.empty()) continue;
      if (faults.size() < kFaultLogCapacity) faults.emplace_back(event.t, std::move(text));
    }
  }

  json joints_json(json& manual_positions) const {
    const std::size_t n = model.joint_count();
    json joints = json::array();
    for (std::size_t j = 0; j < n; ++j) {
      joints.push_back({{"name", model.joint_names[j]},
                        {"cmd", nullable(view.cmd[j])},
                        {"meas", nullable(view.meas[j])},
                        {"vel", nullable(view.vel[j])}});
      if (view.manual) manual_positions[model.joint_names[j]] = nullable(view.manual_pose[j]);
    }
    return joints;
  }

  json loop_json() const {
    if (setup.replay) return recorded_loop;
    json late = json::object();
    for (std::size_t b = 0; b < model.buses.size(); ++b) late[model.buses[b].name] = view.late[b];
    json edges = json::array(), counts = json::array();
    for (std::size_t i = 0; i < kJitterEdgesMs.size(); ++i) {
      edges.push_back(kJitterEdgesMs[i]);
      counts.push_back(stats.jitter_bins[i]);
    }
    return {{"cycles", view.cycles},
            {"rate_hz", stats.rate_hz()},
            {"period_ms", timing_json(stats.period)},
            {"jitter_ms", timing_json(stats.jitter)},
            {"overruns", view.overruns},
            {"skipped", view.skipped},
            {"late", late},
            {"jitter_hist", {{"edges_ms", edges}, {"counts", counts}}}};
  }

  json devices_json() const {
    json devices = json::array();
    std::size_t k = 0;
    for (const BusModel& bus : model.buses) {
      for (std::size_t d = 0; d < bus.joint.size(); ++d, ++k) {
        const DeviceStatus& s = view.devices[k];
        devices.push_back(
            {{"bus", bus.name},
             {"id", bus.device_id[d]},
             {"joint", model.joint_names[static_cast<std::size_t>(bus.joint[d])]},
             {"health", to_string(s.health)},
             {"faulted", s.faulted},
             {"transactions", s.transactions},
             {"timeouts", s.timeouts},
             {"crc", s.crc_errors},
             {"protocol", s.protocol_errors},
             {"hardware", s.hardware_errors},
             {"exceptions", s.exceptions},
             {"temperature_c", health_number(s.reading.temperature_c)},
             {"current_a", health_number(s.reading.current_a)},
             {"voltage_v", health_number(s.reading.voltage_v)},
             {"torque_nm", health_number(s.reading.torque_nm)},
             {"error_bits", s.reading.has_error_bits ? json(s.reading.error_bits) : json()},
             {"last_fault", nullptr}});
      }
    }
    return devices;
  }

  json fault_log_json(json& devices) const {
    json fault_log = json::array();
    for (const auto& [t, text] : faults) {
      fault_log.push_back({{"t_s", t}, {"text", text}});
      // The device's latest fault, for its row.
      for (json& d : devices) {
        const std::string prefix =
            fmt::format("{} id {} ", d["bus"].get<std::string>(), d["id"].get<int>());
        if (text.rfind(prefix, 0) == 0) d["last_fault"] = text;
      }
    }
    return fault_log;
  }

  json motion_json() const {
    return {{"speed_mps", view.steered ? json(view.steer.speed_m_s) : json(nullptr)},
            {"turn_rps", view.steered ? json(view.steer.turn_rad_s) : json(nullptr)},
            {"position_s", view.show.show ? view.show.position_s : view.motion_time_s},
            {"playing", view.phase == RunPhaseView::motion && !view.manual &&
                            (!view.show.show || view.show.playing)},
            {"duration_s", view.show.show ? json(view.show.duration_s) : json(nullptr)}};
  }

  // The figure posed from the measured and the commanded joints.
  void add_bodies(json& frame) {
    const std::size_t bodies = setup.figure->bodies().size();
    measured_bodies.resize(bodies);
    commanded_bodies.resize(bodies);
    setup.figure->pose(view.meas, measured_bodies);
    setup.figure->pose(view.cmd, commanded_bodies);
    frame["bodies"] = {{"measured", poses_json(measured_bodies)},
                       {"commanded", poses_json(commanded_bodies)}};
  }

  void sample_loop() {
    const auto period = std::chrono::duration<double>(1.0 / setup.rate_hz);
    auto next = std::chrono::steady_clock::now();
    for (bool last = false;;) {
      core.publish(build_state());
      std::unique_lock lock(mutex);
      if (last) return;
      next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
      last = changed.wait_until(lock, next, [this] { return sampler_quit; });
    }
  }

  static void answer(httplib::Response& res, int status, const json& body) {
    DashboardCore::answer(res, status, body);
  }
  static void error(httplib::Response& res, int status, const std::string& message) {
    DashboardCore::error(res, status, message);
  }

  // A control: the token, then a JSON object body, then `act` (one at a
  // time; never in a replay).
  void control(const std::string& path, std::function<void(const json&, httplib::Response&)> act) {
    core.control(path, [this, act](const json& body, httplib::Response& res) {
      if (setup.replay) return error(res, 409, "a replay controls no robot");
      std::lock_guard lock(controls_mutex);
      act(body, res);
    });
  }

  static std::optional<double> number(const json& body, const char* key) {
    const auto it = body.find(key);
    if (it == body.end() || !it->is_number()) return std::nullopt;
    const double value = it->get<double>();
    if (!std::isfinite(value)) return std::nullopt;
    return value;
  }

  void routes() {
    httplib::Server& server = core.server();
    server.Get("/api/info", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(info, "application/json");
    });

    control("/api/stop", [this](const json&, httplib::Response& res) {
      controls.stop.store(true);
      answer(res, 200, {{"ok", true}});
    });
    control("/api/manual", [this](const json& body, httplib::Response& res) {
      const auto on = body.find("on");
      if (on == body.end() || !on->is_boolean()) {
        return error(res, 400, "expected {\"on\": true} or {\"on\": false}");
      }
      manual = on->get<bool>();
      controls.manual.store(manual, std::memory_order_release);
      answer(res, 200, {{"ok", true}});
    });
    route_jog();
    route_steer();
    route_show();
    route_cue();
    route_seek(server);
  }

  // A served figure's cues: one asked for, or a pause.
  void route_cue() {
    control("/api/cue", [this](const json& body, httplib::Response& res) {
      if (!setup.cue) return error(res, 409, "the figure plays no cues (animrt serve does)");
      const auto cue = body.find("cue");
      const auto pause = body.find("pause");
      if (cue != body.end() && pause != body.end()) {
        return error(res, 400, "give either \"cue\" or \"pause\", not both");
      }
      if (cue != body.end() && cue->is_string()) {
        if (!setup.cue(cue->get<std::string>())) {
          return error(res, 400, "no cue named " + cue->dump());
        }
      } else if (pause != body.end() && pause->is_boolean()) {
        setup.pause_cues(pause->get<bool>());
      } else {
        return error(res, 400, "expected {\"cue\": NAME} or {\"pause\": true|false}");
      }
      answer(res, 200, {{"ok", true}});
    });
  }

  // A joint's position in manual mode, clamped to its limits.
  void route_jog() {
    control("/api/jog", [this](const json& body, httplib::Response& res) {
      const auto joint = body.find("joint");
      if (joint == body.end() || !joint->is_string()) {
        return error(res, 400, "expected \"joint\": a joint name");
      }
      const auto& names = model.joint_names;
      const auto it = std::find(names.begin(), names.end(), joint->get<std::string>());
      if (it == names.end()) return error(res, 400, "no joint named " + joint->dump());
      const auto position = number(body, "position");
      if (!position) return error(res, 400, "expected \"position\": a finite number (rad or m)");
      if (!manual) return error(res, 409, "not in manual mode (POST /api/manual {\"on\": true})");
      const auto j = static_cast<std::size_t>(it - names.begin());
      const double clamped =
          std::clamp(*position, model.limits[j].min_position, model.limits[j].max_position);
      const double record[2] = {static_cast<double>(j), clamped};
      if (!controls.manual_targets.push(record)) {
        return error(res, 409, "too many manual targets waiting for the cycle");
      }
      answer(res, 200, {{"ok", true}, {"position", clamped}});
    });
  }

  void route_steer() {
    control("/api/steer", [this](const json& body, httplib::Response& res) {
      if (!setup.steering) return error(res, 409, "the motion is not steerable");
      const auto speed = number(body, "speed_mps");
      const auto turn = number(body, "turn_rps");
      if (!speed || !turn) {
        return error(res, 400, "expected \"speed_mps\" and \"turn_rps\": finite numbers");
      }
      // Held to the range /api/info gives (the gait would hold it there
      // too), so the state and the answer say what the figure is asked.
      const double max_turn = setup.steering->max_turn_rad_s;
      const MotionCommand held{std::clamp(*speed, 0.0, setup.steering->max_speed_m_s()),
                               std::clamp(*turn, -max_turn, max_turn)};
      controls.steer.post(held);
      answer(res, 200,
             {{"ok", true}, {"speed_mps", held.speed_m_s}, {"turn_rps", held.turn_rad_s}});
    });
  }

  // A show's play, pause or seek.
  void route_show() {
    control("/api/show", [this](const json& body, httplib::Response& res) {
      if (!setup.show) return error(res, 409, "the motion is not a show");
      const auto action = body.find("action");
      const std::string name =
          action != body.end() && action->is_string() ? action->get<std::string>() : "";
      std::optional<double> seek;
      if (name == "seek") {
        seek = number(body, "t_s");
        if (!seek) return error(res, 400, "expected \"t_s\": a finite number of seconds");
        seek = std::clamp(*seek, 0.0, setup.show_duration_s);
      } else if (name != "play" && name != "pause") {
        return error(res, 400, "expected \"action\": \"play\", \"pause\" or \"seek\"");
      }
      if (phase.load(std::memory_order_relaxed) != RunPhaseView::motion) {
        return error(res, 409, "the show plays in the motion phase only");
      }
      if (name != "seek") show.playing = name == "play";
      if (seek) {
        ++show.seeks;
        show.t_s = *seek;
      }
      controls.show.post(show);
      json answer_body = {{"ok", true}};
      if (seek) answer_body["t_s"] = *seek;
      answer(res, 200, answer_body);
    });
  }

  // A replay's seek (no token: a replay controls no robot).
  void route_seek(httplib::Server& server) {
    server.Post("/api/seek", [this](const httplib::Request& req, httplib::Response& res) {
      if (!setup.replay || !setup.seek) return error(res, 409, "not a replay");
      std::string problem;
      const std::optional<json> parsed = DashboardCore::object_body(req.body, problem);
      if (!parsed) return error(res, 400, problem);
      const json& body = *parsed;
      const auto t = number(body, "t_s");
      if (!t) return error(res, 400, "expected \"t_s\": a finite number of seconds");
      const auto playing = body.find("playing");
      if (playing != body.end() && !playing->is_boolean()) {
        return error(res, 400, "expected \"playing\": true or false");
      }
      std::lock_guard lock(controls_mutex);
      setup.seek(*t, playing == body.end() || playing->get<bool>());
      answer(res, 200, {{"ok", true}});
    });
  }
};

DashboardServer::DashboardServer(RunMonitor& monitor, RunControls& controls, DashboardSetup setup)
    : impl_(std::make_unique<Impl>(monitor, controls, std::move(setup))) {
  Impl& m = *impl_;
  if (!(m.setup.rate_hz > 0.0) || !std::isfinite(m.setup.rate_hz)) {
    throw std::invalid_argument("the dashboard rate must be a positive number of Hz");
  }
  m.info = m.build_info();
  if (m.setup.replay) m.recorded_loop = recorded_loop_json(m.setup.replay_times_s);
  m.core.publish(m.build_state());
  m.routes();
  m.core.start();
  m.sampler = std::thread([&m] { m.sample_loop(); });
}

DashboardServer::~DashboardServer() { stop(); }

int DashboardServer::port() const { return impl_->core.port(); }
const std::string& DashboardServer::token() const { return impl_->core.token(); }
std::string DashboardServer::url() const { return impl_->core.url(); }

void DashboardServer::stop() {
  Impl& m = *impl_;
  {
    std::lock_guard lock(m.mutex);
    m.sampler_quit = true;
  }
  m.changed.notify_all();
  if (m.sampler.joinable()) m.sampler.join();  // after its last frame
  m.core.stop();
}

}  // namespace animrt
