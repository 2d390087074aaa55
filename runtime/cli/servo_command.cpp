#include "servo_command.hpp"

#include <iostream>
#include <memory>
#include <string>
#include <utility>

#include "animrt/bridge/commission/servo_setup.hpp"
#include "animrt/core/error.hpp"
#include "option_checks.hpp"
#include "port_check.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

using commission::Family;
using commission::ServoSetup;

struct ServoArgs {
  std::string port;
  std::string protocol;
  int id = -1;
  int baud = 0;  // 0: the family's factory rate
  int timeout_ms = 20;
  int value = 0;
  std::string mode;
  long min_ticks = 0;
  long max_ticks = 0;
  bool yes = false;
};

bool confirmed(const std::string& what) {
  std::cerr << what << " Type y to go on: " << std::flush;
  std::string answer;
  if (!std::getline(std::cin, answer)) return false;
  return answer == "y" || answer == "yes" || answer == "Y";
}

int run_servo(const ServoArgs& args, const std::string& action) {
  const Family family = args.protocol == "dynamixel2" ? Family::dynamixel2 : Family::feetech;
  // Factory rates: Dynamixel X 57600, Feetech STS/SCS 1 Mbaud.
  const int baud = args.baud > 0 ? args.baud : (family == Family::dynamixel2 ? 57600 : 1'000'000);
  // What the command line alone shows wrong is said before the line is
  // opened (an absent servo's "no answer" would hide it).
  const int max_id = ServoSetup::max_id(family);
  if (args.baud < 0) {
    std::cerr << "error: --baud " << args.baud << ": expected a baud rate\n";
    return kExitUsage;
  }
  using Id = std::pair<const char*, int>;
  for (const auto& [what, id] :
       {Id{"--id", args.id}, Id{"set-id: the new id", action == "set-id" ? args.value : 0}}) {
    if (id < 0 || id > max_id) {
      std::cerr << "error: " << what << " " << id << " is outside 0.." << max_id << " ("
                << args.protocol << ")\n";
      return kExitUsage;
    }
  }
  // A port that is no serial port is told so first (open_serial says why).
  open_serial(args.port, 57600).reset();
  if (const std::string busy = port_busy(args.port); !busy.empty()) {
    std::cerr << "error: serial port " << args.port << " is " << busy << "; stop it first\n";
    return kExitDeviceError;
  }
  if (action == "factory-reset" && !args.yes &&
      !confirmed("Factory reset of " + args.protocol + " id " + std::to_string(args.id) + " on " +
                 args.port + ": every setting but id and baud rate goes back to the factory's.")) {
    std::cerr << "error: factory reset not confirmed (answer y, or pass --yes)\n";
    return kExitUsage;
  }
  const std::string port = args.port;
  ServoSetup servo(
      family, [port](int b) { return open_serial(port, b); }, args.id, baud,
      std::chrono::milliseconds(args.timeout_ms));
  std::string done;
  if (action == "set-id") done = servo.set_id(args.value);
  if (action == "set-baud") done = servo.set_baud(args.value);
  if (action == "set-return-delay") done = servo.set_return_delay(args.value);
  if (action == "set-mode") done = servo.set_mode(args.mode);
  if (action == "set-limits") done = servo.set_limits(args.min_ticks, args.max_ticks);
  if (action == "reboot") done = servo.reboot();
  if (action == "factory-reset") done = servo.factory_reset();
  std::cout << done << '\n';
  return kExitOk;
}

}  // namespace

void add_servo_command(CLI::App& app) {
  auto args = std::make_shared<ServoArgs>();
  auto* cmd = app.add_subcommand(
      "servo", "Set up one serial servo: id, baud, return delay, mode, limits, reboot, reset");
  cmd->add_option("PORT", args->port, "serial port")->required();
  cmd->add_option("--protocol", args->protocol, "dynamixel2 or feetech")
      ->required()
      ->check(CLI::IsMember({"dynamixel2", "feetech"}));
  cmd->add_option("--id", args->id, "the servo's id now")->required()->check(kInteger);
  cmd->add_option("--baud", args->baud,
                  "the servo's baud rate now (default the factory's: 57600 Dynamixel, 1000000 "
                  "Feetech)")
      ->check(kInteger);
  cmd->add_option("--timeout-ms", args->timeout_ms, "wait for one answer (default 20)")
      ->check(CLI::Range(1, 1000));
  cmd->require_subcommand(1);

  auto body = [cmd, args](const std::string& action) {
    return [args, action] {
      try {
        return run_servo(*args, action);
      } catch (const DeviceError& e) {
        std::cerr << "error: " << e.what() << '\n';
        return kExitDeviceError;
      }
    };
  };
  auto* set_id = cmd->add_subcommand("set-id", "give the servo a new id (read back at it)");
  set_id->add_option("ID", args->value, "new id")->required()->check(kInteger);
  set_subcommand_body(set_id, body("set-id"));
  auto* set_baud =
      cmd->add_subcommand("set-baud", "change its baud rate (read back at the new one)");
  set_baud->add_option("BAUD", args->value, "new baud rate")->required()->check(kInteger);
  set_subcommand_body(set_baud, body("set-baud"));
  auto* delay = cmd->add_subcommand("set-return-delay", "its Return Delay Time, in microseconds");
  delay->add_option("US", args->value, "microseconds, even, 0..508")->required()->check(kInteger);
  set_subcommand_body(delay, body("set-return-delay"));
  auto* mode = cmd->add_subcommand("set-mode", "its operating mode");
  mode->add_option("MODE", args->mode,
                   "dynamixel2: current, velocity, position, extended-position, "
                   "current-position, pwm; feetech (STS): position, velocity, pwm, step")
      ->required();
  set_subcommand_body(mode, body("set-mode"));
  auto* limits = cmd->add_subcommand("set-limits", "its own position limits, in ticks");
  limits->add_option("MIN", args->min_ticks, "lowest position (ticks)")
      ->required()
      ->check(kInteger);
  limits->add_option("MAX", args->max_ticks, "highest position (ticks)")
      ->required()
      ->check(kInteger);
  set_subcommand_body(limits, body("set-limits"));
  auto* reboot = cmd->add_subcommand("reboot", "restart the servo (Dynamixel)");
  set_subcommand_body(reboot, body("reboot"));
  auto* reset = cmd->add_subcommand(
      "factory-reset", "settings back to the factory's, id and baud rate kept (asks first)");
  reset->add_flag("--yes", args->yes, "do not ask");
  set_subcommand_body(reset, body("factory-reset"));
}

}  // namespace animrt::cli
