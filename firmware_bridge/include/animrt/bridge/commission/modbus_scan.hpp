#pragma once
// Modbus devices on an RTU line or behind a TCP address: one read of
// holding register 0 per unit id, within the answer timeout. A device that
// answers with an exception (no such register) is there all the same.

#include <string>

#include "animrt/bridge/commission/found_device.hpp"

namespace animrt::commission {

const std::vector<int>& modbus_rtu_bauds();

// `port` a serial port (RTU, 8 data bits, `parity` 'E', 'O' or 'N' with one
// stop bit, two without parity as the standard says); ids
// limits.first_id..last_id within 1..247. Throws DeviceError if the line
// cannot be opened.
void scan_modbus_rtu(const std::string& port, int baud, char parity, const ScanLimits& limits,
                     ScanResult& out);

// `host_port` "HOST:PORT"; unit ids as above (many devices
// answer every unit id: then one row says so). Throws DeviceError if the
// connection is refused.
void scan_modbus_tcp(const std::string& host_port, const ScanLimits& limits, ScanResult& out);

}  // namespace animrt::commission
