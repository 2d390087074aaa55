#include "animrt/bridge/commission/modbus_scan.hpp"

#include <modbus/modbus.h>

#include <algorithm>
#include <cerrno>
#include <memory>

#include "animrt/core/error.hpp"

namespace animrt::commission {
namespace {

struct ModbusContext {
  modbus_t* ctx = nullptr;
  ~ModbusContext() {
    if (ctx != nullptr) {
      modbus_close(ctx);
      modbus_free(ctx);
    }
  }
};

// Asks each unit id for holding register 0: a value, or an exception
// (illegal address or function) means a device is there.
void ask_units(modbus_t* ctx, const std::string& protocol, int baud, const ScanLimits& limits,
               ScanResult& out) {
  const auto us = static_cast<std::uint32_t>(limits.answer_timeout.count());
  modbus_set_response_timeout(ctx, us / 1'000'000, us % 1'000'000);
  modbus_set_byte_timeout(ctx, us / 1'000'000, us % 1'000'000);
  modbus_set_error_recovery(ctx, MODBUS_ERROR_RECOVERY_NONE);
  const int first = std::max(limits.first_id, 1);
  const int last = std::min(limits.last_id, 247);
  int asked = 0;
  int garbled = 0;
  std::vector<FoundDevice> found;
  for (int id = first; id <= last; ++id) {
    ++asked;
    modbus_set_slave(ctx, id);
    std::uint16_t value = 0;
    const int n = modbus_read_registers(ctx, 0, 1, &value);
    const int error = errno;
    FoundDevice d;
    d.protocol = protocol;
    d.baud = baud;
    d.id = id;
    if (n == 1) {
      d.note = "holding register 0 reads " + std::to_string(value);
    } else if (error == EMBXILADD || error == EMBXILFUN || error == EMBXILVAL ||
               error == EMBXSFAIL) {
      d.note = std::string("answers with an exception: ") + modbus_strerror(error);
    } else {
      if (error == EMBBADCRC || error == EMBBADDATA || error == EMBBADSLAVE) ++garbled;
      modbus_flush(ctx);
      continue;
    }
    found.push_back(std::move(d));
  }
  if (found.size() > 1 && static_cast<int>(found.size()) == asked) {
    // One device (or gateway) that ignores the unit id.
    found.resize(1);
    found[0].note += "; answers every unit id asked";
  }
  for (FoundDevice& d : found) out.devices.push_back(std::move(d));
  if (garbled > 0) {
    out.garbled.push_back(protocol + (baud > 0 ? " at " + std::to_string(baud) : std::string()) +
                          ": " + std::to_string(garbled) + " answers with a bad CRC or frame");
  }
  if (limits.progress) {
    limits.progress(protocol + (baud > 0 ? " at " + std::to_string(baud) : std::string()) + ": " +
                    std::to_string(found.size()) + " unit(s) answered");
  }
}

}  // namespace

const std::vector<int>& modbus_rtu_bauds() {
  static const std::vector<int> bauds = {9600, 19200, 38400, 57600, 115200};
  return bauds;
}

void scan_modbus_rtu(const std::string& port, int baud, char parity, const ScanLimits& limits,
                     ScanResult& out) {
  ModbusContext c;
  c.ctx = modbus_new_rtu(port.c_str(), baud, parity, 8, parity == 'N' ? 2 : 1);
  if (c.ctx == nullptr || modbus_connect(c.ctx) != 0) {
    throw DeviceError("cannot open serial port " + port +
                      " for Modbus RTU: " + modbus_strerror(errno));
  }
  ask_units(c.ctx, "modbus-rtu", baud, limits, out);
}

void scan_modbus_tcp(const std::string& host_port, const ScanLimits& limits, ScanResult& out) {
  const auto colon = host_port.rfind(':');
  int tcp_port = 0;
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no port");
    std::size_t used = 0;
    tcp_port = std::stoi(host_port.substr(colon + 1), &used);
    if (used != host_port.size() - colon - 1 || tcp_port <= 0 || tcp_port > 65535) {
      throw std::invalid_argument("bad port");
    }
  } catch (const std::exception&) {
    throw DeviceError("tcp://" + host_port + ": expected tcp://HOST:PORT");
  }
  const std::string host = host_port.substr(0, colon);
  ModbusContext c;
  // By name or address (modbus_new_tcp takes addresses only).
  c.ctx = modbus_new_tcp_pi(host.c_str(), std::to_string(tcp_port).c_str());
  if (c.ctx == nullptr || modbus_connect(c.ctx) != 0) {
    throw DeviceError("cannot connect to Modbus TCP " + host_port + ": " + modbus_strerror(errno));
  }
  ask_units(c.ctx, "modbus-tcp", 0, limits, out);
}

}  // namespace animrt::commission
