#include "modbus_requests.hpp"

#include <modbus.h>
#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <thread>

namespace animrt::modbus_requests {
namespace {

// Waits (boundedly: LockstepLine::kGuard) until the drives have taken every
// byte the host wrote; false if they did not (a hung simulator).
bool wait_taken(const LockstepLine& line) {
  const auto deadline = std::chrono::steady_clock::now() + LockstepLine::kGuard;
  for (;;) {
    line.clear_wake();  // before the look, so no wake-up is lost
    if (line.device_caught_up()) return true;
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) return false;
    pollfd fd{line.wake_fd(), POLLIN, 0};
    ::poll(&fd, 1, static_cast<int>(left.count()) + 1);
  }
}

// Sends the request (slave, function, data; libmodbus adds the CRC) and
// receives the answer into `rsp`: its length, or -1 with errno.
int exchange(modbus_t* ctx, LockstepLine& line, const std::uint8_t* req, int length,
             std::uint8_t* rsp) {
  const int sent = modbus_send_raw_request(ctx, req, length);
  if (sent < 0) return -1;
  line.host_wrote(static_cast<std::size_t>(sent));
  const bool taken = wait_taken(line);
  const std::uint64_t due = line.unread();
  if (!taken || due == 0) {
    errno = ETIMEDOUT;  // nothing came, and nothing more will
    return -1;
  }
  const int rc = modbus_receive_confirmation(ctx, rsp);
  // One request, at most one answer: read now, or flushed before the next.
  line.host_read(due);
  if (rc == 0) errno = EMBBADSLAVE;  // libmodbus: another slave's answer
  return rc > 0 ? rc : -1;
}

// The checks libmodbus makes of an answer: the slave, the function (or its
// exception), the length.
bool answer_ok(const std::uint8_t* req, const std::uint8_t* rsp, int rc, int want) {
  if (rc < 0) return false;
  if (rc < 3) {
    errno = EMBBADDATA;
    return false;
  }
  if (rsp[0] != req[0]) {
    errno = EMBBADSLAVE;
    return false;
  }
  if (rsp[1] == (req[1] | 0x80)) {
    errno = MODBUS_ENOBASE + rsp[2];
    return false;
  }
  if (rsp[1] != req[1] || rc != want) {
    errno = EMBBADDATA;
    return false;
  }
  return true;
}

void put16(std::uint8_t* p, int v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}

int get16(const std::uint8_t* p) { return (p[0] << 8) | p[1]; }

// A libmodbus call on a real line, with late answers waited out (RTU).
template <class Call>
int on_real_line(modbus_t* ctx, Line line, int slave, const LateAnswers::Request& request,
                 Call&& call) {
  if (line.late == nullptr) return call();
  if (!line.urgent) line.late->before(ctx, slave, request);
  const auto sent = LateAnswers::Clock::now();
  const int rc = call();
  const int error = errno;
  line.late->after(rc, slave, request, sent);
  errno = error;
  return rc;
}

}  // namespace

void LateAnswers::before(modbus_t* ctx, int slave, const Request& request) {
  Owed& o = owed_[static_cast<std::size_t>(slave & 0xFF)];
  if (!o.due || o.request == request) return;
  std::this_thread::sleep_until(o.until);
  modbus_flush(ctx);
  o.due = false;
}

void LateAnswers::after(int rc, int slave, const Request& request, Clock::time_point sent) {
  Owed& o = owed_[static_cast<std::size_t>(slave & 0xFF)];
  // No answer in time, or one not usable as this request's (damaged, or
  // another's): this request's own may still come. An exception is an
  // answer; a connection error leaves nothing to wait for.
  const bool given_up =
      rc < 0 && (errno == ETIMEDOUT || errno == EMBBADCRC || errno == EMBBADDATA ||
                 errno == EMBBADEXC || errno == EMBBADSLAVE);
  // Answered after a repeat given up: that answer may have been the one
  // owed, and this request's own is owed now.
  if (!given_up && !(o.due && o.request == request)) return;
  const auto now = Clock::now();
  o.until = o.due ? std::max(o.until, now + (now - sent)) : now + (now - sent);
  o.due = true;
  o.request = request;
}

int read_registers(modbus_t* ctx, Line line, int slave, bool input, int address, int count,
                   std::uint16_t* dest) {
  if (line.lockstep == nullptr) {
    const int function = input ? MODBUS_FC_READ_INPUT_REGISTERS : MODBUS_FC_READ_HOLDING_REGISTERS;
    return on_real_line(ctx, line, slave, {function, address, count}, [&] {
      return input ? modbus_read_input_registers(ctx, address, count, dest)
                   : modbus_read_registers(ctx, address, count, dest);
    });
  }
  if (count < 1 || count > MODBUS_MAX_READ_REGISTERS) {
    errno = EMBMDATA;
    return -1;
  }
  std::uint8_t req[6] = {static_cast<std::uint8_t>(slave),
                         static_cast<std::uint8_t>(input ? MODBUS_FC_READ_INPUT_REGISTERS
                                                         : MODBUS_FC_READ_HOLDING_REGISTERS)};
  put16(req + 2, address);
  put16(req + 4, count);
  std::uint8_t rsp[MODBUS_MAX_ADU_LENGTH];
  const int rc = exchange(ctx, *line.lockstep, req, sizeof req, rsp);
  // Slave, function, byte count, the registers, CRC.
  if (!answer_ok(req, rsp, rc, 3 + 2 * count + 2)) return -1;
  if (rsp[2] != 2 * count) {
    errno = EMBBADDATA;
    return -1;
  }
  for (int i = 0; i < count; ++i) dest[i] = static_cast<std::uint16_t>(get16(rsp + 3 + 2 * i));
  return count;
}

int write_registers(modbus_t* ctx, Line line, int slave, int address, int count,
                    const std::uint16_t* src) {
  if (line.lockstep == nullptr) {
    return on_real_line(ctx, line, slave, {MODBUS_FC_WRITE_MULTIPLE_REGISTERS, address, count},
                        [&] { return modbus_write_registers(ctx, address, count, src); });
  }
  if (count < 1 || count > MODBUS_MAX_WRITE_REGISTERS) {
    errno = EMBMDATA;
    return -1;
  }
  std::uint8_t req[7 + 2 * MODBUS_MAX_WRITE_REGISTERS] = {static_cast<std::uint8_t>(slave),
                                                          MODBUS_FC_WRITE_MULTIPLE_REGISTERS};
  put16(req + 2, address);
  put16(req + 4, count);
  req[6] = static_cast<std::uint8_t>(2 * count);
  for (int i = 0; i < count; ++i) put16(req + 7 + 2 * i, src[i]);
  std::uint8_t rsp[MODBUS_MAX_ADU_LENGTH];
  const int rc = exchange(ctx, *line.lockstep, req, 7 + 2 * count, rsp);
  // Slave, function, address, quantity, CRC.
  if (!answer_ok(req, rsp, rc, 8)) return -1;
  if (get16(rsp + 2) != address || get16(rsp + 4) != count) {
    errno = EMBBADDATA;
    return -1;
  }
  return count;
}

int write_single(modbus_t* ctx, Line line, int slave, bool coil, int address, std::uint16_t value) {
  if (line.lockstep == nullptr) {
    const int function = coil ? MODBUS_FC_WRITE_SINGLE_COIL : MODBUS_FC_WRITE_SINGLE_REGISTER;
    return on_real_line(ctx, line, slave, {function, address, 1}, [&] {
      return coil ? modbus_write_bit(ctx, address, value != 0 ? 1 : 0)
                  : modbus_write_register(ctx, address, value);
    });
  }
  const int word = coil ? (value != 0 ? 0xFF00 : 0) : value;
  std::uint8_t req[6] = {static_cast<std::uint8_t>(slave),
                         static_cast<std::uint8_t>(coil ? MODBUS_FC_WRITE_SINGLE_COIL
                                                        : MODBUS_FC_WRITE_SINGLE_REGISTER)};
  put16(req + 2, address);
  put16(req + 4, word);
  std::uint8_t rsp[MODBUS_MAX_ADU_LENGTH];
  const int rc = exchange(ctx, *line.lockstep, req, sizeof req, rsp);
  // The request echoed, and the CRC.
  if (!answer_ok(req, rsp, rc, 8)) return -1;
  if (get16(rsp + 2) != address || get16(rsp + 4) != word) {
    errno = EMBBADDATA;
    return -1;
  }
  return 1;
}

}  // namespace animrt::modbus_requests
