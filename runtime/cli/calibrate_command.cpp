#include "calibrate_command.hpp"

#include <fmt/format.h>
#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/dynamixel/x_models.hpp"
#include "animrt/core/error.hpp"
#include "animrt/runtime/robot_config.hpp"
#include "animrt/runtime/yaml_value_editor.hpp"
#include "limp_figure.hpp"
#include "option_checks.hpp"
#include "stop_signals.hpp"
#include "subcommand.hpp"

namespace animrt::cli {
// Named, so that the unity build's other commands do not share these names.
namespace calibrate_cmd {

struct CalibrateArgs {
  std::string robot;
  std::vector<std::string> joints;
  bool non_interactive = false;
  double seconds_per_joint = 10.0;
  double min_range_deg = 2.0;
  PortOverrides ports;
  int jog = -1;  // --jog 1, --no-jog 0; -1: asked (interactive), none (non-interactive)
  double jog_deg = 5.0;
  double jog_percent = 10.0;
  bool yes = false;  // moves agreed beforehand (a homing search on switches)
};

// What one joint's calibration saw, in the servo's own ticks (so that the
// file's present zero_ticks and direction do not matter), unwrapped: a
// servo that reports one turn (0..4095) jumps by a turn where its shaft
// crosses the seam, and no hand turns a joint half a turn in one read.
struct Seen {
  double min_ticks = std::numeric_limits<double>::infinity();
  double max_ticks = -std::numeric_limits<double>::infinity();
  double home_ticks = 0.0;
  int direction = 1;
  double turn = 4096.0;  // the servo's ticks per turn of its shaft
  double last_raw = std::numeric_limits<double>::quiet_NaN();
  double unwrap = 0.0;  // whole turns added to the raw ticks
  void add(double raw) {
    if (!std::isnan(last_raw)) {
      if (raw - last_raw > turn / 2) unwrap -= turn;
      if (raw - last_raw < -turn / 2) unwrap += turn;
    }
    last_raw = raw;
    const double ticks = raw + unwrap;
    min_ticks = std::min(min_ticks, ticks);
    max_ticks = std::max(max_ticks, ticks);
    home_ticks = ticks;
  }
  // Whole turns off, so the home is one the servo reports; false when the
  // range then crosses the seam (the servo cannot be driven across it in
  // position mode).
  bool within_one_turn() {
    const double shift = std::floor(home_ticks / turn) * turn;
    min_ticks -= shift;
    max_ticks -= shift;
    home_ticks -= shift;
    return min_ticks >= 0 && max_ticks <= turn - 1;
  }
};

// Ticks per turn of a servo's shaft, as it reports its position.
double ticks_per_turn(const std::string& protocol) {
  return protocol == "feetech_scs" ? 1024.0 : 4096.0;
}

// The servo ticks of a joint position as the file maps them today.
double raw_ticks(const ActuatorBinding& a, double position) {
  return a.zero_ticks + a.direction * position * a.ticks_per_rad;
}

double ticks_to_deg(const ActuatorBinding& a, double ticks) {
  return rad_to_deg(ticks / a.ticks_per_rad);
}

// A value as the file gets it: 0.1 deg, no trailing zeros, never "-0".
std::string deg_text(double deg) {
  double r = std::round(deg * 10.0) / 10.0;
  if (r == 0.0) r = 0.0;
  return fmt::format("{}", r);
}

bool protocol_with_ticks(const std::string& protocol) {
  return protocol == "dynamixel2" || protocol == "feetech_sts" || protocol == "feetech_scs" ||
         protocol == "cia402";
}

void sleep_until(timespec& next, long period_ns) {
  next.tv_nsec += period_ns;
  while (next.tv_nsec >= 1'000'000'000L) {
    next.tv_nsec -= 1'000'000'000L;
    ++next.tv_sec;
  }
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
}

bool enter_pressed() {
  pollfd in{STDIN_FILENO, POLLIN, 0};
  if (::poll(&in, 1, 0) <= 0 || (in.revents & (POLLIN | POLLHUP)) == 0) return false;
  char buffer[256];
  const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
  if (n <= 0) return true;  // end of input: take what was seen
  return std::find(buffer, buffer + n, '\n') != buffer + n;
}

// Follows joint `j` until `done()` (or a stop signal): the seen range and
// the last position; a live line every 0.1 s when `live`.
void follow(LimpFigure& figure, std::size_t j, Seen& seen, bool live,
            const std::function<bool(double)>& done) {
  const ActuatorBinding& a = *figure.binding(j);
  const long period_ns = static_cast<long>(1e9 / figure.config().rate_hz);
  std::vector<double> positions;
  std::vector<bool> fresh;
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  const double t0 = next.tv_sec + next.tv_nsec * 1e-9;
  double shown = -1.0;
  RunControls& controls = commissioning_controls();
  while (!controls.stop.load()) {
    figure.read(positions, &fresh);
    // Only what the servo said: a lost answer leaves an old value, or none.
    if (fresh[j]) seen.add(raw_ticks(a, positions[j]));
    const double t = next.tv_sec + next.tv_nsec * 1e-9 - t0;
    if (live && t - shown >= 0.1) {
      shown = t;
      const double now = a.direction * ticks_to_deg(a, seen.home_ticks - a.zero_ticks);
      const double lo = a.direction * ticks_to_deg(a, seen.min_ticks - a.zero_ticks);
      const double hi = a.direction * ticks_to_deg(a, seen.max_ticks - a.zero_ticks);
      std::cout << fmt::format("\r  {}: now {:7.1f} deg   seen {:7.1f} .. {:7.1f} deg   ",
                               figure.config().joints[j].name, now, std::min(lo, hi),
                               std::max(lo, hi))
                << std::flush;
    }
    if (done(t)) break;
    sleep_until(next, period_ns);
  }
  if (live) std::cout << '\n';
  // At least the position where it was left, read.
  if (std::isnan(seen.last_raw) && !controls.stop.load()) {
    figure.read_fresh(j, positions);
    seen.add(raw_ticks(a, positions[j]));
  }
}

// One answer line from the user (raw reads: enter_pressed() reads the same
// descriptor); empty at the end of input.
std::string read_line() {
  std::string line;
  char c = 0;
  while (::read(STDIN_FILENO, &c, 1) == 1 && c != '\n') line += c;
  return line;
}

bool ask_yes(const std::string& question) {
  for (;;) {
    std::cout << question << " [y/n] " << std::flush;
    const std::string answer = read_line();
    if (answer == "y" || answer == "yes") return true;
    if (answer == "n" || answer == "no" || answer.empty()) return false;
  }
}

// The jog: joint `j` held by a weak torque, its goal jog_deg ahead in the
// file's positive direction for half a second, then limp again. How far it
// went, in the file's degrees (NaN: its servo has no current or torque control).
double jog(LimpFigure& figure, std::size_t j, const CalibrateArgs& args) {
  if (!figure.hold_weakly(j, args.jog_percent / 100.0)) return std::nan("");
  std::vector<double> positions;
  figure.read_fresh(j, positions);
  const double start = positions[j];
  std::vector<double> goals(positions.size(), std::nan(""));
  goals[j] = start + deg_to_rad(args.jog_deg);
  figure.write(goals);
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (int k = 0; k < 10 && !commissioning_controls().stop.load(); ++k) {
    sleep_until(next, 50'000'000L);
  }
  // Where the jog took it as its servo says, never a lost answer's old value.
  figure.read_fresh(j, positions);
  figure.let_go();
  return rad_to_deg(positions[j] - start);
}

// The direction from a jog: which way the servo turned for the file's
// positive, and (asked interactively) whether the user saw the joint turn
// its positive way. Returns the file's direction when the jog told nothing.
int direction_by_jog(LimpFigure& figure, std::size_t j, const CalibrateArgs& args) {
  const std::string& name = figure.config().joints[j].name;
  const ActuatorBinding& a = *figure.binding(j);
  std::cout << name << ": jog " << deg_text(args.jog_deg) << " deg under a weak torque ("
            << args.jog_percent << " %)" << std::endl;
  const double moved = jog(figure, j, args);
  if (std::isnan(moved)) {
    std::cout << name
              << ": its servo has no current or torque control: not jogged, "
                 "direction kept "
              << a.direction << '\n';
    return a.direction;
  }
  if (!(std::abs(moved) >= 0.5 * args.jog_deg)) {
    std::cout << fmt::format(
        "{}: moved {:.1f} deg of {}: blocked, at a limit or too weak (--jog-percent); direction "
        "kept {}\n",
        name, moved, deg_text(args.jog_deg), a.direction);
    return a.direction;
  }
  const int servo = moved > 0 ? 1 : -1;  // the servo turned the file's positive way
  std::cout << fmt::format("{}: it turned {:+.1f} deg as the file counts them\n", name, moved);
  const bool seen_positive =
      args.non_interactive || ask_yes(name + ": did it move in its positive direction?");
  return a.direction * servo * (seen_positive ? 1 : -1);
}

// The direction the user shows by hand (interactive, without a jog): the
// joint moved a little its positive way from `home` (ticks).
int direction_by_hand(LimpFigure& figure, std::size_t j, double home) {
  const std::string& name = figure.config().joints[j].name;
  const ActuatorBinding& a = *figure.binding(j);
  std::cout << name
            << ": now move it a little in its positive direction and press Enter (only "
               "Enter: keep direction "
            << a.direction << ")" << std::endl;
  Seen moved;
  moved.turn = ticks_per_turn(figure.protocol(j));
  follow(figure, j, moved, true, [](double) { return enter_pressed(); });
  const double delta_deg = ticks_to_deg(a, std::remainder(moved.home_ticks - home, moved.turn));
  if (std::abs(delta_deg) >= 1.0) return delta_deg > 0 ? 1 : -1;
  return a.direction;
}

// The joints to calibrate: --joint or all that a servo with ticks drives.
std::vector<std::size_t> chosen_joints(const LimpFigure& figure, const CalibrateArgs& args) {
  const auto& joints = figure.config().joints;
  std::vector<std::size_t> out;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const bool asked =
        std::find(args.joints.begin(), args.joints.end(), joints[j].name) != args.joints.end();
    if (!args.joints.empty() && !asked) continue;
    const std::string protocol = figure.protocol(j);
    const bool usable = figure.binding(j) != nullptr && protocol_with_ticks(protocol) &&
                        joints[j].type == JointType::revolute;
    if (usable) {
      out.push_back(j);
    } else if (asked) {
      throw std::invalid_argument("--joint " + joints[j].name + ": not calibrated here (" +
                                  (protocol.empty() ? "no bus drives it" : "protocol " + protocol) +
                                  "); calibrate knows revolute joints on Dynamixel and Feetech "
                                  "servos and CiA 402 drives");
    } else {
      std::cout << joints[j].name << ": skipped (" << (protocol.empty() ? "no bus" : protocol)
                << "; calibrate knows revolute joints on Dynamixel and Feetech servos and CiA "
                   "402 drives)\n";
    }
  }
  for (const std::string& name : args.joints) {
    const bool known = std::any_of(joints.begin(), joints.end(),
                                   [&](const JointSpec& s) { return s.name == name; });
    if (!known) {
      throw std::invalid_argument("--joint " + quote(name) + ": the robot file " +
                                  quote_path(figure.config().file) + " has no such joint");
    }
  }
  return out;
}

// The key of the home's count in the joint's actuator map.
const char* zero_key(const LimpFigure& figure, std::size_t j) {
  return figure.protocol(j) == "cia402" ? "zero_counts" : "zero_ticks";
}

// The file's new values for one joint, written into `edit`. Returns the
// report line.
std::string write_joint(YamlValueEditor& edit, const std::string& name, const ActuatorBinding& a,
                        const Seen& seen, long long zero, const char* zero_key = "zero_ticks") {
  // The range as seen from the home, whatever the home's ticks become.
  const double home = seen.home_ticks;
  const double lo = seen.direction * ticks_to_deg(a, seen.min_ticks - home);
  const double hi = seen.direction * ticks_to_deg(a, seen.max_ticks - home);
  // Rounded inward: a limit is never past what the hand reached.
  const double min_deg = std::ceil(std::min(lo, hi) * 10.0 - 1e-9) / 10.0;
  const double max_deg = std::floor(std::max(lo, hi) * 10.0 + 1e-9) / 10.0;
  edit.set({"joints", name, "limits", "min_deg"}, deg_text(min_deg));
  edit.set({"joints", name, "limits", "max_deg"}, deg_text(max_deg));
  edit.set({"joints", name, "home_deg"}, "0");
  edit.set({"joints", name, "actuator", zero_key}, std::to_string(zero));
  edit.set({"joints", name, "actuator", "direction"}, std::to_string(seen.direction));
  return fmt::format("{}: limits {} .. {} deg, home at {} ticks (0 deg), direction {}", name,
                     deg_text(min_deg), deg_text(max_deg), zero, seen.direction);
}

// A multi-turn joint (Dynamixel extended position mode) or a CiA 402
// drive's: homed in the device itself (Homing Offset; homing mode on the
// current position), so its zero_ticks stays as the file gives it.
bool is_multi_turn(const LimpFigure& figure, std::size_t j) {
  if (figure.protocol(j) == "cia402") return true;
  return figure.protocol(j) == "dynamixel2" && dxl::device_options(*figure.binding(j)).multi_turn;
}

// The homing method of a CiA 402 joint that searches its switches (17-30), or 0.
int switch_homing_method(const LimpFigure& figure, std::size_t j) {
  if (figure.protocol(j) != "cia402") return 0;
  const Cia402Homing h = options_of<Cia402JointOptions>(figure.binding(j)->options).homing;
  return h.on_switches() ? h.method : 0;
}

// A drive homed on its switches moves, so only once the user agreed (asked,
// or --yes); then its switch's edge reads the file's zero_ticks, before the
// range is followed, so the range is seen from that home.
void home_on_switches(LimpFigure& figure, std::size_t j, const CalibrateArgs& args) {
  const std::string& name = figure.config().joints[j].name;
  const int method = switch_homing_method(figure, j);
  const std::string what = fmt::format(
      "{}: homing method {} moves the joint until its drive finds its switch", name, method);
  const bool agreed = args.yes || (!args.non_interactive && ask_yes(what + "; start it?"));
  if (!agreed) {
    throw std::runtime_error(what + ": not agreed (" +
                             (args.non_interactive ? "--yes agrees beforehand" : "answered no") +
                             "); nothing was written");
  }
  std::cout << what << std::endl;
  const std::int64_t reads = figure.set_home(j, figure.binding(j)->zero_ticks);
  std::cout << fmt::format("{}: homed on its switch: its home reads {} ticks\n", name, reads);
}

// The checks on what was seen, the home of a multi-turn joint set in its
// servo, and the file's new values. Returns the report line.
std::string finish_joint(LimpFigure& figure, YamlValueEditor& edit, std::size_t j, Seen& seen,
                         const CalibrateArgs& args) {
  const std::string& name = figure.config().joints[j].name;
  const ActuatorBinding& a = *figure.binding(j);
  const double range = ticks_to_deg(a, seen.max_ticks - seen.min_ticks);
  if (!(range >= args.min_range_deg)) {
    throw std::runtime_error(fmt::format(
        "{}: moved through only {:.1f} deg (at least {} deg needed): nothing was written; move "
        "the joint through its whole range while it is recorded",
        name, range, args.min_range_deg));
  }
  if (!is_multi_turn(figure, j)) {
    if (!seen.within_one_turn()) {
      throw std::runtime_error(fmt::format(
          "{}: its range, {:.0f} .. {:.0f} ticks, crosses its servo's {:.0f} -> 0 seam, which a "
          "servo in position mode cannot be driven across: nothing was written; turn the horn "
          "on its spline so that the range lies within one turn",
          name, seen.min_ticks, seen.max_ticks, seen.turn - 1));
    }
    return write_joint(edit, name, a, seen, std::lround(seen.home_ticks));
  }
  if (const int method = switch_homing_method(figure, j)) {
    seen.home_ticks = static_cast<double>(a.zero_ticks);  // homed before the range was seen
    return write_joint(edit, name, a, seen, a.zero_ticks, zero_key(figure, j)) +
           fmt::format(" (homing method {}: 0 deg at the switch)", method);
  }
  // The home where the joint rests now reads the file's zero_ticks.
  const std::int64_t reads = figure.set_home(j, a.zero_ticks);
  const bool drive = figure.protocol(j) == "cia402";
  std::cout << fmt::format("{}: {}: its home reads {} ticks\n", name,
                           drive ? "homed on its current position" : "Homing Offset set", reads);
  return write_joint(edit, name, a, seen, a.zero_ticks, zero_key(figure, j)) +
         (drive ? " (homing method 37)" : " (Homing Offset)");
}

// The edited file must load as a robot: checked on a copy beside it, so
// its relative paths resolve, before the original is replaced.
void check_loads(const std::string& path, const std::string& text) {
  const std::filesystem::path p(path);
  const std::string check =
      (p.parent_path() / ("." + p.filename().string() + ".calibrated")).string();
  {
    std::ofstream out(check, std::ios::binary);
    out << text;
    if (!out) {
      throw InputError({path, 0, 0}, "", "cannot write beside the robot file; nothing was written");
    }
  }
  try {
    load_robot_config(check);
  } catch (const InputError& e) {
    std::filesystem::remove(check);
    throw InputError({path, e.where().line, e.where().column}, e.key(),
                     e.message() + " (after calibration; nothing was written)");
  }
  std::filesystem::remove(check);
}

int run_calibrate(const CalibrateArgs& args) {
  install_stop_signals(commissioning_controls(), SecondSignal::end_process);
  // What the file holds now: written back only if it still holds this.
  const std::string original = read_whole_file(args.robot);
  LimpFigure figure(args.robot, args.ports);
  const std::vector<std::size_t> joints = chosen_joints(figure, args);
  std::cout << "torque is off on every joint\n";
  if (args.non_interactive && args.jog != 1) {
    std::cout << "direction is not checked in non-interactive mode without --jog: each joint "
                 "keeps the direction its file gives\n";
  }
  YamlValueEditor edit(original, args.robot);
  std::vector<std::string> lines;
  RunControls& controls = commissioning_controls();
  for (const std::size_t j : joints) {
    const std::string& name = figure.config().joints[j].name;
    const ActuatorBinding& a = *figure.binding(j);
    Seen seen;
    seen.direction = a.direction;
    seen.turn = ticks_per_turn(figure.protocol(j));
    // A multi-turn servo counts on across its turns: nothing to unwrap.
    if (is_multi_turn(figure, j)) seen.turn = std::numeric_limits<double>::infinity();
    if (switch_homing_method(figure, j) != 0) home_on_switches(figure, j, args);
    const bool jogged = args.jog == 1 || (args.jog < 0 && !args.non_interactive &&
                                          ask_yes(name + ": check its direction by a small jog "
                                                         "under a weak torque?"));
    if (jogged) seen.direction = direction_by_jog(figure, j, args);
    if (args.non_interactive) {
      std::cout << fmt::format("{}: move it through its whole range and to its home pose ({} s)",
                               name, args.seconds_per_joint)
                << std::endl;
      const double limit = args.seconds_per_joint;
      follow(figure, j, seen, false, [limit](double t) { return t >= limit; });
    } else {
      std::cout << name
                << ": move it by hand through its whole range, leave it at its home pose and "
                   "press Enter"
                << std::endl;
      follow(figure, j, seen, true, [](double) { return enter_pressed(); });
      if (!jogged) seen.direction = direction_by_hand(figure, j, seen.home_ticks);
    }
    if (controls.stop.load()) {
      std::cout << "stopped: nothing was written\n";
      return kExitUsage;
    }
    lines.push_back(finish_joint(figure, edit, j, seen, args));
  }
  check_loads(args.robot, edit.text());
  replace_file_contents(args.robot, original, edit.text());
  for (const std::string& line : lines) std::cout << line << '\n';
  std::cout << args.robot << ": " << lines.size() << " joint" << (lines.size() == 1 ? "" : "s")
            << " calibrated\n";
  return kExitOk;
}

}  // namespace calibrate_cmd

void add_calibrate_command(CLI::App& app) {
  using namespace calibrate_cmd;
  static CalibrateArgs args;
  auto* cmd = app.add_subcommand(
      "calibrate",
      "Torque off, move each joint by hand through its range and to its home pose; writes "
      "zero_ticks, direction and limits back into the robot file, comments kept");
  cmd->add_option("ROBOT", args.robot, "robot file (YAML), edited in place")->required();
  cmd->add_option("--joint", args.joints, "calibrate only this joint (repeatable)");
  cmd->add_flag("--non-interactive", args.non_interactive,
                "no questions: each joint is followed for --seconds-per-joint, its home is where "
                "it rests at the end, its direction stays as the file gives it");
  cmd->add_option("--seconds-per-joint", args.seconds_per_joint,
                  "time per joint in non-interactive mode")
      ->check(FiniteRange(0.1, 3600.0));
  cmd->add_flag_callback(
      "--jog", [] { args.jog = 1; },
      "check each joint's direction by a small jog under a weak torque "
      "(interactive: without asking first; non-interactive: the servo's "
      "turn decides)");
  cmd->add_flag_callback(
      "--no-jog", [] { args.jog = 0; }, "no direction jog, and no question");
  cmd->add_option("--jog-deg", args.jog_deg, "how far the jog goes (default 5)")
      ->check(FiniteRange(0.5, 30.0));
  cmd->add_option("--jog-percent", args.jog_percent,
                  "the jog's torque: this share of the servo's current limit (default 10)")
      ->check(FiniteRange(1.0, 50.0));
  cmd->add_flag("--yes", args.yes,
                "agree beforehand to the moves calibrate would ask about: the homing search of "
                "a CiA 402 drive on its switches (a joint with homing method 17-30)");
  cmd->add_option("--min-range-deg", args.min_range_deg,
                  "refuse a joint moved through less than this (default 2)")
      ->check(FiniteRange(0.0, 360.0));
  args.ports.add_option(cmd);
  set_subcommand_body(cmd, [] {
    try {
      return run_calibrate(args);
    } catch (const DeviceError& e) {
      std::cerr << "error: " << e.what() << '\n';
      return kExitDeviceError;
    }
  });
}

}  // namespace animrt::cli
