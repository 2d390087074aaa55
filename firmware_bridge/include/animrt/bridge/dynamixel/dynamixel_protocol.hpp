#pragma once
// Dynamixel Protocol 2.0 as a protocol module: X-series servos on a serial
// line, one id each, positions in ticks.

#include "animrt/bridge/protocol.hpp"

namespace animrt {

const Protocol& dynamixel2_protocol();

}  // namespace animrt
