#pragma once
// A simulated BNO08x in UART-RVC mode on a pseudo-terminal: as the part
// does, it sends a frame every 10 ms unasked (index counting, attitude in
// 0.01 degree, acceleration in mg, checksum), whether anyone reads or not.
// The attitude comes from a provider: the physics' torso, a level figure,
// or the robot file's scripted push (ImuConfig::sim_push). The part's
// mounting is applied, so the host must take it out as with a real part.
// From ImuConfig::sim_silent_at_s on it sends nothing (a loose cable).

#include <array>
#include <atomic>
#include <functional>
#include <string>
#include <thread>

#include "animrt/bridge/imu/imu_config.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/imu.hpp"
#include "animrt/sim/maestro/pty_pair.hpp"

namespace animrt::sim {

// The trunk's attitude and specific force at run time t (s).
struct TrunkState {
  std::array<double, 4> quat{1.0, 0.0, 0.0, 0.0};
  std::array<double, 3> accel_m_s2{0.0, 0.0, 9.80665};  // trunk frame; level and still: +1 g up
};
using TrunkProvider = std::function<TrunkState(double t)>;

// Level, or pushed over as `push` says.
TrunkProvider scripted_trunk(const ImuConfig::Push& push);

class RvcSimImu {
 public:
  // Frames are due on whole multiples of 1/rate_hz on `clock`, from
  // `start` on; the provider is asked for time (due - start). Throws DeviceError when no pty opens.
  RvcSimImu(const ImuConfig& config, const Clock& clock, Nanos start, TrunkProvider trunk);
  ~RvcSimImu();
  RvcSimImu(const RvcSimImu&) = delete;
  RvcSimImu& operator=(const RvcSimImu&) = delete;

  const std::string& port() const { return pty_.path(); }
  std::uint64_t frames_sent() const { return sent_.load(std::memory_order_relaxed); }

 private:
  void serve();

  ImuConfig config_;
  std::array<double, 4> mount_;
  const Clock& clock_;
  Nanos start_;
  TrunkProvider trunk_;
  PtyPair pty_;
  WakePipe wake_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> sent_{0};
  std::thread thread_;
};

}  // namespace animrt::sim
