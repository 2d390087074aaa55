#pragma once
// A drive's register map, read from YAML (configs/modbus/*.yaml), so any
// Modbus drive can be wired without code: where the goal and the present
// value live, their data type and word order, the scale and offset to SI
// units, the enable coil or register, and the status register's fault bits.
//
//   SI value = raw * scale + offset            (raw as the data type reads it)
//
// The same map serves the master (runtime) and the simulated drive.

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "animrt/core/error.hpp"

namespace animrt::modbus {

enum class Table : std::uint8_t { holding, input };
enum class DataType : std::uint8_t { int16, uint16, int32, uint32, float32 };
enum class WordOrder : std::uint8_t { high_first, low_first };

const char* to_string(Table table);
const char* to_string(DataType type);

struct Register {
  Table table = Table::holding;
  int address = 0;  // 0-based protocol address
  DataType type = DataType::int16;
  WordOrder order = WordOrder::high_first;
  double scale = 1.0;
  double offset = 0.0;
  Location where;

  int words() const { return type == DataType::int16 || type == DataType::uint16 ? 1 : 2; }
  int end() const { return address + words(); }  // one past the last register

  // Raw words <-> SI value. encode() rounds and saturates to the type's range.
  double decode(const std::uint16_t* words) const;
  void encode(double si, std::uint16_t* words) const;
};

struct Enable {
  bool configured = false;
  bool coil = true;  // coil, or a holding register
  int address = 0;
  std::uint16_t on = 1;
  std::uint16_t off = 0;
  Location where;
};

// The drive's communication timeout (a watchdog against a dead host): a
// holding register, uint16, in counts of unit_ms, 0 = off. When no request
// reaches the drive for that long, the drive takes its own action (stop or
// disable, set with the vendor's tool). The bus writes it when it arms the
// device guards and clears it at a clean deactivate.
struct Watchdog {
  bool configured = false;
  int address = 0;
  double unit_ms = 1.0;
  Location where;
};

// What the drive says about itself (the map's `health` section), read by a
// bus with `health` on: each register optional; current (A), temperature
// (deg C) and supply voltage (V) scaled like goal and present, the fault
// code unscaled (0: no fault; any other value is the drive's own fault).
struct FaultCode {
  std::uint16_t code = 0;
  std::string name;
};

struct HealthRegisters {
  std::optional<Register> current;
  std::optional<Register> temperature;
  std::optional<Register> voltage;
  std::optional<Register> fault_code;
  std::vector<FaultCode> codes;  // fault_code.codes: names of the drive's codes
  Location where;

  // The name the map gives `code`, or "" when it names none.
  std::string code_name(std::uint32_t code) const;

  bool any() const { return current || temperature || voltage || fault_code; }
  // Those given, for planning reads and overlap checks.
  std::vector<const Register*> list() const;
};

struct FaultBit {
  int bit = 0;
  std::string name;
};

struct RegisterMap {
  std::string file;
  std::string name;
  std::string unit;  // "rad" or "m": what goal/present are in after scaling
  Register goal;     // holding
  Register present;  // holding or input
  bool has_status = false;
  Register status;  // holding or input, int16/uint16
  std::uint16_t fault_mask = 0;
  std::vector<FaultBit> faults;
  HealthRegisters health;
  Enable enable;
  Watchdog watchdog;
  bool has_range = false;
  double range_min = 0.0, range_max = 0.0;  // goal values the drive accepts (SI)

  // "overcurrent, following error" for the set bits.
  std::string fault_text(std::uint16_t status_value) const;
  // Registers a joint occupies, for overlap checks: (table, begin, end).
  std::vector<std::pair<Table, std::pair<int, int>>> spans() const;
};

// Loads and validates a map file. Throws InputError naming the file, line,
// column and key: unknown type or table, missing scale, overlapping
// registers, a goal outside the holding registers, and so on.
std::shared_ptr<const RegisterMap> load_register_map(const std::string& path);
std::shared_ptr<const RegisterMap> load_register_map_text(const std::string& text,
                                                          const std::string& file_name);

}  // namespace animrt::modbus
