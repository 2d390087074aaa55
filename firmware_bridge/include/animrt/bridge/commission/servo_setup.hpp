#pragma once
// Sets up one serial servo (Dynamixel Protocol 2.0 or Feetech SCS/STS):
// id, baud rate, return delay, operating mode, its own position limits,
// reboot and factory reset. Every change is read back from the servo; a
// change that does not read back, or a servo that does not answer, is a
// DeviceError with one line saying what and where.

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "animrt/bridge/byte_transport.hpp"

namespace animrt::commission {

enum class Family : std::uint8_t { dynamixel2, feetech };

class ServoSetup {
 public:
  // Opens the line at a baud rate (the servo's, or the new one after set_baud).
  using Open = std::function<std::unique_ptr<ByteTransport>(int baud)>;

  // Pings `id` at `baud`; throws DeviceError if it does not answer, or if
  // several servos answer as that id.
  ServoSetup(Family family, Open open, int id, int baud, std::chrono::microseconds timeout);

  // Each returns what was done ("id 1 -> 7 (read back)").
  std::string set_id(int new_id);
  std::string set_baud(int new_baud);
  std::string set_return_delay(int microseconds);
  std::string set_mode(const std::string& mode);
  std::string set_limits(long min_ticks, long max_ticks);
  std::string reboot();
  // Dynamixel: everything but id and baud rate back to factory values (so
  // the servo stays reachable where it is); Feetech: its Reset instruction.
  std::string factory_reset();

  // Names set_mode takes, for this family.
  std::string mode_names() const;
  // The highest id a servo of `family` takes (0 is the lowest).
  static int max_id(Family family);

 private:
  std::string where() const;  // "<protocol> id N at B baud on PORT"
  [[noreturn]] void fail(const std::string& what) const;
  void check_answers(int id);  // ping; fail() unless exactly one servo answers
  void require_torque_off();
  // Writes `bytes` at `address`, then reads them back at `read_id`.
  void write_verified(std::uint16_t address, std::span<const std::uint8_t> bytes, int read_id,
                      const std::string& what);
  void write(std::uint16_t address, std::span<const std::uint8_t> bytes, const std::string& what);
  std::vector<std::uint8_t> read(int id, std::uint16_t address, std::uint16_t length,
                                 const std::string& what);
  void wait_for_answer(const std::string& after);
  void lock_eeprom(int id, bool locked);
  bool sts() const;

  Family family_;
  Open open_;
  std::unique_ptr<ByteTransport> line_;
  int id_;
  int baud_;
  std::chrono::microseconds timeout_;
  bool scs_ = false;  // Feetech SCS series (high byte first, 1024 steps)
};

}  // namespace animrt::commission
