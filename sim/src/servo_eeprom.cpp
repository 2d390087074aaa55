#include "animrt/sim/servo_eeprom.hpp"

#include <algorithm>
#include <cstdlib>

namespace animrt::sim {
namespace {

constexpr int kDynamixelBauds[] = {9600,      57600,     115200,    1'000'000,
                                   2'000'000, 3'000'000, 4'000'000, 4'500'000};
constexpr int kFeetechBauds[] = {1'000'000, 500'000, 250'000, 128'000,
                                 115'200,   76'800,  57'600,  38'400};

}  // namespace

const ServoFamily kDynamixelX{"dynamixel2", 64, 7, 8, 9, 64, true, -1, kDynamixelBauds, 1, 1, 250};
const ServoFamily kFeetechSts{"feetech_sts", 40, 5, 6, 7, 40, false, 55, kFeetechBauds, 1, 0, 0};
const ServoFamily kFeetechScs{"feetech_scs", 40, 5, 6, 7, 40, false, 48, kFeetechBauds, 1, 0, 0};

std::uint8_t baud_register(const ServoFamily& family, int baud) {
  std::size_t best = 0;
  for (std::size_t i = 1; i < family.bauds.size(); ++i) {
    if (std::abs(static_cast<long>(family.bauds[i]) - baud) <
        std::abs(static_cast<long>(family.bauds[best]) - baud)) {
      best = i;
    }
  }
  return static_cast<std::uint8_t>(best);
}

int baud_of(const ServoFamily& family, std::uint8_t value) {
  return value < family.bauds.size() ? family.bauds[value] : 0;
}

EepromWrite eeprom_write(const ServoFamily& family, std::span<const std::uint8_t> table,
                         std::size_t address, std::size_t size) {
  if (size == 0 || address >= family.eeprom_end) return EepromWrite::none;
  if (family.torque_locks_eeprom && table[family.torque_address] != 0) return EepromWrite::refused;
  if (family.lock_address >= 0 && table[static_cast<std::size_t>(family.lock_address)] != 0) {
    return EepromWrite::volatile_;
  }
  return EepromWrite::kept;
}

void ServoEeprom::build(std::span<const std::uint8_t> table) {
  const auto end = table.begin() + static_cast<std::ptrdiff_t>(family_->eeprom_end);
  kept_.assign(table.begin(), end);
  factory_ = kept_;
  factory_[family_->id_address] = family_->factory_id;
  factory_[family_->baud_address] = family_->factory_baud;
  factory_[family_->return_delay_address] = family_->factory_return_delay;
}

void ServoEeprom::keep(std::span<const std::uint8_t> table) {
  if (std::equal(kept_.begin(), kept_.end(), table.begin())) return;
  std::copy_n(table.begin(), kept_.size(), kept_.begin());
  ++changes_;
}

void ServoEeprom::load(std::span<std::uint8_t> table) const {
  std::copy(kept_.begin(), kept_.end(), table.begin());
}

bool ServoEeprom::restore(std::span<const std::uint8_t> kept, std::span<std::uint8_t> table) {
  if (kept.size() != kept_.size()) return false;
  std::copy(kept.begin(), kept.end(), table.begin());
  keep(table);
  return true;
}

void ServoEeprom::factory_reset(std::span<std::uint8_t> table, bool keep_id, bool keep_baud) {
  const std::uint8_t id = table[family_->id_address];
  const std::uint8_t baud = table[family_->baud_address];
  std::copy(factory_.begin(), factory_.end(), table.begin());
  if (keep_id) table[family_->id_address] = id;
  if (keep_baud) table[family_->baud_address] = baud;
  keep(table);
}

}  // namespace animrt::sim
