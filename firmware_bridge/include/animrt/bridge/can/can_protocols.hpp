#pragma once
// The CAN protocol modules: "mit" (MIT mini-cheetah mode motors) and
// "cia402" (CANopen drives in cyclic synchronous position mode). Both put a
// bus on a CAN interface (`interface: can0`, or `virtual:NAME` for the
// in-process bus); several buses may share one interface.

#include "animrt/bridge/protocol.hpp"

namespace animrt {

const Protocol& mit_protocol();
const Protocol& cia402_protocol();

}  // namespace animrt
