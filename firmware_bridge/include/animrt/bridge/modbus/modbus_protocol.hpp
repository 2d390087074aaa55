#pragma once
// Modbus drives as protocol modules: "modbus-tcp" (port: HOST:PORT) and
// "modbus-rtu" (port: a serial device), each joint bound to a slave id and a
// register map file.

#include "animrt/bridge/protocol.hpp"

namespace animrt {

const Protocol& modbus_tcp_protocol();
const Protocol& modbus_rtu_protocol();

}  // namespace animrt
