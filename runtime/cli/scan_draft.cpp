#include "scan_draft.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "animrt/core/input_file.hpp"

namespace animrt::cli {
namespace {

namespace fs = std::filesystem;
using commission::FoundDevice;

void write_file(const fs::path& path, const std::string& text) {
  check_replaceable_file(path.string());  // renamed over: never over a device
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text;
    out.flush();
    if (!out) {
      const int error = errno;
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("--write-robot: cannot write " + tmp.string() + ": " +
                               std::strerror(error));
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("--write-robot: cannot write " + path.string() + ": " + ec.message());
  }
}

std::string fixed1(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

bool is_servo(const FoundDevice& d) { return d.protocol != "maestro"; }

// Servos that answered with their limits, counted by protocol and baud.
using DraftBusCounts = std::map<std::pair<std::string, int>, int>;

DraftBusCounts count_draft_buses(const commission::ScanResult& found) {
  DraftBusCounts groups;
  for (const FoundDevice& d : found.devices) {
    if (is_servo(d) && d.min_limit && d.max_limit) ++groups[{d.protocol, d.baud}];
  }
  if (groups.empty()) {
    throw std::runtime_error("--write-robot: no servo answered with its limits; nothing to draft");
  }
  return groups;
}

DraftBusCounts::const_iterator choose_draft_bus(const DraftBusCounts& groups) {
  auto best = groups.begin();
  for (auto it = groups.begin(); it != groups.end(); ++it) {
    // The most servos; of equals, the fastest line.
    if (it->second > best->second ||
        (it->second == best->second && it->first.second > best->first.second)) {
      best = it;
    }
  }
  return best;
}

// The comments on what to check, the name, the loop and the safety section.
void put_draft_header(std::ostream& y, const std::string& port, const std::string& stem,
                      long rate_hz, int baud) {
  y << "# Drafted by `animrt scan " << port << " --write-robot` from the devices that\n"
    << "# answered. Check before the first run:\n"
    << "#  - joint names: each joint is named after its servo's id; rename them;\n"
    << "#  - zero_ticks (the middle of each servo's own limits here) and direction:\n"
    << "#    `animrt calibrate` measures them, or set them by hand;\n"
    << "#  - limits: taken from each servo's limit registers, which are often the\n"
    << "#    whole turn; narrow them to what the mechanics allow;\n"
    << "#  - velocity and acceleration limits: deliberately slow defaults.\n"
    << "name: " << (stem.empty() ? "draft" : stem) << "\n\n"
    << "loop:\n  rate_hz: " << rate_hz << "   # what " << baud
    << " baud allows for these servos; a higher baud allows a faster loop\n\n"
    << "safety:\n  watchdog_timeout_s: " << fixed1(std::max(0.1, std::ceil(30.0 / rate_hz) / 10.0))
    << (rate_hz < 5 ? "\n  following_error_window_s: " + fixed1(std::ceil(30.0 / rate_hz) / 10.0)
                    : std::string())
    << "\n  start_ramp_s: 2.0\n  stop_ramp_s: 2.0\n\n";
}

// The one bus, and as comments the devices left off it.
void put_draft_bus(std::ostream& y, const std::string& port, const commission::ScanResult& found,
                   const DraftBusCounts& groups, DraftBusCounts::const_iterator best) {
  const auto& [protocol, baud] = best->first;
  y << "buses:\n  bus0:\n"
    << "    protocol: " << protocol << "\n"
    << "    port: " << port << "   # a /dev/serial/by-id/... link survives replugging\n"
    << "    baud: " << baud << "\n    timeout_ms: 10\n";
  for (const auto& [key, count] : groups) {
    if (key == best->first) continue;
    y << "    # also found: " << count << " " << key.first << " servo(s) at " << key.second
      << " baud; move them to " << baud << " with `animrt servo ... set-baud " << baud
      << "` and add them here\n";
  }
  for (const FoundDevice& d : found.devices) {
    if (d.protocol == "maestro") {
      y << "    # also found: a Maestro at " << d.baud
        << " baud; it needs a bus of its own (protocol: maestro) and its channels by hand\n";
    }
  }
  for (const commission::Collision& c : found.collisions) {
    y << "    # left out: id " << c.id << " at " << c.baud << " baud (" << c.how
      << "): plug in one servo at a time and give each its own id\n";
  }
}

// A joint per servo on the bus, and its keys in the hold show. Returns the
// number of joints.
int put_draft_joints(std::ostream& y, std::ostream& keys, const commission::ScanResult& found,
                     const std::string& protocol, int baud) {
  y << "\njoints:\n";
  int joints = 0;
  for (const FoundDevice& d : found.devices) {
    if (d.protocol != protocol || d.baud != baud || !d.min_limit || !d.max_limit) continue;
    const double tpr = d.ticks_per_rev.value_or(4096.0);
    const long zero = std::lround((*d.min_limit + *d.max_limit) / 2.0);
    // Rounded inwards: a limit past what the servo's own limits allow is refused.
    const double min_deg = std::ceil((*d.min_limit - zero) * 3600.0 / tpr) / 10.0;
    const double max_deg = std::floor((*d.max_limit - zero) * 3600.0 / tpr) / 10.0;
    if (!(max_deg > min_deg)) {
      // Limits a tenth of a degree apart or crossed (or a Feetech's 0 and
      // 0, wheel mode): no joint a robot file takes.
      y << "  # left out: id " << d.id << " (" << d.model << "): its limit registers ("
        << *d.min_limit << " and " << *d.max_limit
        << " ticks) leave no travel; set them with `animrt servo ... set-limits` and scan again\n";
      continue;
    }
    const std::string name = "id" + std::to_string(d.id);
    y << "  " << name << ":   # " << d.model;
    if (d.position) y << ", at " << *d.position << " ticks when scanned";
    if (d.multi_turn) {
      y << "\n    # multi_turn: found in extended position mode (Operating Mode 4):\n"
        << "    # it counts +-256 turns and its limit registers bound nothing; set the\n"
        << "    # limits to what the joint allows. `animrt calibrate` sets its home.";
    }
    y << "\n    limits: {min_deg: " << fixed1(min_deg) << ", max_deg: " << fixed1(max_deg)
      << ", velocity_dps: 60, acceleration_dps2: 300}\n"
      << "    home_deg: 0\n"
      << "    actuator: {bus: bus0, id: " << d.id;
    if (protocol != "feetech_scs") y << ", ticks_per_rev: " << static_cast<long>(tpr);
    y << ", zero_ticks: " << zero << ", direction: 1" << (d.multi_turn ? ", multi_turn: true" : "")
      << "}\n";
    keys << "  " << name << ":\n    keys:\n      - [0.0, 0]\n      - [1.0, 0]\n";
    ++joints;
  }
  return joints;
}

}  // namespace

int write_robot_draft(const std::string& path, const std::string& port,
                      const commission::ScanResult& found) {
  // One bus per port: the protocol and baud with the most servos; the
  // others are listed for the user to move there.
  const DraftBusCounts groups = count_draft_buses(found);
  const auto best = choose_draft_bus(groups);
  const auto [protocol, baud] = best->first;

  // A loop the line can keep up with: about 24 bytes per servo and cycle
  // (its goal out, its position in), with a fifth to spare.
  const int servos = best->second;
  const long rate_hz =
      std::clamp(std::lround(std::floor(0.8 * baud / (240.0 * servos + 100.0))), 1L, 100L);
  const fs::path robot(path);
  const std::string stem = robot.stem().string();
  const fs::path show = robot.parent_path() / (stem + ".hold.yaml");

  std::ostringstream y;
  put_draft_header(y, port, stem, rate_hz, baud);
  put_draft_bus(y, port, found, groups, best);
  std::ostringstream keys;
  const int joints = put_draft_joints(y, keys, found, protocol, baud);
  if (joints == 0) {
    throw std::runtime_error(
        "--write-robot: no servo's limit registers leave it any travel; nothing to draft");
  }
  y << "\n# Holds every joint at its home pose: replace with the figure's motion.\n"
    << "motion:\n  type: show\n  file: " << show.filename().string() << "\n";

  std::ostringstream s;
  s << "# Holds every joint of " << robot.filename().string() << " at 0 deg (its home pose).\n"
    << "name: hold\nloop: false\nduration_s: 1.0\njoints:\n"
    << keys.str();
  write_file(show, s.str());
  write_file(robot, y.str());
  return joints;
}

}  // namespace animrt::cli
