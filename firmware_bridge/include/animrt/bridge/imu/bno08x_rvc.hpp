#pragma once
// The BNO08x UART-RVC stream (BNO080 datasheet 1000-3927, 1.3.5.2): with
// PS0 high the part sends, unasked, 100 frames a second of 19 bytes at
// 115200 baud: header 0xAA 0xAA, an 8-bit index that counts frames, yaw,
// pitch and roll in 0.01 degree and x, y, z acceleration in mg (int16
// little-endian each), three reserved bytes (zero), and a checksum that is
// the byte sum of index through reserved. Rotations apply yaw, then pitch,
// then roll. The stream carries no angular rate: the host differentiates.
//
// The same codec serves both sides: the host decodes, the simulated part
// (sim/) encodes.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "animrt/core/imu.hpp"

namespace animrt::imu {

constexpr std::size_t kRvcFrameSize = 19;
constexpr std::uint8_t kRvcHeader = 0xAA;
constexpr double kRvcHz = 100.0;
constexpr int kRvcBaud = 115200;

// One frame in the part's units.
struct RvcFrame {
  std::uint8_t index = 0;
  std::int16_t yaw_cdeg = 0, pitch_cdeg = 0, roll_cdeg = 0;  // 0.01 degree
  std::array<std::int16_t, 3> accel_mg{};                    // x, y, z
  std::array<std::uint8_t, 3> reserved{};                    // zero on today's parts
};

using RvcBytes = std::array<std::uint8_t, kRvcFrameSize>;

RvcBytes encode_rvc(const RvcFrame& frame);
// A frame from 19 bytes: nullopt for a wrong header or checksum.
std::optional<RvcFrame> decode_rvc(std::span<const std::uint8_t, kRvcFrameSize> bytes);

// The frame in SI: attitude from yaw, pitch, roll (radians) and the
// acceleration in m/s^2 (1 mg = 9.80665e-3 m/s^2). Rates are left zero.
ImuReading rvc_reading(const RvcFrame& frame, double time_s);
// The frame a part at attitude `quat` with specific force `accel_m_s2` sends
// (rounded to its units, saturated to int16).
RvcFrame rvc_frame(std::uint8_t index, const std::array<double, 4>& quat,
                   const std::array<double, 3>& accel_m_s2);

// The host's side of the stream: bytes in, whole frames out. Finds the
// header anywhere (the stream has no request: a host that opens the port
// mid-frame, or loses bytes, resynchronises on the next 0xAA 0xAA whose
// checksum holds), and counts what it threw away. Fixed buffer, no
// allocation: safe on a reader thread that must not stall.
class RvcStream {
 public:
  // Takes bytes; returns how many good frames they completed. The newest is
  // latest().
  std::size_t feed(std::span<const std::uint8_t> bytes);
  const RvcFrame& latest() const { return latest_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t checksum_errors() const { return checksum_errors_; }
  std::uint64_t skipped_bytes() const { return skipped_bytes_; }
  // Frames the index says were sent but never arrived.
  std::uint64_t lost_frames() const { return lost_frames_; }

 private:
  std::array<std::uint8_t, 2 * kRvcFrameSize> buf_{};
  std::size_t size_ = 0;
  RvcFrame latest_;
  std::uint64_t frames_ = 0, checksum_errors_ = 0, skipped_bytes_ = 0, lost_frames_ = 0;
};

}  // namespace animrt::imu
