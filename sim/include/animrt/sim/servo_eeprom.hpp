#pragma once
// The non-volatile half of a simulated serial servo's control table, shared
// by every family (Dynamixel X, Feetech STS/SCS): which addresses are EEPROM,
// when a write to them is refused or kept, the copy that survives a reboot,
// a power cycle and (with a state file) an `animrt sim` restart, the factory
// settings a Factory Reset or `animrt sim --factory` brings back, and the
// Baud Rate register's code. What differs between families is data: the
// ServoFamily model table.

#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace animrt::sim {

struct ServoFamily {
  std::string_view name;   // as in the state file: "dynamixel2", "feetech_sts", "feetech_scs"
  std::size_t eeprom_end;  // first RAM address: below it, EEPROM
  std::uint16_t id_address;
  std::uint16_t baud_address;
  std::uint16_t return_delay_address;
  std::uint16_t torque_address;
  bool torque_locks_eeprom;    // Dynamixel: EEPROM writes refused while torque is on
  int lock_address;            // Feetech: EEPROM writes kept only while this reads 0; -1: none
  std::span<const int> bauds;  // Baud Rate register value -> bits per second
  std::uint8_t factory_id;     // factory settings
  std::uint8_t factory_baud;   // (register value)
  std::uint8_t factory_return_delay;
};

// X-series e-manual: ID 1, 57600 baud, Return Delay Time 250 (500 us).
extern const ServoFamily kDynamixelX;
// STS3215 / SCS memory tables: ID 1, 1,000,000 baud, return delay 0.
extern const ServoFamily kFeetechSts;
extern const ServoFamily kFeetechScs;

// Baud Rate register value for `baud`: its code, or the nearest one's.
std::uint8_t baud_register(const ServoFamily& family, int baud);
// Bits per second of a register value; 0 for a value with no baud.
int baud_of(const ServoFamily& family, std::uint8_t value);

// What a write of `size` bytes at `address` does to EEPROM, judged on the
// table before the write.
enum class EepromWrite {
  none,       // RAM only
  refused,    // torque is on (Dynamixel): Access Error, nothing changes
  volatile_,  // applied, but lost at power-off (Feetech with the lock set)
  kept,       // applied and kept
};
EepromWrite eeprom_write(const ServoFamily& family, std::span<const std::uint8_t> table,
                         std::size_t address, std::size_t size);

class ServoEeprom {
 public:
  explicit ServoEeprom(const ServoFamily& family) : family_(&family) {}
  // The table's EEPROM part as built (the servo configured for its robot
  // file) is what it keeps; the factory image is the same with the family's
  // factory ID, baud and return delay.
  void build(std::span<const std::uint8_t> table);

  const ServoFamily& family() const { return *family_; }
  std::span<const std::uint8_t> kept() const { return kept_; }
  // Counts changes of what is kept (the state file saves when it moves).
  std::uint64_t changes() const { return changes_; }

  // After a write that EEPROM keeps: the table's EEPROM part is kept.
  void keep(std::span<const std::uint8_t> table);
  // Power-on: the table's EEPROM part from what was kept.
  void load(std::span<std::uint8_t> table) const;
  // What a state file kept; false (nothing changes) when its size is not
  // this family's EEPROM size.
  bool restore(std::span<const std::uint8_t> kept, std::span<std::uint8_t> table);
  // Factory settings into the table and what is kept, but the ID and/or
  // the baud rate where asked to keep them.
  void factory_reset(std::span<std::uint8_t> table, bool keep_id, bool keep_baud);

 private:
  const ServoFamily* family_;
  std::vector<std::uint8_t> factory_;
  std::vector<std::uint8_t> kept_;
  std::uint64_t changes_ = 0;
};

}  // namespace animrt::sim
