#include <sys/stat.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <memory>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/core/error.hpp"
#include "fd_transport.hpp"

namespace animrt {

std::unique_ptr<ByteTransport> open_serial(const std::string& port, int baud) {
  if (port.empty()) detail::throw_open_error("\"\"", "no port given");
  if (baud <= 0) detail::throw_open_error(port, "invalid baud rate " + std::to_string(baud));
  // Resolve symlinks (udev's /dev/serial/by-id/..., socat's links to ptys) so
  // the device is classified by what it is, not by its name.
  char resolved[PATH_MAX];
  if (::realpath(port.c_str(), resolved) == nullptr) {
    const int error = errno;
    detail::throw_open_error(port, std::strerror(error), error);
  }
  const std::string device(resolved);
  struct stat st {};
  if (::stat(device.c_str(), &st) != 0) {
    const int error = errno;
    detail::throw_open_error(port, std::strerror(error), error);
  }
  if (!S_ISCHR(st.st_mode)) {
    detail::throw_open_error(port, S_ISDIR(st.st_mode)
                                       ? "is a directory, not a serial port"
                                       : "not a character device (not a serial port)");
  }
  if (detail::is_pseudo_terminal(device)) return detail::open_pty(port, device, baud);
  return detail::open_libserialport(port, device, baud);
}

std::unique_ptr<ByteTransport> open_bus_serial(const BusConfig& bus) {
  try {
    std::unique_ptr<ByteTransport> line = open_serial(bus.port, bus.baud);
    if (bus.lockstep_line) line->follow(bus.lockstep_line);
    return line;
  } catch (const DeviceError& e) {
    throw DeviceError("bus " + bus.name + ": " + e.what());
  }
}

}  // namespace animrt
