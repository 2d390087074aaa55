// CANopen frames (SDO, EMCY) and the CiA 402 words they carry. The input is
// a sequence of frames: id (2 bytes), dlc (1 byte, any value up to 255, as a
// broken driver might report), then up to 8 data bytes.

#include <linux/can.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace animrt;
  std::size_t pos = 0;
  std::uint16_t previous = 0;
  while (size - pos >= 3) {
    can_frame f{};
    f.can_id = static_cast<canid_t>(data[pos] | (data[pos + 1] << 8)) & CAN_SFF_MASK;
    f.can_dlc = data[pos + 2];
    pos += 3;
    const std::size_t n = std::min<std::size_t>({8, f.can_dlc, size - pos});
    std::memcpy(f.data, data + pos, n);
    pos += n;

    const canopen::Sdo sdo = canopen::parse_sdo(f);
    if (sdo.kind == canopen::SdoKind::abort) (void)canopen::sdo_abort_text(sdo.value);
    canopen::Emcy emcy;
    if (canopen::parse_emcy(f, emcy)) (void)canopen::emcy_class(emcy.code);

    const auto word = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
    const cia402::State state = cia402::decode_statusword(word);
    (void)cia402::to_string(state);
    const cia402::Command command = cia402::decode_controlword(word, previous);
    (void)cia402::to_string(command);
    int transition = 0;
    (void)cia402::next_state(state, command, &transition);
    (void)cia402::controlword_toward(state, cia402::decode_statusword(previous), previous);
    previous = word;
  }
  return 0;
}
