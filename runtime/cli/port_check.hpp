#pragma once
// Before a commissioning tool talks on a serial port: is another program
// using it? Two programs on one half-duplex line garble each other's
// packets, and a scan would then report collisions that are not there.

#include <string>

namespace animrt::cli {

// "" when no other process has `port` open; else "busy: open in PID (NAME)".
// The far end of a pseudo-terminal (a process holding /dev/ptmx, as a
// device simulator does) is the wire, not a user of the port.
std::string port_busy(const std::string& port);

}  // namespace animrt::cli
