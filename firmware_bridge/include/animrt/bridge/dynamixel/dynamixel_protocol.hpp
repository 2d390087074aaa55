#pragma once
// Dynamixel Protocol 2.0 as a protocol module: X-series servos on a serial
// line, one id each, positions in ticks.

#include <cstddef>

#include "animrt/bridge/protocol.hpp"

namespace animrt {

const Protocol& dynamixel2_protocol();

// Bytes on the wire per cycle for `devices` servos: Sync Write of 4-byte
// goals, Sync Read (or Fast Sync Read) of 4-byte present positions and the
// answers. 12 servos: 280 with Sync Read, 204 with Fast Sync Read.
// `read_bytes`: data bytes read per servo (10 with health packed).
std::size_t dynamixel_wire_bytes(std::size_t devices, bool fast_read, std::size_t read_bytes = 4);

}  // namespace animrt
