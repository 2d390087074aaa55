// The BNO08x UART-RVC codec (see bno08x_rvc.hpp).

#include "animrt/bridge/imu/bno08x_rvc.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace animrt::imu {
namespace {

constexpr double kMilliG = 9.80665e-3;  // m/s^2 per mg
constexpr double kCentiDeg = std::numbers::pi / 18000.0;

std::uint8_t checksum(std::span<const std::uint8_t> payload) {
  unsigned sum = 0;
  for (std::uint8_t b : payload) sum += b;
  return static_cast<std::uint8_t>(sum & 0xFF);
}

void put16(std::uint8_t* p, std::int16_t v) {
  const auto u = static_cast<std::uint16_t>(v);
  p[0] = static_cast<std::uint8_t>(u & 0xFF);
  p[1] = static_cast<std::uint8_t>(u >> 8);
}

std::int16_t get16(const std::uint8_t* p) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>(p[0] | (p[1] << 8)));
}

std::int16_t saturate16(double v) {
  return static_cast<std::int16_t>(std::clamp(std::lround(v), -32768L, 32767L));
}

}  // namespace

RvcBytes encode_rvc(const RvcFrame& f) {
  RvcBytes b{};
  b[0] = kRvcHeader;
  b[1] = kRvcHeader;
  b[2] = f.index;
  put16(&b[3], f.yaw_cdeg);
  put16(&b[5], f.pitch_cdeg);
  put16(&b[7], f.roll_cdeg);
  for (int i = 0; i < 3; ++i) put16(&b[9 + 2 * i], f.accel_mg[i]);
  for (int i = 0; i < 3; ++i) b[15 + i] = f.reserved[i];
  b[18] = checksum(std::span(b).subspan(2, 16));
  return b;
}

std::optional<RvcFrame> decode_rvc(std::span<const std::uint8_t, kRvcFrameSize> b) {
  if (b[0] != kRvcHeader || b[1] != kRvcHeader) return std::nullopt;
  if (checksum(b.subspan(2, 16)) != b[18]) return std::nullopt;
  RvcFrame f;
  f.index = b[2];
  f.yaw_cdeg = get16(&b[3]);
  f.pitch_cdeg = get16(&b[5]);
  f.roll_cdeg = get16(&b[7]);
  for (int i = 0; i < 3; ++i) f.accel_mg[i] = get16(&b[9 + 2 * i]);
  for (int i = 0; i < 3; ++i) f.reserved[i] = b[15 + i];
  return f;
}

ImuReading rvc_reading(const RvcFrame& f, double time_s) {
  ImuReading r;
  r.quat = quat_from_ypr(f.yaw_cdeg * kCentiDeg, f.pitch_cdeg * kCentiDeg, f.roll_cdeg * kCentiDeg);
  for (int i = 0; i < 3; ++i) r.accel_m_s2[i] = f.accel_mg[i] * kMilliG;
  r.time_s = time_s;
  return r;
}

RvcFrame rvc_frame(std::uint8_t index, const std::array<double, 4>& quat,
                   const std::array<double, 3>& accel_m_s2) {
  RvcFrame f;
  f.index = index;
  f.yaw_cdeg = saturate16(yaw_of(quat) / kCentiDeg);
  f.pitch_cdeg = saturate16(pitch_of(quat) / kCentiDeg);
  f.roll_cdeg = saturate16(roll_of(quat) / kCentiDeg);
  for (int i = 0; i < 3; ++i) f.accel_mg[i] = saturate16(accel_m_s2[i] / kMilliG);
  return f;
}

std::size_t RvcStream::feed(std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  for (std::uint8_t byte : bytes) {
    buf_[size_++] = byte;
    // Keep the buffer at the start of a candidate header.
    while (size_ > 0) {
      if (buf_[0] != kRvcHeader || (size_ >= 2 && buf_[1] != kRvcHeader)) {
        std::memmove(buf_.data(), buf_.data() + 1, size_ - 1);
        --size_;
        ++skipped_bytes_;
        continue;
      }
      if (size_ < kRvcFrameSize) break;
      const auto frame =
          decode_rvc(std::span<const std::uint8_t, kRvcFrameSize>(buf_.data(), kRvcFrameSize));
      if (!frame) {
        // A header inside data, or a corrupted frame: drop one byte and
        // look for the next header.
        ++checksum_errors_;
        std::memmove(buf_.data(), buf_.data() + 1, size_ - 1);
        --size_;
        ++skipped_bytes_;
        continue;
      }
      if (frames_ > 0) {
        lost_frames_ += static_cast<std::uint8_t>(frame->index - latest_.index - 1);
      }
      latest_ = *frame;
      ++frames_;
      ++done;
      size_ = 0;
    }
  }
  return done;
}

}  // namespace animrt::imu
