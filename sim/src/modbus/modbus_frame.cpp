#include "animrt/sim/modbus/modbus_frame.hpp"

#include <modbus.h>

namespace animrt::sim::modbus_frame {
namespace {

int get16(const std::uint8_t* p) { return (p[0] << 8) | p[1]; }

}  // namespace

std::uint16_t crc16(const std::uint8_t* p, std::size_t n) {
  std::uint16_t crc = 0xFFFF;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= p[i];
    for (int b = 0; b < 8; ++b)
      crc = (crc & 1) ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001) : crc >> 1;
  }
  return crc;
}

int rtu_length(const std::uint8_t* b, std::size_t have) {
  if (have < 2) return 0;
  switch (b[1]) {
    case 1:
    case 2:
    case 3:
    case 4:
    case 5:
    case 6:
      return 8;
    case 15:
    case 16:
      return have < 7 ? 0 : 9 + b[6];
    case 23:
      return have < 11 ? 0 : 13 + b[10];
    case 22:
      return 10;
    case 17:
      return 4;
    default:
      return -1;
  }
}

bool parse_write(const std::uint8_t* pdu, std::size_t length, Write& out) {
  if (length < 1) return false;
  std::size_t values_at = 0;
  switch (pdu[0]) {
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
      if (length < 5) return false;
      out.address = get16(pdu + 1);
      out.count = 1;
      values_at = 3;
      break;
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
      if (length < 6) return false;
      out.address = get16(pdu + 1);
      out.count = get16(pdu + 3);
      values_at = 6;
      break;
    case MODBUS_FC_WRITE_AND_READ_REGISTERS:
      if (length < 10) return false;
      out.address = get16(pdu + 5);
      out.count = get16(pdu + 7);
      values_at = 10;
      break;
    default:
      return false;
  }
  if (values_at + 2 * static_cast<std::size_t>(out.count) > length) return false;
  out.values = pdu + values_at;
  return true;
}

}  // namespace animrt::sim::modbus_frame
