// Register maps: data types, word order, scale and offset, and validation
// errors that name the file, line, column and key.

#include "animrt/bridge/modbus/register_map.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace animrt::modbus {
namespace {

const std::string kGood = R"(name: test drive
unit: rad
goal: {table: holding, address: 0, type: int32, word_order: high_first, scale: 0.001}
present: {table: input, address: 0, type: float32, word_order: low_first, scale: 1, offset: 0.5}
status:
  table: input
  address: 2
  type: uint16
  fault_bits: {0: overcurrent, 5: overtemperature}
enable: {register: 4, on: 257, off: 0}
)";

std::string error_of(const std::string& text) {
  try {
    load_register_map_text(text, "map.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  text.replace(text.find(from), from.size(), to);
  return text;
}

TEST(RegisterMap, LoadsAGoodMap) {
  auto m = load_register_map_text(kGood, "map.yaml");
  EXPECT_EQ(m->unit, "rad");
  EXPECT_EQ(m->goal.words(), 2);
  EXPECT_EQ(m->fault_mask, 0x21);
  EXPECT_EQ(m->fault_text(0x21), "overcurrent, overtemperature");
  EXPECT_TRUE(m->enable.configured);
  EXPECT_FALSE(m->enable.coil);
  EXPECT_EQ(m->enable.on, 257);
}

TEST(RegisterMap, DataTypesWordOrderScaleOffset) {
  Register r;
  std::uint16_t w[2];
  r.type = DataType::int32;
  r.order = WordOrder::high_first;
  r.scale = 0.001;
  r.encode(-1.5, w);  // -1500 = 0xFFFFFA24
  EXPECT_EQ(w[0], 0xFFFF);
  EXPECT_EQ(w[1], 0xFA24);
  EXPECT_DOUBLE_EQ(r.decode(w), -1.5);
  r.order = WordOrder::low_first;
  r.encode(70.000, w);  // 70000 = 0x00011170
  EXPECT_EQ(w[0], 0x1170);
  EXPECT_EQ(w[1], 0x0001);
  EXPECT_DOUBLE_EQ(r.decode(w), 70.0);

  r.type = DataType::float32;
  r.order = WordOrder::high_first;
  r.scale = 1.0;
  r.offset = 0.5;
  r.encode(1.75, w);  // raw 1.25f = 0x3FA00000
  EXPECT_EQ(w[0], 0x3FA0);
  EXPECT_EQ(w[1], 0x0000);
  EXPECT_DOUBLE_EQ(r.decode(w), 1.75);

  Register s;
  s.type = DataType::int16;
  s.scale = 0.01;
  s.encode(-0.02, w);
  EXPECT_EQ(w[0], 0xFFFE);
  EXPECT_DOUBLE_EQ(s.decode(w), -0.02);
  s.encode(1e9, w);  // saturates
  EXPECT_EQ(w[0], 0x7FFF);
  s.type = DataType::uint16;
  s.encode(-5, w);
  EXPECT_EQ(w[0], 0);
}

TEST(RegisterMap, ValidationErrorsNameFileLineAndKey) {
  EXPECT_EQ(error_of(replaced(kGood, "type: float32", "type: float64")),
            "map.yaml:4:43: present.type: unknown type \"float64\" (expected int16, uint16, int32, "
            "uint32 or float32)");
  EXPECT_EQ(error_of(replaced(kGood, ", scale: 0.001}", "}")),
            "map.yaml:3:7: goal.scale: required key is missing");
  EXPECT_EQ(
      error_of(replaced(kGood, "address: 2", "address: 1")),
      "map.yaml:6:3: status: registers overlap: status (input 1) overlaps present (input 0..1)");
  EXPECT_EQ(
      error_of(replaced(kGood, "register: 4", "register: 1")),
      "map.yaml:10:9: enable: registers overlap: enable (holding 1) overlaps goal (holding 0..1)");
  EXPECT_EQ(
      error_of(replaced(kGood, "goal: {table: holding", "goal: {table: input")),
      "map.yaml:3:15: goal.table: expected holding (a goal must be writable), found \"input\"");
  EXPECT_EQ(
      error_of(replaced(kGood, "scale: 0.001", "scale: 0")),
      "map.yaml:3:80: goal.scale: expected a non-zero number (SI units per count), found \"0\"");
  EXPECT_EQ(error_of(replaced(kGood, "unit: rad", "unit: deg")),
            "map.yaml:2:7: unit: expected rad or m, found \"deg\"");
  EXPECT_EQ(
      error_of(replaced(kGood, "5: overtemperature", "16: overtemperature")),
      "map.yaml:9:36: status.fault_bits.16: expected a bit number 0..15 as the key, found \"16\"");
}

TEST(RegisterMap, AHealthSectionNamesCurrentTemperatureVoltageAndFaultCode) {
  const std::string text = kGood +
                           "health:\n"
                           "  current: {table: input, address: 5, type: int16, scale: 0.01}\n"
                           "  temperature: {table: input, address: 6, type: int16, scale: 0.1}\n"
                           "  fault_code: {table: holding, address: 7, type: uint16}\n";
  auto m = load_register_map_text(text, "map.yaml");
  ASSERT_TRUE(m->health.current && m->health.temperature && m->health.fault_code);
  EXPECT_FALSE(m->health.voltage);
  const std::uint16_t raw = static_cast<std::uint16_t>(-250);
  EXPECT_DOUBLE_EQ(m->health.current->decode(&raw), -2.5);
  EXPECT_EQ(m->spans().size(), 7u);
  EXPECT_EQ(error_of(replaced(text, "address: 6", "address: 2")),
            "map.yaml:13:16: health.temperature: registers overlap: health.temperature (input 2) "
            "overlaps status (input 2)");
  EXPECT_EQ(error_of(replaced(text, "address: 7, type: uint16}",
                              "address: 7, type: uint16, "
                              "scale: 2}")),
            "map.yaml:14:58: health.fault_code.scale: unknown key (expected one of: table, "
            "address, type, codes)");
  // The drive's own names for its fault codes, for the fault line.
  const auto named = load_register_map_text(
      replaced(text, "address: 7, type: uint16}",
               "address: 7, type: uint16, codes: {0x4310: overtemperature, 17: overload}}"),
      "map.yaml");
  EXPECT_EQ(named->health.code_name(0x4310), "overtemperature");
  EXPECT_EQ(named->health.code_name(17), "overload");
  EXPECT_EQ(named->health.code_name(18), "");
  EXPECT_EQ(error_of(replaced(text, "address: 7, type: uint16}",
                              "address: 7, type: uint16, codes: {0x10000: x}}")),
            "map.yaml:14:75: health.fault_code.codes.0x10000: expected a fault code 1..65535 "
            "(decimal or 0x hex) as the key, found \"0x10000\"");
  EXPECT_EQ(error_of(kGood + "health: {}\n"),
            "map.yaml:11:9: health: expected at least one of current, temperature, voltage, "
            "fault_code");
}

}  // namespace
}  // namespace animrt::modbus
