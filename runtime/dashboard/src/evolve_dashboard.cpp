// The evolve run's dashboard server (see evolve_dashboard.hpp and
// docs/dashboard.md).

#include "animrt/runtime/evolve_dashboard.hpp"

#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <thread>

#include "animrt/controllers/gait/gait_source.hpp"
#include "animrt/core/joint.hpp"
#include "dashboard_core.hpp"

namespace animrt {
namespace {

using nlohmann::json;
using SteadyClock = std::chrono::steady_clock;

json generation_json(const evolve::GenerationStats& s) {
  return {{"generation", s.generation},
          {"best", nullable(s.best)},
          {"average", nullable(s.average)},
          {"stddev", nullable(s.stddev)},
          {"invalid", s.invalid},
          {"fell", s.fell},
          {"evaluations", s.evaluations},
          {"seconds", nullable(s.seconds)}};
}

// The best gait so far, as the search's thread hands it over.
struct BestGait {
  int generation = 0;
  double fitness = 0.0;
  std::string phenotype;
  evolve::GaitMeasures measures;
  GaitFile gait;
};

json best_json(const BestGait& b) {
  const evolve::GaitMeasures& m = b.measures;
  return {{"generation", b.generation},
          {"fitness", nullable(b.fitness)},
          {"fell", m.fell},
          {"speed_mps", nullable(m.speed)},
          {"stride_m", nullable(m.stride_length)},
          {"duty_factor", nullable(m.duty_factor)},
          {"energy_j", nullable(m.energy_per_cycle)},
          {"stride_hz", nullable(b.gait.stride_frequency())},
          {"phenotype", b.phenotype}};
}

}  // namespace

struct EvolveDashboardServer::Impl {
  EvolveDashboardSetup setup;
  DashboardCore core;
  std::string info;  // /api/info, built once
  std::thread sampler;
  const SteadyClock::time_point started = SteadyClock::now();
  std::atomic<bool> stop_requested{false};

  // Shared between the search's thread, the sampler and the handlers.
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<json> history;               // one entry per generation, in order
  std::shared_ptr<const BestGait> best;    // the best so far (null: none valid yet)
  std::uint64_t best_version = 0;          // bumped with every new best
  SteadyClock::time_point generation_started = started;
  bool ended = false;  // finish(): the sampler publishes a last frame and ends
  bool stopped = false;
  bool finished = false;

  // The sampler's own: the gait it plays.
  std::uint64_t playing_version = 0;
  std::unique_ptr<MotionSource> source;
  double period_s = 1.0;
  SteadyClock::time_point play_started = started;
  std::vector<JointSpec> specs;
  std::vector<double> angles;
  std::vector<BodyPose> bodies;
  std::string play_error;  // why the best gait does not play ("" when it does)

  explicit Impl(EvolveDashboardSetup s)
      : setup(std::move(s)),
        core(DashboardListen{setup.host, setup.port, setup.remote, setup.www_dir, setup.lib_dir}) {
    for (const std::string& name : setup.joints) {
      JointSpec spec;
      spec.name = name;
      spec.limits = {-kPi, kPi, 100.0, 10000.0};  // as the evolver binds its gaits
      specs.push_back(spec);
    }
    angles.assign(specs.size(), 0.0);
    if (setup.figure) bodies.resize(setup.figure->bodies().size());
  }

  std::string build_info() const {
    json figure = nullptr;
    if (setup.figure) {
      json list = json::array();
      for (const FigureBody& body : setup.figure->bodies()) {
        json geoms = json::array();
        for (const FigureGeom& g : body.geoms) {
          geoms.push_back({{"type", g.type},
                           {"size", g.size},
                           {"pos", g.pos},
                           {"quat", g.quat},
                           {"rgba", g.rgba}});
        }
        list.push_back({{"name", body.name}, {"parent", body.parent}, {"geoms", geoms}});
      }
      figure = {{"bodies", list}};
    }
    return json{{"kind", "evolve"},
                {"name", setup.name},
                {"run_file", setup.run_file},
                {"grammar", setup.grammar},
                {"model_file", setup.model_file},
                {"population", setup.population},
                {"generations", setup.generations},
                {"seed", setup.seed},
                {"workers", setup.workers},
                {"rate_hz", setup.rate_hz},
                {"joints", setup.joints},
                {"model", figure},
                {"replay", false}}
        .dump();
  }

  // Binds a new best gait for playing (the sampler's thread: compiling
  // the gait's expressions is never the search's cost).
  void play(const BestGait& b) {
    try {
      source = make_gait_source(b.gait, specs);
      const double f = b.gait.stride_frequency();
      period_s = f > 0.0 && std::isfinite(f) ? 1.0 / f : 1.0;
      play_error.clear();
    } catch (const std::exception& e) {
      source.reset();
      play_error = e.what();
    }
    play_started = SteadyClock::now();
  }

  std::string build_state() {
    std::shared_ptr<const BestGait> b;
    std::uint64_t version = 0;
    json last = nullptr;
    std::size_t completed = 0;
    bool is_ended = false, is_stopped = false;
    SteadyClock::time_point since;
    {
      std::lock_guard lock(mutex);
      b = best;
      version = best_version;
      completed = history.size();
      if (!history.empty()) last = history.back();
      is_ended = ended;
      is_stopped = stopped;
      since = generation_started;
    }
    if (b && version != playing_version) {
      playing_version = version;
      play(*b);
    }
    const auto now = SteadyClock::now();
    const double t_s = std::chrono::duration<double>(now - started).count();
    double gait_t = 0.0;
    if (source) {
      gait_t = std::fmod(std::chrono::duration<double>(now - play_started).count(), period_s);
      source->sample(gait_t, angles);
    }
    const char* phase = is_ended                  ? "ended"
                        : stop_requested.load()   ? "stopping"
                                                  : "running";
    const int last_number = setup.generations;
    json frame = {
        {"t_s", t_s},
        {"phase", phase},
        {"stopped", is_stopped},
        {"generation", completed ? json(static_cast<int>(completed) - 1) : json(nullptr)},
        {"generations", last_number},
        {"completed", completed},
        {"evaluating", !is_ended && static_cast<int>(completed) <= last_number
                           ? json(static_cast<int>(completed))
                           : json(nullptr)},
        {"generation_elapsed_s",
         is_ended ? json(nullptr) : json(std::chrono::duration<double>(now - since).count())},
        {"last", last},
        {"best", b ? best_json(*b) : json(nullptr)},
        {"playback",
         source ? json{{"t_s", gait_t}, {"period_s", period_s}, {"angles", angles}}
                : json(nullptr)},
        {"play_error", play_error.empty() ? json(nullptr) : json(play_error)}};
    if (setup.figure && source) {
      setup.figure->pose(angles, bodies);
      json measured = json::array();
      for (const BodyPose& p : bodies) measured.push_back({{"pos", p.pos}, {"quat", p.quat}});
      frame["bodies"] = {{"measured", measured}};
    }
    return frame.dump();
  }

  void sample_loop() {
    const auto period = std::chrono::duration<double>(1.0 / setup.rate_hz);
    auto next = SteadyClock::now();
    for (bool last = false;;) {
      core.publish(build_state());
      std::unique_lock lock(mutex);
      if (last) return;
      next += std::chrono::duration_cast<SteadyClock::duration>(period);
      last = changed.wait_until(lock, next, [this] { return ended; });
    }
  }

  // GET /api/state: the frame with every generation so far.
  std::string state_with_history(const std::string& frame) {
    json all = json::array();
    {
      std::lock_guard lock(mutex);
      all = history;
    }
    if (frame.size() < 2 || frame.back() != '}') return frame;
    std::string out = frame;
    out.pop_back();
    out += ",\"history\":" + all.dump() + "}";
    return out;
  }

  void routes() {
    httplib::Server& server = core.server();
    server.Get("/api/info", [this](const httplib::Request&, httplib::Response& res) {
      res.set_content(info, "application/json");
    });
    // Generations from `from` on (the page's curves catch up with this).
    server.Get("/api/history", [this](const httplib::Request& req, httplib::Response& res) {
      std::size_t from = 0;
      if (req.has_param("from")) {
        const std::string text = req.get_param_value("from");
        if (text.empty() || text.size() > 9 ||
            !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; })) {
          return DashboardCore::error(res, 400, "expected from=N, a generation count");
        }
        from = static_cast<std::size_t>(std::stoul(text));
      }
      json list = json::array();
      {
        std::lock_guard lock(mutex);
        for (std::size_t i = from; i < history.size(); ++i) list.push_back(history[i]);
      }
      DashboardCore::answer(res, 200, {{"from", from}, {"generations", list}});
    });
    core.state_from([this](const std::string& frame) { return state_with_history(frame); });
    core.control("/api/stop", [this](const json&, httplib::Response& res) {
      stop_requested = true;
      DashboardCore::answer(res, 200, {{"ok", true}});
    });
    for (const char* path : {"/api/manual", "/api/jog", "/api/steer", "/api/show", "/api/seek"}) {
      core.refuse(path, "an evolve run has no such control");
    }
  }
};

EvolveDashboardServer::EvolveDashboardServer(EvolveDashboardSetup setup)
    : impl_(std::make_unique<Impl>(std::move(setup))) {
  Impl& m = *impl_;
  if (!(m.setup.rate_hz > 0.0) || !std::isfinite(m.setup.rate_hz)) {
    throw std::invalid_argument("the dashboard rate must be a positive number of Hz");
  }
  m.info = m.build_info();
  m.core.publish(m.build_state());
  m.routes();
  m.core.start();
  m.sampler = std::thread([&m] { m.sample_loop(); });
}

EvolveDashboardServer::~EvolveDashboardServer() { stop(); }

int EvolveDashboardServer::port() const { return impl_->core.port(); }
const std::string& EvolveDashboardServer::token() const { return impl_->core.token(); }
std::string EvolveDashboardServer::url() const { return impl_->core.url(); }

void EvolveDashboardServer::publish(const evolve::GenerationStats& stats,
                                    const evolve::Individual& best) {
  Impl& m = *impl_;
  json entry = generation_json(stats);
  // A copy of the gait only when it is the best so far.
  std::shared_ptr<const BestGait> better;
  {
    std::lock_guard lock(m.mutex);
    const bool improves =
        best.valid && std::isfinite(best.fitness) && (!m.best || best.fitness < m.best->fitness);
    if (!improves) {
      m.history.push_back(std::move(entry));
      m.generation_started = SteadyClock::now();
      return;
    }
  }
  // Built outside the lock (the search's thread is the only writer).
  better = std::make_shared<const BestGait>(
      BestGait{stats.generation, best.fitness, best.phenotype, best.measures, best.gait});
  std::lock_guard lock(m.mutex);
  m.history.push_back(std::move(entry));
  m.generation_started = SteadyClock::now();
  m.best = std::move(better);
  ++m.best_version;
}

bool EvolveDashboardServer::stop_requested() const { return impl_->stop_requested.load(); }

void EvolveDashboardServer::finish(bool stopped, bool keep_serving) {
  Impl& m = *impl_;
  {
    std::lock_guard lock(m.mutex);
    if (m.finished) return;
    m.finished = true;
    m.ended = true;
    m.stopped = stopped;
  }
  m.changed.notify_all();
  if (m.sampler.joinable()) m.sampler.join();  // after its last frame
  if (!keep_serving) m.core.stop();
}

void EvolveDashboardServer::stop() {
  finish(false);
  impl_->core.stop();  // idempotent
}

}  // namespace animrt
