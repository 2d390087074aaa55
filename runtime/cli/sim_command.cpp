#include "sim_command.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <string>
#include <thread>

#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_loader.hpp"
#include "animrt/runtime/runner.hpp"
#include "animrt/sim/can/can_sim_bus.hpp"
#include "animrt/sim/control_socket.hpp"
#include "animrt/sim/servo_state_file.hpp"
#include "animrt/sim/simulated_backend.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

struct SimArgs {
  std::string config;
  std::string control;    // Unix socket of the control interface
  bool factory = false;   // serial servos at factory settings, one plugged in per bus
  std::string state;      // their EEPROM kept across restarts
  bool any_baud = false;  // servos hear every baud rate (a line that does not carry it)
};

RunControls sim_signal_controls;

int serve_sim(const SimArgs& args) {
  LoadedRobot robot = load_robot(args.config);
  MonotonicClock clock;
  // Served for other programs: CAN devices go on the real interfaces.
  sim::set_can_sim_attach(sim::CanSimAttach::socketcan);
  std::unique_ptr<sim::ServoStateFile> state;  // outlives the buses, which save to it at exit
  if (!args.state.empty()) state = std::make_unique<sim::ServoStateFile>(args.state);
  auto simulated = start_simulated_devices(robot.config.buses, clock, nullptr,
                                           ServoStartup{args.factory, state.get(), args.any_baud});
  // Just below the bus threads of an `animrt run` on this machine (loop 80,
  // buses 79), so a busy host does not make the devices miss their answers.
  for (const std::string& note :
       raise_simulated_devices(simulated, RunOptions{}.realtime_priority - 2)) {
    spdlog::warn("simulated devices: {}", note);
  }
  std::unique_ptr<sim::ControlSocket> control;
  if (!args.control.empty()) {
    sim::NamedBuses named;
    for (std::size_t i = 0; i < simulated.size(); ++i) {
      named.emplace_back(robot.config.buses[i].name, simulated[i].get());
    }
    control = std::make_unique<sim::ControlSocket>(args.control, std::move(named));
  }
  for (const auto& sim : simulated) std::cout << sim->describe() << '\n';
  if (control) std::cout << "control " << control->path() << '\n';
  std::cout << std::flush;
  while (!sim_signal_controls.stop.load())
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  return kExitOk;
}

}  // namespace

void add_sim_command(CLI::App& app) {
  auto a = std::make_shared<SimArgs>();
  auto* sim = app.add_subcommand("sim", "Serve a robot's simulated devices until Ctrl-C");
  sim->add_option("CONFIG", a->config, "robot file (YAML)")->required();
  sim->add_option("--control", a->control,
                  "listen for commands (hand, get, plug, unplug) on this Unix socket "
                  "(docs/cli.md)");
  sim->add_flag("--factory", a->factory,
                "serial servos at factory settings (ID 1; Dynamixel 57600 baud, Feetech 1 Mbaud), "
                "only the first of each bus plugged in");
  sim->add_option("--state", a->state,
                  "keep the serial servos' EEPROM in this file across restarts (read at start, "
                  "written on every change)");
  sim->add_flag("--any-baud", a->any_baud,
                "serial servos answer at any baud rate, not only their own (for a line whose "
                "baud setting does not reach the simulator, e.g. a QEMU-emulated UART)");
  set_subcommand_body(sim, [a] {
    install_stop_signals(sim_signal_controls);
    try {
      return serve_sim(*a);
    } catch (const DeviceError& e) {
      std::cerr << "error: " << e.what() << '\n';
      return kExitDeviceError;
    }
  });
}

}  // namespace animrt::cli
