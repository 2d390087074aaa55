#include "limp_figure.hpp"

#include <cmath>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "stop_signals.hpp"

namespace animrt::cli {

void PortOverrides::add_option(CLI::App* cmd) {
  cmd->add_option("--port", entries,
                  "BUS=PATH: open bus BUS at PATH instead of the robot file's port (the file is "
                  "not changed); repeatable");
}

namespace {

void apply_ports(const std::vector<std::string>& entries, RobotConfig& config) {
  for (const std::string& entry : entries) {
    const std::size_t eq = entry.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size()) {
      throw std::invalid_argument("--port " + quote(entry) + ": expected BUS=PATH");
    }
    const std::string name = entry.substr(0, eq);
    for (const std::string& earlier : entries) {
      if (&earlier == &entry) break;
      if (earlier.compare(0, eq + 1, entry, 0, eq + 1) == 0) {
        throw std::invalid_argument("--port " + quote(entry) + ": bus " + quote(name) +
                                    " is given a port twice (also " + quote(earlier) + ")");
      }
    }
    bool found = false;
    for (BusConfig& bus : config.buses) {
      if (bus.name == name) {
        bus.port = entry.substr(eq + 1);
        found = true;
      }
    }
    if (!found) {
      throw std::invalid_argument("--port " + quote(entry) + ": the robot file " +
                                  quote_path(config.file) + " has no bus named " + quote(name));
    }
  }
}

}  // namespace

LimpFigure::LimpFigure(const std::string& robot_path, const PortOverrides& ports) {
  LoadedRobot robot = load_robot(robot_path);
  apply_ports(ports.entries, robot.config);
  figure_ = std::make_unique<Figure>(std::move(robot), backend_);
  bus_positions_.resize(figure_->bus_count());
  for (std::size_t b = 0; b < figure_->bus_count(); ++b) {
    ActuatorBus& bus = figure_->bus(b);
    bus.configure();
    // A servo may power up with its torque on: off before anyone touches it.
    bus.deactivate();
    bus_positions_[b].assign(bus.config().actuators.size(), 0.0);
  }
  bus_goals_ = bus_positions_;
  held_buses_.assign(figure_->bus_count(), false);
}

LimpFigure::~LimpFigure() { let_go(); }

void LimpFigure::let_go() {
  for (std::size_t b = 0; b < figure_->bus_count(); ++b) figure_->bus(b).deactivate();
  held_buses_.assign(figure_->bus_count(), false);
}

bool LimpFigure::hold_weakly(std::size_t joint, double share) {
  for (std::size_t b = 0; b < figure_->bus_count(); ++b) {
    ActuatorBus& bus = figure_->bus(b);
    const auto& actuators = bus.config().actuators;
    for (std::size_t i = 0; i < actuators.size(); ++i) {
      if (actuators[i].joint_index == static_cast<int>(joint)) {
        if (!bus.activate_compliant(i, share)) return false;
        held_buses_[b] = true;
        return true;
      }
    }
  }
  return false;
}

std::int64_t LimpFigure::set_home(std::size_t joint, std::int64_t ticks) {
  for (std::size_t b = 0; b < figure_->bus_count(); ++b) {
    ActuatorBus& bus = figure_->bus(b);
    const auto& actuators = bus.config().actuators;
    for (std::size_t i = 0; i < actuators.size(); ++i) {
      if (actuators[i].joint_index == static_cast<int>(joint)) return bus.set_home(i, ticks);
    }
  }
  throw DeviceError("joint " + config().joints.at(joint).name + ": no bus drives it");
}

void LimpFigure::write(const std::vector<double>& joints) {
  for (std::size_t b = 0; b < figure_->bus_count(); ++b) {
    // Only buses with a joint held: a goal would switch a limp hobby servo's pulse on.
    if (!held_buses_[b]) continue;
    ActuatorBus& bus = figure_->bus(b);
    const auto& actuators = bus.config().actuators;
    for (std::size_t i = 0; i < actuators.size(); ++i) {
      const int j = actuators[i].joint_index;
      const bool known = j >= 0 && static_cast<std::size_t>(j) < joints.size();
      bus_goals_[b][i] = known ? joints[static_cast<std::size_t>(j)] : std::nan("");
    }
    bus.write(bus_goals_[b]);
  }
}

void LimpFigure::read(std::vector<double>& joints, std::vector<bool>* fresh) {
  joints.resize(config().joints.size(), 0.0);
  if (fresh) fresh->assign(joints.size(), false);
  for (std::size_t b = 0; b < figure_->bus_count(); ++b) {
    ActuatorBus& bus = figure_->bus(b);
    bus.read(bus_positions_[b]);
    const auto& actuators = bus.config().actuators;
    const std::span<DeviceStatus> status = bus.devices();
    for (std::size_t i = 0; i < actuators.size(); ++i) {
      const int j = actuators[i].joint_index;
      if (j >= 0 && static_cast<std::size_t>(j) < joints.size()) {
        joints[static_cast<std::size_t>(j)] = bus_positions_[b][i];
        if (fresh && i < status.size()) {
          (*fresh)[static_cast<std::size_t>(j)] = status[i].health == DeviceHealth::ok;
        }
      }
    }
  }
}

void LimpFigure::read_fresh(std::size_t j, std::vector<double>& joints) {
  std::vector<bool> fresh;
  for (int k = 0; k < kFreshReads; ++k) {
    read(joints, &fresh);
    if (fresh.at(j)) return;
  }
  throw DeviceError("joint " + config().joints.at(j).name + ": its device did not answer " +
                    std::to_string(kFreshReads) + " reads of its position in a row");
}

const ActuatorBinding* LimpFigure::binding(std::size_t joint) const {
  for (const BusConfig& bus : config().buses) {
    for (const ActuatorBinding& a : bus.actuators) {
      if (a.joint_index == static_cast<int>(joint)) return &a;
    }
  }
  return nullptr;
}

std::string LimpFigure::protocol(std::size_t joint) const {
  for (const BusConfig& bus : config().buses) {
    for (const ActuatorBinding& a : bus.actuators) {
      if (a.joint_index == static_cast<int>(joint)) return bus.protocol;
    }
  }
  return "";
}

RunControls& commissioning_controls() {
  static RunControls controls;
  return controls;
}

}  // namespace animrt::cli
