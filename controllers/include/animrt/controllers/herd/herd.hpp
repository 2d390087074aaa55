#pragma once
// A herd: every agent of a scene, the groups that steer them, the figures
// that walk them, the navigation mesh they share, stepped at the scene's
// step. Offline (`animrt herd`) it runs as fast as it can; beside a robot
// (`animrt run --herd`) it runs on its own thread and one agent is the
// robot: the herd commands its gait, and its measured pose (from physics)
// replaces that agent's own.

#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "animrt/controllers/herd/agent.hpp"
#include "animrt/controllers/herd/figure.hpp"
#include "animrt/controllers/herd/metrics.hpp"
#include "animrt/controllers/herd/scene.hpp"
#include "animrt/controllers/herd/spatial_grid.hpp"

namespace animrt::herd {

class NavWorld;
class Crowd;

// What the herd needs of a group beyond its steering.
class HerdGroup {
 public:
  virtual ~HerdGroup() = default;
  virtual GroupSteering& steering() = 0;
  // The flock's leader (the point it follows), if it has one.
  virtual std::optional<Vec2> leader() const { return std::nullopt; }
  // Whether member `agent` has reached its goal (crowds).
  virtual bool arrived(int /*agent*/) const { return false; }
  // The fastest member `agent` walks (for its straight-line time).
  virtual double max_speed(int /*agent*/) const { return 0.0; }
};

// A robot file -> the gait file its motion plays (the runtime knows robot
// files; the herd only needs their gait).
using GaitOfRobot = std::function<std::string(const std::string& robot_file)>;

class Herd {
 public:
  // Builds everything the scene names: figures (their gaits' steering and
  // calibration), the navigation mesh, the groups, agents spawned in their
  // areas. Throws InputError at the scene's locations for a spawn area in a
  // wall, a target with no path from the spawn area, a figure whose gait
  // cannot be steered. `seed` overrides the scene's seed when set.
  Herd(HerdScene scene, const GaitOfRobot& gait_of_robot, std::optional<std::uint64_t> seed = {});
  ~Herd();
  Herd(const Herd&) = delete;
  Herd& operator=(const Herd&) = delete;

  const HerdScene& scene() const { return scene_; }
  // What the scene may not do as meant, one line each naming the scene's
  // line and key: a figure whose gait cannot turn (no usable turning walk
  // and no turn on the spot) cannot steer to a target nor mend its drift.
  const std::vector<std::string>& warnings() const { return warnings_; }
  double time() const { return t_; }
  std::span<const Agent> agents() const { return agents_; }
  std::span<const MotionCommand> commands() const { return commands_; }
  const std::string& agent_name(int i) const { return names_[static_cast<std::size_t>(i)]; }
  // "GROUP.INDEX" (e.g. "red.3"); -1 when there is no such agent.
  int find_agent(const std::string& name) const;
  const NavWorld* nav() const { return nav_.get(); }
  std::optional<Vec2> leader(int group) const;
  bool arrived(int agent) const;
  const Figure& figure(int agent) const {
    return figures_[static_cast<std::size_t>(figure_of_[static_cast<std::size_t>(agent)])];
  }

  // One step of scene().step_s: steer every group, command every figure,
  // walk it (an embodied agent is left where set_pose() put it). A figure
  // whose step would take it into another stands still for that step
  // instead (counted as a contact stop).
  void step();
  // The embodied agent: from now on its pose comes from outside.
  void embody(int agent);
  void set_pose(int agent, Vec2 position, double heading, double speed, double turn);

  // Samples the metrics (the CLI calls it at every output step).
  void record_metrics();
  HerdMetrics metrics() const { return recorder_->finish(); }

 private:
  void keep_out_of_walls(Agent& agent) const;

  HerdScene scene_;
  std::vector<std::string> warnings_;
  std::vector<Figure> figures_;
  std::vector<int> figure_of_;          // per agent
  std::vector<double> turning_radius_;  // per figure (figure.hpp)
  // A crowd figure's turning radius (0: it turns on the spot); -1 for a flock's.
  double turning_of(int agent) const;
  std::vector<Agent> agents_;
  std::vector<std::string> names_;
  std::vector<Vec2> desired_;
  std::vector<MotionCommand> commands_;
  std::vector<char> embodied_;
  std::unique_ptr<NavWorld> nav_;
  std::unique_ptr<Crowd> crowd_;  // shared by the crowd groups, outlives them
  std::vector<std::unique_ptr<HerdGroup>> groups_;
  std::unique_ptr<MetricsRecorder> recorder_;
  std::vector<std::optional<Vec2>> leaders_scratch_;
  std::vector<char> arrived_scratch_;
  std::vector<double> max_speed_scratch_;
  SpatialGrid grid_;        // the agents at the start of a step, for the contact guard
  long contact_stops_ = 0;  // figure-steps the contact guard stopped
  double t_ = 0.0;
};

}  // namespace animrt::herd
