#include "animrt/bridge/dynamixel/latency_timer.hpp"

#include <filesystem>
#include <fstream>
#include <system_error>

namespace animrt {
namespace {

namespace fs = std::filesystem;

constexpr int kWantedMs = 1;

bool is_usb_serial(const std::string& name) { return name.rfind("ttyUSB", 0) == 0; }

// ttyUSB0 for /dev/ttyUSB0 or a link to it (/dev/serial/by-id/...); empty
// for anything else.
std::string usb_serial_name(const std::string& port) {
  const std::string given = fs::path(port).filename().string();
  if (is_usb_serial(given)) return given;
  std::error_code ec;
  const std::string name = fs::canonical(port, ec).filename().string();
  return !ec && is_usb_serial(name) ? name : std::string();
}

std::string timer_path(const std::string& name, const std::string& sysfs_root) {
  return sysfs_root + "/bus/usb-serial/devices/" + name + "/latency_timer";
}

}  // namespace

std::optional<int> read_latency_timer(const std::string& port, const std::string& sysfs_root) {
  const std::string name = usb_serial_name(port);
  if (name.empty()) return std::nullopt;
  std::ifstream in(timer_path(name, sysfs_root));
  int ms = 0;
  if (!(in >> ms)) return std::nullopt;
  return ms;
}

std::string latency_timer_warning(const std::string& port, const std::string& sysfs_root) {
  const std::optional<int> ms = read_latency_timer(port, sysfs_root);
  if (!ms || *ms <= kWantedMs) return {};
  const std::string name = usb_serial_name(port);
  // The command names the real sysfs file even when a test reads a fake one.
  return "serial port " + port + " (" + name + "): the USB adapter's latency timer is " +
         std::to_string(*ms) + " ms, so every answer waits up to that long; set it to 1 ms with: " +
         "echo 1 | sudo tee " + timer_path(name, "/sys") +
         " (or a udev rule: ACTION==\"add\", SUBSYSTEM==\"usb-serial\", DRIVER==\"ftdi_sio\", "
         "ATTR{latency_timer}=\"1\")";
}

}  // namespace animrt
