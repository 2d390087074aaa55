#pragma once
// The status packets simulated serial servos put on the line for one
// instruction packet, shared by every family: back to back in `bytes`, in
// the order they appear on the wire. And what the line does when two
// servos answer at once (two sharing an ID): their packets collide.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "animrt/core/clock.hpp"

namespace animrt::sim {

struct Answers {
  struct Answer {
    std::size_t offset = 0;
    std::size_t size = 0;
    int return_delay_us = 0;  // the answering servo's Return Delay Time
    Nanos late_ns = 0;        // injected lateness (DynamixelServo::set_answer_delay)
  };
  std::vector<std::uint8_t> bytes;
  std::vector<Answer> list;

  void clear() {
    bytes.clear();
    list.clear();
  }
  std::span<const std::uint8_t> packet(const Answer& a) const {
    return {bytes.data() + a.offset, a.size};
  }
};

// The answers from `first` on (the last ones added) were sent at once by
// servos sharing an ID: their drivers fight on the half-duplex line and no
// two servos' clocks agree. Modelled as one answer, the OR of the packets,
// each a byte behind the one before, so the host reads a corrupt packet
// (its checksum fails) where a single servo would have answered.
void collide(Answers& out, std::size_t first);

}  // namespace animrt::sim
