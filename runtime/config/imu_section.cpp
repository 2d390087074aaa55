// The `imus:` list and the tilt watch's keys (see imu_section.hpp).

#include "imu_section.hpp"

#include <numbers>
#include <set>
#include <string>

namespace animrt {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

}  // namespace

std::vector<ImuConfig> parse_imus(const YamlNode& list, double rate_hz) {
  if (!list.is_sequence()) list.fail("expected a list of IMUs, found " + list.describe());
  std::vector<ImuConfig> imus;
  std::set<std::string> names;
  for (const YamlNode& item : list.items()) {
    item.allow_only(
        {"name", "protocol", "port", "baud", "rate_hz", "stale_timeout_s", "mount", "sim"});
    ImuConfig imu;
    imu.where = item.location();
    const YamlNode name = item.at("name");
    imu.name = name.as_string();
    if (imu.name.empty()) name.fail("expected an IMU name, found \"\"");
    if (!names.insert(imu.name).second) name.fail("a second IMU named " + imu.name);
    const YamlNode protocol = item.at("protocol");
    imu.protocol = protocol.as_string();
    if (imu.protocol != "bno08x_rvc") {
      protocol.fail("unknown IMU protocol " + protocol.describe() + " (supported: bno08x_rvc)");
    }
    imu.port = item.get_string("port", "");
    if (auto n = item.find("baud")) {
      imu.baud = static_cast<int>(n->as_int());
      if (imu.baud != 115200) {
        n->fail("expected 115200 (the BNO08x sends UART-RVC at 115200 baud only), found " +
                n->describe());
      }
    }
    if (auto n = item.find("rate_hz")) {
      imu.rate_hz = n->as_double_in(1.0, 1000.0);
      if (imu.rate_hz != 100.0) {
        n->fail("expected 100 (the BNO08x sends UART-RVC at 100 Hz only), found " + n->describe());
      }
    }
    if (auto n = item.find("stale_timeout_s")) {
      imu.stale_timeout_s = n->as_double_in(0.0, 10.0);
      // At least one report period and one loop period, or every cycle
      // between two frames would be stale.
      const double least = std::max(1.0 / imu.rate_hz, 1.0 / rate_hz);
      if (imu.stale_timeout_s < 2.0 * least) {
        n->fail("expected at least two report or loop periods (" + format_number(2.0 * least) +
                " s), found " + n->describe());
      }
    }
    if (auto mount = item.find("mount")) {
      mount->allow_only({"yaw_deg", "pitch_deg", "roll_deg"});
      imu.mount_ypr_rad = {mount->get_double("yaw_deg", 0.0) * kDeg,
                           mount->get_double("pitch_deg", 0.0) * kDeg,
                           mount->get_double("roll_deg", 0.0) * kDeg};
      for (const char* key : {"yaw_deg", "pitch_deg", "roll_deg"}) {
        if (auto n = mount->find(key)) n->as_double_in(-360.0, 360.0);
      }
    }
    if (auto sim = item.find("sim")) {
      sim->allow_only({"push_at_s", "push_axis", "push_rate_deg_s", "push_to_deg", "silent_at_s",
                       "latency_ms"});
      if (auto n = sim->find("silent_at_s")) imu.sim_silent_at_s = n->as_double_in(0.0, 1e6);
      if (auto n = sim->find("latency_ms")) {
        // A real part's frame is younger than its report period; a lockstep
        // physics reaches a time only a loop period after the clock does.
        imu.sim_latency_s = n->as_double_in(1000.0 / rate_hz, 200.0) / 1000.0;
      }
      if (auto at = sim->find("push_at_s")) {
        imu.sim_push.on = true;
        imu.sim_push.at_s = at->as_double_in(0.0, 1e6);
        imu.sim_push.rate_rad_s = sim->at("push_rate_deg_s").as_double_in(1.0, 3600.0) * kDeg;
        imu.sim_push.to_rad = sim->at("push_to_deg").as_double_in(-180.0, 180.0) * kDeg;
        if (auto axis = sim->find("push_axis")) {
          const std::string a = axis->as_string();
          if (a != "roll" && a != "pitch") {
            axis->fail("expected roll or pitch, found " + axis->describe());
          }
          imu.sim_push.pitch = a == "pitch";
        }
      }
    }
    imus.push_back(std::move(imu));
  }
  return imus;
}

void parse_tilt_watch(const YamlNode& node, SafetyConfig& safety) {
  if (auto n = node.find("tilt_limit_deg"))
    safety.tilt_limit_rad = n->as_double_in(1.0, 180.0) * kDeg;
  if (auto n = node.find("tilt_time_s")) safety.tilt_time_s = n->as_double_in(0.0, 10.0);
  if (auto n = node.find("tilt_hold_s")) safety.tilt_hold_s = n->as_double_in(0.0, 60.0);
  if (auto n = node.find("on_tilt")) {
    const std::string v = n->as_string();
    if (v == "hold") {
      safety.on_tilt = SafetyConfig::OnTilt::hold;
    } else if (v == "torque_off") {
      safety.on_tilt = SafetyConfig::OnTilt::torque_off;
    } else {
      n->fail("expected hold or torque_off, found " + n->describe());
    }
  }
}

}  // namespace animrt
