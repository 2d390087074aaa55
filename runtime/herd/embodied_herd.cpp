#include "animrt/runtime/embodied_herd.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt {

std::string gait_of_robot(const std::string& robot_file) {
  const RobotConfig config = load_robot_config(robot_file);
  if (config.motion.type != "gait") {
    throw InputError(config.motion.where, config.motion.key.empty() ? "motion" : config.motion.key,
                     "a herd figure walks a gait; this robot's motion is " + config.motion.type);
  }
  return config.motion.file;
}

EmbodiedHerd::EmbodiedHerd(const std::string& scene_file, const std::string& agent,
                           const Clock& clock, RunControls& controls, MeasuredTrack measured)
    : clock_(clock), controls_(controls), measured_(std::move(measured)) {
  herd::HerdScene scene = herd::load_herd_scene(scene_file);
  herd_ = std::make_unique<herd::Herd>(std::move(scene), gait_of_robot);
  agent_ = herd_->find_agent(agent);
  if (agent_ < 0) {
    std::string names;
    for (std::size_t g = 0; g < herd_->scene().groups.size(); ++g) {
      names += (g ? ", " : "") + herd_->scene().groups[g].name + ".0";
    }
    throw InputError(
        Location{scene_file, 0, 0}, "--agent",
        "no agent named '" + elide(agent) + "' (agents are GROUP.INDEX, e.g. " + names + ")");
  }
  if (measured_) herd_->embody(agent_);
  const herd::Agent& a = herd_->agents()[static_cast<std::size_t>(agent_)];
  spawn_ = a.position;
  spawn_heading_ = a.heading;
  thread_ = std::thread([this] { loop(); });
}

EmbodiedHerd::~EmbodiedHerd() { stop(); }

void EmbodiedHerd::start(Nanos t0) { t0_.store(t0); }

void EmbodiedHerd::stop() {
  quit_.store(true);
  if (thread_.joinable()) thread_.join();
}

void EmbodiedHerd::loop() {
  try {
    step_until_quit();
  } catch (const std::exception& e) {
    // A herd that cannot go on must not leave the robot walking on its last
    // command or end the program: the figure stands and the run ramps home.
    failure_ = e.what();
    controls_.steer.post(MotionCommand{});
    controls_.stop.store(true);
  }
}

void EmbodiedHerd::step_until_quit() {
  const double dt = herd_->scene().step_s;
  const long steps_per_output = std::max(1L, std::lround(1.0 / (herd_->scene().output_hz * dt)));
  long steps = 0;
  double last_heading = spawn_heading_;
  while (!quit_.load()) {
    const Nanos t0 = t0_.load();
    if (t0 >= 0) {
      const double run_t = to_seconds(clock_.now() - t0);
      while (herd_->time() + dt <= run_t && !quit_.load()) {
        if (measured_) {
          // The trunk's track, turned and moved onto the agent's spawn pose.
          const Track p = measured_();
          const herd::Vec2 ahead = herd::heading_vector(spawn_heading_);
          const herd::Vec2 left{-ahead.y, ahead.x};
          const herd::Vec2 position = spawn_ + ahead * p.x_m + left * p.y_m;
          const double heading = spawn_heading_ + p.yaw_rad;
          // The speed its gait achieves under the herd's last command, not
          // the track's: over one herd step a trot's track jitters by more
          // than the figure's acceleration, and steering ramps the speed
          // from this one.
          const double speed =
              herd_->figure(agent_)
                  .walk.achieved(herd_->commands()[static_cast<std::size_t>(agent_)])
                  .speed_m_s;
          const double turn = std::remainder(heading - last_heading, 2 * M_PI) / dt;
          herd_->set_pose(agent_, position, heading, speed, turn);
          last_heading = heading;
        }
        herd_->step();
        controls_.steer.post(herd_->commands()[static_cast<std::size_t>(agent_)]);
        if (++steps % steps_per_output == 0) herd_->record_metrics();
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

std::string EmbodiedHerd::report() const {
  const herd::Agent& a = herd_->agents()[static_cast<std::size_t>(agent_)];
  std::string s = fmt::format(
      "herd: {:.1f} s stepped; agent {} ({}) walked from ({:.2f}, {:.2f}) to ({:.2f}, {:.2f}) m, "
      "heading "
      "{:.2f} rad, last command {:.3f} m/s, {:.3f} rad/s",
      herd_->time(), herd_->agent_name(agent_),
      measured_ ? "measured by physics" : "as its gait achieves", spawn_.x, spawn_.y, a.position.x,
      a.position.y, a.heading, herd_->commands()[static_cast<std::size_t>(agent_)].speed_m_s,
      herd_->commands()[static_cast<std::size_t>(agent_)].turn_rad_s);
  const auto& group = herd_->scene().groups[static_cast<std::size_t>(a.group)];
  if (group.target_m) {
    s +=
        fmt::format("; distance to its goal {:.2f} -> {:.2f} m",
                    herd::norm(*group.target_m - spawn_), herd::norm(*group.target_m - a.position));
  }
  if (!failure_.empty()) s += "\nherd: stopped the run: " + failure_;
  const herd::HerdMetrics m = herd_->metrics();
  s += fmt::format("\nherd: {} collisions, min clearance {}", m.collisions,
                   m.has_pair ? fmt::format("{:.3f} m", m.min_clearance_m) : std::string("n/a"));
  return s;
}

}  // namespace animrt
