#pragma once
// The Modbus requests ModbusBus makes, through libmodbus. With a lockstep
// line (simulated drives on a lockstep clock, lockstep_line.hpp; RTU only)
// a request is sent, the host waits until the drives have taken it and
// written whatever they answer, and an answer that is not there then is
// missing at once, where libmodbus would wait its response timeout on the
// wall clock; the answer that is there is read and checked here as
// libmodbus checks it. Without a line: libmodbus's own calls, unchanged.
//
// Each returns what the libmodbus call it stands for returns: the number of
// registers or bits, or -1 with errno set (ETIMEDOUT for a missing answer,
// MODBUS_ENOBASE + code for an exception).

#include <cstdint>

#include "animrt/bridge/lockstep_line.hpp"

struct _modbus;

namespace animrt::modbus_requests {

// Read Holding Registers (input = false) or Read Input Registers.
int read_registers(_modbus* ctx, LockstepLine* line, int slave, bool input, int address, int count,
                   std::uint16_t* dest);
// Write Multiple Registers.
int write_registers(_modbus* ctx, LockstepLine* line, int slave, int address, int count,
                    const std::uint16_t* src);
// Write Single Register (coil = false) or Write Single Coil (value != 0: on).
int write_single(_modbus* ctx, LockstepLine* line, int slave, bool coil, int address,
                 std::uint16_t value);

}  // namespace animrt::modbus_requests
