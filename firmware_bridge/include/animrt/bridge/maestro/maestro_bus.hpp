#pragma once
// Master side of Pololu Maestro servo controllers on one serial line (one
// board in the compact protocol, or daisy-chained boards addressed by device
// number in the Pololu protocol). Hobby servos report nothing: the measured
// position is the board's own output pulse (Get Position), which follows the
// target through the board's speed and acceleration limits. Every device is
// therefore flagged DeviceStatus::open_loop.
//
// Per cycle and board: read() sends Get Position for each channel and Get
// Errors in one burst and reads the 2-byte answers in order; write() sends
// Set Multiple Targets per contiguous block of channels (Set Target on a
// Micro Maestro, which lacks it). A non-zero error register is a hardware
// error of every channel on that board (the board itself sends its servos
// home on any error).

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/maestro/maestro_codec.hpp"
#include "animrt/bridge/status_book.hpp"

namespace animrt {

// BusConfig::options of a "maestro" bus.
struct MaestroBusOptions {
  maestro::Form form = maestro::Form::compact;
  int channels = 12;                     // per board: 6, 12, 18 or 24
  bool multiple_targets = true;          // Set Multiple Targets (Mini Maestro only)
  int device = maestro::kDefaultDevice;  // default device number of the channels (Pololu form)
  // The serial timeout the board should have (ms, 0: none). The Maestro takes
  // it only from its settings (Maestro Control Center, Serial Settings:
  // Timeout), never over the serial line, so animrt can only say so.
  double serial_timeout_ms = 0.0;
};

// ActuatorBinding::options of a Maestro channel. The binding's ticks are
// quarter-microseconds: zero_ticks = 4 * neutral_us, ticks_per_rad =
// 4 / |rad_per_us|, direction = sign(rad_per_us).
struct MaestroChannelOptions {
  int device = maestro::kDefaultDevice;  // board's device number (Pololu form)
  int channel = 0;
  double min_us = 992.0;
  double max_us = 2000.0;
  double neutral_us = 1500.0;
  double rad_per_us = 0.0;  // with sign
  int speed = 0;            // board units (0.25 us / 10 ms), 0 = unlimited
  int acceleration = 0;     // board units (0.25 us / 10 ms / 80 ms), 0 = unlimited
};

class MaestroBus final : public ActuatorBus {
 public:
  // Throws DeviceError for bindings without MaestroChannelOptions, channels
  // used twice, or more channels than the board has.
  MaestroBus(BusConfig config, std::unique_ptr<ByteTransport> transport);

  const BusConfig& config() const override { return config_; }
  // Reads every position and clears each board's error register; throws
  // DeviceError listing every board that did not answer. A channel whose
  // output is off (position 0) is reported at its neutral pulse. A serial
  // timeout the board latched (the host before us went silent) is cleared
  // with a warning (timeout_warning()).
  void configure() override;
  // Clears a serial timeout latched since configure() (the board's setting
  // may be shorter than the pause before activation), then speed and
  // acceleration limits, then target = present output (which switches the
  // pulses on without a jump); throws DeviceError on any other error bit.
  void activate() override;
  // The board's serial timeout is its own setting, always on, so it may have
  // fired while the other buses came up: the channels it sent home would
  // jump back at the first target. Get Errors tells (and clears it); then
  // the run is refused (DeviceError) rather than started.
  void arm_device_guard() override;
  // The warning configure() printed about serial timeouts that had fired;
  // empty when none had.
  const std::string& timeout_warning() const { return timeout_warning_; }
  // Target 0 (pulses off: the servos go limp), best effort.
  void deactivate() override;
  void read(std::span<double> positions) override;
  void write(std::span<const double> positions) override;
  std::span<DeviceStatus> devices() override { return book_.devices(); }

  // The last error register read from each board, by board index.
  std::uint16_t board_errors(std::size_t board) const { return boards_[board].last_errors; }

 private:
  struct Board {
    maestro::Address address;
    std::vector<std::size_t> devices;  // indices into config_.actuators, by channel order
    std::uint16_t last_errors = 0;
  };
  enum class Outcome : std::uint8_t { ok, timeout, truncated };

  // One burst of Get Position (+ Get Errors) to a board; fills
  // positions_ticks_ for channels that answered. Returns false if the board's
  // answers did not all arrive.
  bool poll_board(Board& board, bool count);
  std::size_t receive(std::size_t want, std::chrono::microseconds timeout);
  void read_away_owed();
  void send(std::size_t length);
  std::uint16_t target_of(std::size_t device, double rad) const;
  std::string prefix() const { return book_.prefix(); }

  BusConfig config_;
  MaestroBusOptions options_;
  std::unique_ptr<ByteTransport> transport_;
  std::chrono::microseconds timeout_;
  std::vector<MaestroChannelOptions> channels_;  // per device
  std::vector<Board> boards_;
  StatusBook book_;
  std::vector<std::uint16_t> present_;  // quarter-us, latest known
  std::vector<std::uint16_t> goal_;     // quarter-us, latest sent
  std::vector<std::uint8_t> answered_;  // scratch, per device
  std::vector<std::uint16_t> block_;    // scratch for Set Multiple Targets
  bool fresh_ = false;
  std::string timeout_warning_;
  // The bytes a burst's answer still owed when it was given up: they carry
  // no channel or board, so they are read away before the next burst.
  std::size_t owed_bytes_ = 0;
  std::chrono::steady_clock::time_point owed_until_{};
  std::array<std::uint8_t, 512> tx_{};
  std::array<std::uint8_t, 512> rx_{};
};

}  // namespace animrt
