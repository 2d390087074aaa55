#pragma once
// The Modbus requests ModbusBus makes, through libmodbus. With a lockstep
// line (simulated drives on a lockstep clock, lockstep_line.hpp; RTU only)
// a request is sent, the host waits until the drives have taken it and
// written whatever they answer, and an answer that is not there then is
// missing at once, where libmodbus would wait its response timeout on the
// wall clock; the answer that is there is read and checked here as
// libmodbus checks it. Without a line: libmodbus's own calls, with a late
// answer waited out first on RTU (LateAnswers).
//
// Each returns what the libmodbus call it stands for returns: the number of
// registers or bits, or -1 with errno set (ETIMEDOUT for a missing answer,
// MODBUS_ENOBASE + code for an exception).

#include <array>
#include <chrono>
#include <cstdint>

#include "animrt/bridge/lockstep_line.hpp"

struct _modbus;

namespace animrt::modbus_requests {

// RTU on a real line: an answer names its slave and function but no
// register, and libmodbus reads whatever comes next. The answer to a
// request given up (no answer in time, or a garbled one) may still come;
// during the slave's next, other request it would pass for that one's
// answer (a position word taken for a health word), or fail it. Such a
// request first waits for it, as long again as the request given up took,
// and flushes the line. A repeat of the same request does not wait: the
// late answer carries what it asks (so a silent slave costs no more per
// cycle); what it leaves owed, the next other request waits out.
class LateAnswers {
 public:
  using Clock = std::chrono::steady_clock;
  struct Request {
    int function = 0, address = 0, count = 0;
    bool operator==(const Request&) const = default;
  };
  void before(_modbus* ctx, int slave, const Request& request);
  void after(int rc, int slave, const Request& request, Clock::time_point sent);

 private:
  struct Owed {
    bool due = false;
    Request request;
    Clock::time_point until{};
  };
  std::array<Owed, 256> owed_{};  // by slave id
};

// The line requests go over: a lockstep line to simulated drives (RTU), or
// a real one, where late answers are waited out (RTU) or the transaction
// id tells them apart (TCP: both null).
struct Line {
  LockstepLine* lockstep = nullptr;
  LateAnswers* late = nullptr;
  // Sent without waiting for a late answer (a switch-off: the drive acts on
  // the request whatever answer the host then reads).
  bool urgent = false;
};

// Read Holding Registers (input = false) or Read Input Registers.
int read_registers(_modbus* ctx, Line line, int slave, bool input, int address, int count,
                   std::uint16_t* dest);
// Write Multiple Registers.
int write_registers(_modbus* ctx, Line line, int slave, int address, int count,
                    const std::uint16_t* src);
// Write Single Register (coil = false) or Write Single Coil (value != 0: on).
int write_single(_modbus* ctx, Line line, int slave, bool coil, int address, std::uint16_t value);

}  // namespace animrt::modbus_requests
