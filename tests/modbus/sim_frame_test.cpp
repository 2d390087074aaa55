// The simulated drive's own request parsing (sim/src/modbus/modbus_frame.cpp):
// RTU frame lengths, the CRC, and the values of register writes.

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "animrt/sim/modbus/modbus_frame.hpp"

namespace animrt::sim::modbus_frame {
namespace {

// Modbus over serial line V1.02, 6.12 example: write registers 0x0001..0x0002.
TEST(ModbusSimFrame, WriteMultipleRegistersValues) {
  const std::vector<std::uint8_t> pdu = {0x10, 0x00, 0x01, 0x00, 0x02,
                                         0x04, 0x00, 0x0A, 0x01, 0x02};
  Write w;
  ASSERT_TRUE(parse_write(pdu.data(), pdu.size(), w));
  EXPECT_EQ(w.address, 1);
  EXPECT_EQ(w.count, 2);
  EXPECT_EQ(w.value(0), 0x000A);
  EXPECT_EQ(w.value(1), 0x0102);
}

TEST(ModbusSimFrame, WriteSingleAndReadWrite) {
  const std::uint8_t single[] = {0x06, 0x00, 0x01, 0x00, 0x03};
  Write w;
  ASSERT_TRUE(parse_write(single, sizeof single, w));
  EXPECT_EQ(w.address, 1);
  EXPECT_EQ(w.count, 1);
  EXPECT_EQ(w.value(0), 3);
  // Function 23: read 6 registers from 0x0003, write 1 register (0x00FF) at 0x000E.
  const std::uint8_t rw[] = {0x17, 0x00, 0x03, 0x00, 0x06, 0x00,
                             0x0E, 0x00, 0x01, 0x02, 0x00, 0xFF};
  ASSERT_TRUE(parse_write(rw, sizeof rw, w));
  EXPECT_EQ(w.address, 0x0E);
  EXPECT_EQ(w.count, 1);
  EXPECT_EQ(w.value(0), 0x00FF);
  const std::uint8_t read[] = {0x03, 0x00, 0x00, 0x00, 0x02};
  EXPECT_FALSE(parse_write(read, sizeof read, w));
}

// A write that declares 0xFFFF registers but carries none: the drive used to
// read the values past the end of the frame (past its 512-byte receive
// buffer for a goal register above 255).
TEST(ModbusSimFrame, WriteDeclaringMoreValuesThanItCarriesIsNotParsed) {
  const std::uint8_t pdu[] = {0x10, 0x00, 0x00, 0xFF, 0xFF, 0x00};
  Write w;
  EXPECT_FALSE(parse_write(pdu, sizeof pdu, w));
  const std::uint8_t cut[] = {0x10, 0x00, 0x00, 0x00, 0x02, 0x04, 0x00, 0x01, 0x00};
  EXPECT_FALSE(parse_write(cut, sizeof cut, w));
  const std::uint8_t short_single[] = {0x06, 0x00, 0x01, 0x00};
  EXPECT_FALSE(parse_write(short_single, sizeof short_single, w));
}

TEST(ModbusSimFrame, RtuLengthAndCrc) {
  // Read holding registers 0x006B x3 from slave 17 (the V1.02 example), CRC 76 87.
  const std::uint8_t read[] = {0x11, 0x03, 0x00, 0x6B, 0x00, 0x03, 0x76, 0x87};
  EXPECT_EQ(rtu_length(read, 1), 0);
  EXPECT_EQ(rtu_length(read, sizeof read), 8);
  EXPECT_EQ(crc16(read, 6), 0x8776);
  const std::uint8_t write[] = {0x11, 0x10, 0x00, 0x01, 0x00, 0x02, 0x04};
  EXPECT_EQ(rtu_length(write, 6), 0);
  EXPECT_EQ(rtu_length(write, 7), 13);
  const std::uint8_t unknown[] = {0x11, 0x63};
  EXPECT_EQ(rtu_length(unknown, 2), -1);
}

}  // namespace
}  // namespace animrt::sim::modbus_frame
