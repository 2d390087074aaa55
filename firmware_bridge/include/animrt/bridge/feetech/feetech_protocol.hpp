#pragma once
// Feetech serial-bus servos as protocol modules: `feetech_sts` (STS series,
// e.g. STS3215/STS3032: 4096 steps per turn, values low byte first, Sync
// Read) and `feetech_scs` (SCS series, e.g. SCS0009/SCS15: 1024 steps over
// about 300 degrees, values high byte first, no Sync Read).

#include "animrt/bridge/feetech/feetech_codec.hpp"
#include "animrt/bridge/protocol.hpp"

namespace animrt {

const Protocol& feetech_sts_protocol();
const Protocol& feetech_scs_protocol();

// The series a protocol name stands for; false if it is not a Feetech one.
bool feetech_series(std::string_view protocol, ft::Series& series);

}  // namespace animrt
