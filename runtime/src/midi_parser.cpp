#include "animrt/runtime/midi_input.hpp"

namespace animrt {
namespace {

// Data bytes of a channel message, by its kind (the status's high nibble).
int channel_data_bytes(int status) {
  const int kind = status & 0xf0;
  return kind == 0xc0 || kind == 0xd0 ? 1 : 2;
}

// Data bytes of a system common message (0xf1-0xf6).
int common_data_bytes(int status) {
  if (status == 0xf1 || status == 0xf3) return 1;
  if (status == 0xf2) return 2;
  return 0;
}

}  // namespace

bool MidiParser::feed(std::uint8_t byte, MidiMessage& out) {
  if (byte >= 0xf8) return false;  // real time: anywhere, changes nothing
  if (byte & 0x80) {
    if (in_sysex_) {
      in_sysex_ = false;  // 0xf7 ends it; any other status ends it too
      if (byte == 0xf7) return false;
    }
    if (byte == 0xf0) {
      in_sysex_ = true;
      ++sysex_;
      status_ = 0;
      return false;
    }
    if (byte >= 0xf0) {  // system common: cancels the running status
      status_ = 0;
      common_left_ = common_data_bytes(byte);
      return false;
    }
    status_ = byte;
    needed_ = channel_data_bytes(byte);
    have_ = 0;
    common_left_ = 0;
    return false;
  }
  if (in_sysex_) return false;
  if (common_left_ > 0) {
    --common_left_;
    return false;
  }
  if (status_ == 0) {
    ++malformed_;
    return false;
  }
  data_[have_++] = byte;
  if (have_ < needed_) return false;
  have_ = 0;  // running status: the next data bytes are another message of this kind
  out = {status_, data_[0], needed_ > 1 ? data_[1] : 0};
  return true;
}

int midi_cue(const MidiMessage& message, const std::vector<MidiBinding>& bindings) {
  const int kind = message.status & 0xf0;
  const int channel = (message.status & 0x0f) + 1;
  const bool note_on = kind == 0x90 && message.data2 > 0;
  const bool program = kind == 0xc0;
  if (!note_on && !program) return -1;
  int cue = -1;
  for (const MidiBinding& b : bindings) {
    if (b.program == program && b.number == message.data1 &&
        (b.channel == 0 || b.channel == channel)) {
      cue = b.cue;
    }
  }
  return cue;
}

}  // namespace animrt
