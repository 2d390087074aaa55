// The BNO08x UART-RVC reader (see rvc_reader.hpp).

#include "animrt/bridge/imu/rvc_reader.hpp"

#include <array>
#include <chrono>

namespace animrt::imu {
namespace {

std::array<double, 3> rotate(const std::array<double, 4>& q, const std::array<double, 3>& v) {
  const std::array<double, 4> p{0.0, v[0], v[1], v[2]};
  const auto r = quat_mul(quat_mul(q, p), quat_conj(q));
  return {r[1], r[2], r[3]};
}

}  // namespace

ImuReading to_trunk(const ImuReading& part, const std::array<double, 4>& mount) {
  ImuReading r = part;
  r.quat = quat_mul(part.quat, quat_conj(mount));
  // A vector in the part's frame, in the trunk's: rotated by the mounting.
  r.accel_m_s2 = rotate(mount, part.accel_m_s2);
  r.rate_rad_s = rotate(mount, part.rate_rad_s);
  return r;
}

RvcReader::RvcReader(std::unique_ptr<ByteTransport> line, const ImuConfig& config,
                     const Clock& clock, Nanos start)
    : line_(std::move(line)),
      mount_(
          quat_from_ypr(config.mount_ypr_rad[0], config.mount_ypr_rad[1], config.mount_ypr_rad[2])),
      frame_s_(1.0 / config.rate_hz),
      clock_(clock),
      start_(start) {
  // Frames that waited in the driver are old: the reader starts with the next.
  line_->discard_input();
  thread_ = std::thread([this] { serve(); });
}

RvcReader::~RvcReader() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void RvcReader::serve() {
  std::array<std::uint8_t, 256> buf{};
  while (!stop_.load(std::memory_order_relaxed)) {
    const std::size_t n = line_->read(buf, std::chrono::milliseconds(20));
    if (n == 0) {
      if (line_->failure()) return;
      continue;
    }
    const double now = to_seconds(clock_.now() - start_);
    std::size_t fed = 0;
    // One frame at a time, so each is turned into a reading.
    while (fed < n) {
      const std::size_t before = static_cast<std::size_t>(stream_.frames());
      std::size_t k = fed;
      while (k < n && static_cast<std::size_t>(stream_.frames()) == before) {
        stream_.feed(std::span(buf).subspan(k, 1));
        ++k;
      }
      fed = k;
      if (static_cast<std::size_t>(stream_.frames()) == before) break;
      ImuReading r = to_trunk(rvc_reading(stream_.latest(), now), mount_);
      if (have_last_) {
        // Body rate from the change of attitude over the frame period:
        // 2 * vec(conj(q0) * q1) / dt, for small steps.
        const auto dq = quat_mul(quat_conj(last_.quat), r.quat);
        const double sign = dq[0] < 0.0 ? -1.0 : 1.0;
        const double steps = 1.0 + static_cast<double>(stream_.lost_frames() - lost_.load());
        for (int i = 0; i < 3; ++i) r.rate_rad_s[i] = sign * 2.0 * dq[i + 1] / (steps * frame_s_);
      }
      last_ = r;
      have_last_ = true;
      // Counted before it is posted: whoever takes a reading sees counters
      // that include it.
      frames_.store(stream_.frames(), std::memory_order_relaxed);
      checksum_errors_.store(stream_.checksum_errors(), std::memory_order_relaxed);
      lost_.store(stream_.lost_frames(), std::memory_order_relaxed);
      readings_.post(r);
    }
  }
}

}  // namespace animrt::imu
