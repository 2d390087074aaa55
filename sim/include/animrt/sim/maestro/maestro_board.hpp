#pragma once
// Firmware of one simulated Pololu Maestro: channels configured as servos,
// the command set of maestro_codec.hpp, the board's speed and acceleration
// limits on the output pulse, and the error register. No I/O.
//
// Output model (per channel, quarter-microseconds), updated every 10 ms tick
// of the board's clock, as the user's guide describes the limits:
//  - speed S (0.25 us per 10 ms) bounds how far the output moves per tick;
//  - acceleration A (0.25 us per 10 ms per 80 ms) bounds how much that step
//    may grow or shrink per tick (A/8), so the output speeds up, cruises and
//    slows down to stop at the target;
//  - S = A = 0: the output jumps to the target; target 0 switches pulses off,
//    and a channel that was off jumps straight to its first target.
// Targets outside the channel's min..max pulse are clamped to it.
// Errors: a stray data byte, an unknown command, a command cut short, a
// channel the board does not have, or a multi-target block past the last
// channel set the serial protocol error bit; on any error the board sends
// every channel home (here: off), as the factory settings do. Get Errors
// answers and clears the register.
// Serial timeout (a setting, made in the Maestro Control Center, not over
// the line): when no valid command reached the board for longer than it, the
// serial timeout error bit is set and every channel goes home (off), at that
// instant of the board's clock however late the next command comes; it
// fires again after each further timeout of silence.

#include <cstdint>
#include <span>
#include <vector>

#include "animrt/bridge/maestro/maestro_codec.hpp"
#include "animrt/core/clock.hpp"

namespace animrt::sim {

struct MaestroChannelSetup {
  int channel = 0;
  double min_us = 992.0;
  double max_us = 2000.0;
};

class MaestroBoard {
 public:
  static constexpr Nanos kTick = 10'000'000;  // 10 ms

  MaestroBoard(int device_number, int channels, std::span<const MaestroChannelSetup> setup,
               Nanos now);

  int device_number() const { return device_; }
  // The board's serial timeout setting; 0 (the factory setting): none.
  void set_serial_timeout(Nanos timeout) { serial_timeout_ = timeout; }
  int channels() const { return static_cast<int>(channels_.size()); }

  // Handles one command addressed to this board (compact, or Pololu form with
  // this device number) at time `now`; appends any answer bytes to `out`.
  void handle(const maestro::Command& command, Nanos now, std::vector<std::uint8_t>& out);
  // A protocol-level error on the line (seen by every board).
  void protocol_error(Nanos now);

  // Brings the outputs to `now` (never back).
  void advance(Nanos now);
  std::uint16_t position(int channel) const { return channels_.at(channel).position; }
  std::uint16_t target(int channel) const { return channels_.at(channel).target; }
  std::uint16_t errors() const { return errors_; }

  // Fault injection: error bits as if the board had detected them.
  void raise_errors(std::uint16_t bits, Nanos now);
  bool responding() const { return responding_; }
  void set_responding(bool responding) { responding_ = responding; }

 private:
  struct Channel {
    std::uint16_t min_q = 3968, max_q = 8000;  // quarter-us
    std::uint16_t target = 0, position = 0;    // 0 = off
    std::uint16_t speed = 0, acceleration = 0;
    double step = 0.0;  // quarter-us moved in the last tick (for acceleration)
  };
  void tick(Channel& c) const;
  void advance_ticks(Nanos now);
  void set_target(Channel& c, std::uint16_t target) const;
  void fail(std::uint16_t bits);

  int device_;
  std::vector<Channel> channels_;
  std::uint16_t errors_ = 0;
  Nanos tick_time_;  // time of the last tick
  Nanos serial_timeout_ = 0;
  Nanos last_command_;  // the latest valid command (or serial timeout)
  bool responding_ = true;
};

}  // namespace animrt::sim
