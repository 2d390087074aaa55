#pragma once
// A figure held limp for commissioning (calibrate, record): the robot file's
// buses opened and their devices found, torque switched off and kept off,
// the joints' positions read on demand. Nothing here moves a joint.

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "animrt/runtime/figure.hpp"
#include "animrt/runtime/run_controls.hpp"

namespace animrt::cli {

// --port BUS=PATH, repeatable: the bus's port for this command only (the
// robot file is not changed), e.g. a simulator's pseudo-terminal.
struct PortOverrides {
  std::vector<std::string> entries;
  void add_option(CLI::App* cmd);
};

class LimpFigure {
 public:
  // Loads the robot (InputError), opens its buses at their ports (or the
  // overrides) and switches every device's torque off (DeviceError).
  LimpFigure(const std::string& robot_path, const PortOverrides& ports);
  ~LimpFigure();  // torque off again, the buses close

  const RobotConfig& config() const { return figure_->config(); }
  // Positions of every joint (rad, or m), in robot joint order; a joint
  // whose device did not answer keeps its previous value and is not
  // `fresh` (when given). Throws DeviceError for a bus that fails.
  void read(std::vector<double>& joints, std::vector<bool>* fresh = nullptr);
  // As read(), with joint `j`'s own device answered: read again while its
  // answer was lost (late or damaged on a busy line), up to kFreshReads
  // reads, so a position nobody read is never taken for one. Throws
  // DeviceError naming the joint when none came.
  static constexpr int kFreshReads = 5;
  void read_fresh(std::size_t j, std::vector<double>& joints);
  // Joint `j` held by a weak torque (`share` of its servo's current limit)
  // where it is: a hand moves it, and it stays where it is left once write()
  // follows it. False when its servo has no current control (it stays
  // limp). Throws DeviceError.
  bool hold_weakly(std::size_t joint, double share);
  // Goals of the joints held (rad, or m; NaN keeps a goal), in robot joint
  // order. Limp joints take no notice.
  void write(const std::vector<double>& joints);
  // Torque off on every joint again.
  void let_go();
  // Joint `j`'s device homed where it rests, so that its position there
  // reads `ticks` (ActuatorBus::set_home); the position read back, in ticks.
  // Throws DeviceError.
  std::int64_t set_home(std::size_t joint, std::int64_t ticks);

  // The binding of joint `j` and its bus's protocol (null when no bus drives it).
  const ActuatorBinding* binding(std::size_t joint) const;
  std::string protocol(std::size_t joint) const;

 private:
  HardwareBackend backend_;
  std::unique_ptr<Figure> figure_;
  std::vector<std::vector<double>> bus_positions_;
  std::vector<std::vector<double>> bus_goals_;
  std::vector<bool> held_buses_;
};

// The controls that stop signals write while a commissioning command runs.
RunControls& commissioning_controls();

}  // namespace animrt::cli
