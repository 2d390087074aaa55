#include "scan_command.hpp"

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "animrt/bridge/commission/can_scan.hpp"
#include "animrt/bridge/commission/modbus_scan.hpp"
#include "animrt/bridge/commission/serial_scan.hpp"
#include "animrt/core/error.hpp"
#include "option_checks.hpp"
#include "port_check.hpp"
#include "scan_draft.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
namespace {

using commission::FoundDevice;
using commission::ScanLimits;
using commission::ScanResult;

struct ScanArgs {
  std::string port;
  std::string can;  // --can IFACE
  int listen_ms = 1200;
  std::vector<std::string> protocols;
  std::vector<int> bauds;
  std::string ids = "0-252";
  int timeout_ms = 10;
  std::string write_robot;
  char parity = 'E';  // Modbus RTU: the standard's default, even
};

constexpr const char* kProtocols[] = {"maestro", "dynamixel2", "feetech", "modbus-rtu"};

std::string opt(const std::optional<double>& v, const char* format) {
  if (!v) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, *v);
  return text;
}

void print_table(const std::string& port, const ScanResult& result) {
  const std::vector<std::string> head = {"bus",       "protocol", "baud",     "id",
                                         "model",     "firmware", "position", "temp_C",
                                         "voltage_V", "torque",   "note"};
  std::vector<std::vector<std::string>> rows;
  for (const FoundDevice& d : result.devices) {
    rows.push_back(
        {port, d.protocol, d.baud > 0 ? std::to_string(d.baud) : "-", std::to_string(d.id),
         d.model.empty() ? "-" : d.model, d.firmware.empty() ? "-" : d.firmware,
         d.position ? std::to_string(*d.position) : "-", opt(d.temperature_c, "%.0f"),
         opt(d.voltage_v, "%.1f"), d.torque_on ? (*d.torque_on ? "on" : "off") : "-", d.note});
  }
  std::vector<std::size_t> width(head.size());
  for (std::size_t c = 0; c < head.size(); ++c) {
    width[c] = head[c].size();
    for (const auto& r : rows) width[c] = std::max(width[c], r[c].size());
  }
  auto line = [&](const std::vector<std::string>& r) {
    std::string out;
    for (std::size_t c = 0; c < r.size(); ++c) {
      out += r[c];
      if (c + 1 < r.size()) out += std::string(width[c] - r[c].size() + 2, ' ');
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    std::cout << out << '\n';
  };
  line(head);
  for (const auto& r : rows) line(r);
}

// "A-B" or "A": the ids asked where ids are asked one by one, and the
// highest id a broadcast ping waits for.
bool parse_ids(const std::string& text, int& first, int& last) {
  const auto dash = text.find('-');
  const std::string a = text.substr(0, dash);
  const std::string b = dash == std::string::npos ? a : text.substr(dash + 1);
  auto number = [](const std::string& s, int& out) {
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
    return ec == std::errc() && end == s.data() + s.size() && !s.empty();
  };
  return number(a, first) && number(b, last) && first >= 0 && first <= last && last <= 253;
}

bool wanted(const ScanArgs& args, const std::string& protocol) {
  return args.protocols.empty() ||
         std::find(args.protocols.begin(), args.protocols.end(), protocol) != args.protocols.end();
}

std::vector<int> bauds_for(const ScanArgs& args, const std::vector<int>& standard) {
  if (args.bauds.empty()) return standard;
  std::vector<int> out;
  for (int b : args.bauds) {
    if (std::find(standard.begin(), standard.end(), b) != standard.end()) out.push_back(b);
  }
  return out;
}

void report(const ScanArgs& args, const ScanResult& result, bool maestro_line) {
  if (result.devices.empty() && result.collisions.empty()) {
    std::cout << args.port << ": no device answered\n";
  } else {
    print_table(args.port, result);
  }
  for (const commission::Collision& c : result.collisions) {
    std::cout << "collision: " << c.protocol << " id " << c.id << " at " << c.baud
              << " baud: " << c.how
              << " (several servos share this id: plug in one at a time and give each its own "
                 "id with `animrt servo`)\n";
  }
  for (const std::string& g : result.garbled) {
    std::cout << "garbage: " << g
              << " (a device of another protocol or baud rate, or noise on the line)\n";
  }
  if (maestro_line) {
    std::cout << args.port << ": a Maestro answered, so no servo protocol was tried on it\n";
  }
  if (!args.write_robot.empty()) {
    const int joints = write_robot_draft(args.write_robot, args.port, result);
    std::cout << "wrote " << args.write_robot << " (" << joints
              << " joints; read its comments before the first run)\n";
  }
}

// CANopen: heartbeats, then SDO reads of each node that answered.
int scan_can_bus(const ScanArgs& args, ScanLimits& limits, ScanResult& result) {
  limits.progress = [](const std::string& line) { std::cerr << "scan: " << line << '\n'; };
  std::cerr << "scan " << args.can << ": listening " << args.listen_ms
            << " ms for heartbeats, then SDO reads of 0x1000 and 0x1018...\n";
  commission::scan_canopen(args.can, std::chrono::milliseconds(args.listen_ms), limits, result);
  ScanArgs shown = args;
  shown.port = args.can;
  report(shown, result, false);
  return kExitOk;
}

// Modbus TCP: unit ids behind one address.
int scan_tcp_units(const ScanArgs& args, const ScanLimits& limits, ScanResult& result) {
  std::cerr << "scan " << args.port << ": modbus-tcp unit ids " << std::max(limits.first_id, 1)
            << "-" << std::min(limits.last_id, 247) << "...\n";
  commission::scan_modbus_tcp(args.port.substr(6), limits, result);
  report(args, result, false);
  return kExitOk;
}

struct ScanStep {
  std::string protocol;
  int baud;
};

// Each protocol at each of its bauds (Maestro first: once a Maestro
// answers, no servo packet goes on its line, since it would read their
// bytes as Mini SSC commands and move a channel).
std::vector<ScanStep> serial_scan_steps(const ScanArgs& args) {
  std::vector<ScanStep> steps;
  for (const char* p : kProtocols) {
    if (!wanted(args, p)) continue;
    const std::string name = p;
    const std::vector<int>& standard = name == "maestro"      ? commission::maestro_bauds()
                                       : name == "dynamixel2" ? commission::dynamixel_bauds()
                                       : name == "feetech"    ? commission::feetech_bauds()
                                                              : commission::modbus_rtu_bauds();
    for (int b : bauds_for(args, standard)) steps.push_back({p, b});
  }
  return steps;
}

// Runs the steps on the serial port; returns whether a Maestro answered.
bool run_serial_scan_steps(const ScanArgs& args, const std::vector<ScanStep>& steps,
                           const ScanLimits& limits, ScanResult& result) {
  bool maestro_line = false;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const ScanStep& step = steps[i];
    if (maestro_line && step.protocol != "maestro") continue;
    if (!carries_baud(args.port, step.baud)) {
      std::cerr << "scan " << args.port << ": [" << (i + 1) << "/" << steps.size() << "] "
                << step.protocol << " at " << step.baud
                << " baud skipped: a pseudo-terminal cannot be set to that rate\n";
      continue;
    }
    std::cerr << "scan " << args.port << ": [" << (i + 1) << "/" << steps.size() << "] "
              << step.protocol << " at " << step.baud << " baud...\n";
    if (step.protocol == "modbus-rtu") {
      if (!maestro_line)
        commission::scan_modbus_rtu(args.port, step.baud, args.parity, limits, result);
      continue;
    }
    std::unique_ptr<ByteTransport> line = open_serial(args.port, step.baud);
    if (step.protocol == "maestro") {
      maestro_line = commission::scan_maestro(*line, step.baud, limits, result) || maestro_line;
    } else if (step.protocol == "dynamixel2") {
      commission::scan_dynamixel(*line, step.baud, limits, result);
    } else {
      commission::scan_feetech(*line, step.baud, limits, result);
    }
    if (line->failure() != nullptr) throw DeviceError(describe_failure(*line));
  }
  return maestro_line;
}

int scan_serial_port(const ScanArgs& args, const ScanLimits& limits, ScanResult& result) {
  // A port that is no serial port is told so first (open_serial says why).
  open_serial(args.port, 57600).reset();
  if (const std::string busy = port_busy(args.port); !busy.empty()) {
    std::cerr << "error: serial port " << args.port << " is " << busy
              << "; stop it first (two programs on one bus garble each other)\n";
    return kExitDeviceError;
  }
  const std::vector<ScanStep> steps = serial_scan_steps(args);
  if (steps.empty()) {
    std::cerr << "error: --baud: none of the given rates is a standard rate of the protocols "
                 "asked\n";
    return kExitUsage;
  }
  const auto started = std::chrono::steady_clock::now();
  const bool maestro_line = run_serial_scan_steps(args, steps, limits, result);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::cerr << "scan " << args.port << ": done in " << opt(seconds, "%.1f") << " s, "
            << result.devices.size() << " device(s), " << result.collisions.size()
            << " collision(s)\n";
  report(args, result, maestro_line);
  return kExitOk;
}

int run_scan(const ScanArgs& args) {
  ScanLimits limits;
  if (!parse_ids(args.ids, limits.first_id, limits.last_id)) {
    std::cerr << "error: --ids: expected FIRST-LAST within 0-253, found \"" << args.ids << "\"\n";
    return kExitUsage;
  }
  limits.answer_timeout = std::chrono::milliseconds(args.timeout_ms);
  ScanResult result;
  if (!args.can.empty()) return scan_can_bus(args, limits, result);
  if (args.port.empty()) {
    std::cerr << "error: give a serial PORT, tcp://HOST:PORT or --can IFACE\n";
    return kExitUsage;
  }
  if (args.port.rfind("tcp://", 0) == 0) return scan_tcp_units(args, limits, result);
  return scan_serial_port(args, limits, result);
}

}  // namespace

void add_scan_command(CLI::App& app) {
  auto args = std::make_shared<ScanArgs>();
  auto* cmd = app.add_subcommand(
      "scan", "Find the devices on a serial port with safe queries (nothing moves)");
  cmd->add_option("PORT", args->port,
                  "serial port (e.g. /dev/ttyUSB0), or tcp://HOST:PORT for Modbus TCP");
  cmd->add_option("--can", args->can,
                  "CAN interface (e.g. can0): CANopen heartbeats and SDO reads instead of a port");
  cmd->add_option("--listen-ms", args->listen_ms,
                  "with --can: how long to listen for heartbeats (default 1200)")
      ->check(CLI::Range(0, 60000));
  cmd->add_option("--protocol", args->protocols,
                  "protocols to try on a serial port (default all): maestro, dynamixel2, feetech, "
                  "modbus-rtu")
      ->delimiter(',')
      ->check(CLI::IsMember({"maestro", "dynamixel2", "feetech", "modbus-rtu"}));
  cmd->add_option("--baud", args->bauds,
                  "baud rates to try (default each protocol's standard ones)")
      ->delimiter(',');
  cmd->add_option("--ids", args->ids,
                  "ids asked (FIRST-LAST, default 0-252); a smaller range scans faster");
  cmd->add_option("--timeout-ms", args->timeout_ms, "wait for one answer (default 10)")
      ->check(CLI::Range(1, 1000));
  cmd->add_option_function<std::string>(
         "--parity",
         [args](const std::string& p) {
           args->parity = p == "none" ? 'N' : p == "odd" ? 'O' : 'E';
         },
         "Modbus RTU parity: even (the default, as the standard's), odd or none")
      ->check(CLI::IsMember({"even", "odd", "none"}));
  cmd->add_option("--write-robot", args->write_robot,
                  "draft a robot file from what was found (and a hold-still show beside it)")
      ->check(kOutputFile);
  set_subcommand_body(cmd, [args] {
    try {
      return run_scan(*args);
    } catch (const DeviceError& e) {
      std::cerr << "error: " << e.what() << '\n';
      return kExitDeviceError;
    }
  });
}

}  // namespace animrt::cli
