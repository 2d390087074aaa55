#pragma once
// Pololu Maestro as a protocol module ("maestro"): hobby servos on the
// channels of one board (compact protocol) or of daisy-chained boards (Pololu
// protocol), with a pulse calibration per channel.

#include "animrt/bridge/protocol.hpp"

namespace animrt {

const Protocol& maestro_protocol();

}  // namespace animrt
