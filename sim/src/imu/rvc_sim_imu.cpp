// The simulated BNO08x UART-RVC part (see rvc_sim_imu.hpp).

#include "animrt/sim/imu/rvc_sim_imu.hpp"

#include <poll.h>

#include <algorithm>
#include <cmath>

#include "animrt/bridge/imu/bno08x_rvc.hpp"
#include "animrt/sim/serial_line.hpp"

namespace animrt::sim {

TrunkProvider scripted_trunk(const ImuConfig::Push& push) {
  return [push](double t) {
    TrunkState s;
    if (!push.on || t < push.at_s) return s;
    const double angle = std::copysign(
        std::min(std::abs(push.to_rad), (t - push.at_s) * push.rate_rad_s), push.to_rad);
    s.quat = push.pitch ? quat_from_ypr(0.0, angle, 0.0) : quat_from_ypr(0.0, 0.0, angle);
    // Gravity seen from the tilted trunk: the world's up in the trunk frame.
    const TrunkUp up = trunk_up(s.quat);
    s.accel_m_s2 = {9.80665 * up.nose_up, 9.80665 * up.left_up, 9.80665 * up.up_up};
    return s;
  };
}

RvcSimImu::RvcSimImu(const ImuConfig& config, const Clock& clock, Nanos start, TrunkProvider trunk)
    : config_(config),
      mount_(
          quat_from_ypr(config.mount_ypr_rad[0], config.mount_ypr_rad[1], config.mount_ypr_rad[2])),
      clock_(clock),
      start_(start),
      trunk_(std::move(trunk)),
      pty_("imu " + config.name) {
  thread_ = std::thread([this] { serve(); });
}

RvcSimImu::~RvcSimImu() {
  stop_.store(true);
  wake_.wake();
  if (thread_.joinable()) thread_.join();
}

void RvcSimImu::serve() {
  const Nanos period = from_seconds(1.0 / config_.rate_hz);
  // Frames on whole multiples of the period on the clock, so a lockstep run
  // knows which frame is due by its time.
  Nanos due = (start_ + period - 1) / period * period;
  std::uint8_t index = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    // Wait for the frame's time on the run's clock (a lockstep clock moves
    // only when the run steps it), a wake, or a poll tick.
    if (clock_.now() < due) {
      pollfd p{wake_.read_fd(), POLLIN, 0};
      const timespec tick{0, 200'000};  // a lockstep clock can move a cycle in well under 1 ms
      ::ppoll(&p, 1, &tick, nullptr);
      continue;
    }
    if (config_.sim_silent_at_s >= 0.0 && to_seconds(due - start_) >= config_.sim_silent_at_s) {
      due += period;  // a silent part: its frames never come
      continue;
    }
    const TrunkState s = trunk_(to_seconds(due - start_));
    // The part's own attitude: the trunk's turned by the mounting; its
    // acceleration in the part's axes.
    const auto part = quat_mul(s.quat, mount_);
    const std::array<double, 4> v{0.0, s.accel_m_s2[0], s.accel_m_s2[1], s.accel_m_s2[2]};
    const auto a = quat_mul(quat_mul(quat_conj(mount_), v), mount_);
    const auto bytes = imu::encode_rvc(imu::rvc_frame(index++, part, {a[1], a[2], a[3]}));
    // A part sends whether anyone listens: bytes nobody reads are lost.
    line::write_all(pty_.master(), wake_.read_fd(), bytes);
    sent_.fetch_add(1, std::memory_order_relaxed);
    due += period;
  }
}

}  // namespace animrt::sim
