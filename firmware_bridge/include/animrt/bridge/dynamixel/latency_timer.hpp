#pragma once
// The latency timer of a USB serial adapter (FTDI, as in the U2D2): the
// driver holds received bytes for up to this many milliseconds before
// handing them on. Linux's default is 16 ms, which turns every Dynamixel
// transaction into a 16 ms wait; 1 ms is what a servo bus wants.

#include <optional>
#include <string>

namespace animrt {

// The adapter's latency timer in ms, read from
// <sysfs_root>/bus/usb-serial/devices/<ttyUSBn>/latency_timer, where ttyUSBn
// is the port after following symlinks (/dev/serial/by-id/...). Nothing for
// a port that is not a USB serial adapter (a pty, a built-in UART) or when
// the file cannot be read.
std::optional<int> read_latency_timer(const std::string& port,
                                      const std::string& sysfs_root = "/sys");

// A warning naming the port, the value and the command that sets it to 1 ms
// when the latency timer is above 1 ms; empty otherwise.
std::string latency_timer_warning(const std::string& port, const std::string& sysfs_root = "/sys");

}  // namespace animrt
