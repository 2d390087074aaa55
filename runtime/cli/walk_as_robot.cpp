#include "walk_as_robot.hpp"

#include <algorithm>
#include <cstdio>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"

namespace animrt::cli {

void walk_as_robot(const std::string& robot_file, const evolve::ModelInfo& model,
                   evolve::WalkSettings& settings) {
  const RobotConfig robot = load_robot_config(robot_file);
  settings.joint_limits.clear();
  for (const std::string& name : model.joints) {
    const auto it = std::find_if(robot.joints.begin(), robot.joints.end(),
                                 [&](const JointSpec& j) { return j.name == name; });
    if (it == robot.joints.end()) {
      throw InputError(robot.joints_where, "joints",
                       "no joint " + quote(name) + " of the model (--robot needs them all)");
    }
    settings.joint_limits.push_back(it->limits);
  }
  settings.limits_period_s = 1.0 / robot.rate_hz;
  if (robot.imus.empty()) return;
  // The runtime's reflex reads the trunk's IMU (the first): a new attitude
  // every report, as old as the part reports it.
  const ImuConfig& imu = robot.imus.front();
  settings.balance_period_s = 1.0 / imu.rate_hz;
  settings.balance_delay_s = imu.sim_latency_s > 0.0 ? imu.sim_latency_s : 1.0 / imu.rate_hz;
}

std::string describe_walk_as_robot(const std::string& robot_file,
                                   const evolve::WalkSettings& settings) {
  char line[512];
  int n = std::snprintf(line, sizeof line, "targets played through %s's joint limits at %g Hz",
                        robot_file.c_str(), 1.0 / settings.limits_period_s);
  if (settings.balance_period_s > 0.0 && n > 0 && n < static_cast<int>(sizeof line)) {
    std::snprintf(line + n, sizeof line - n,
                  "; the balance reflex reads the attitude every %g ms, %g ms late",
                  settings.balance_period_s * 1000.0, settings.balance_delay_s * 1000.0);
  }
  return line;
}

}  // namespace animrt::cli
