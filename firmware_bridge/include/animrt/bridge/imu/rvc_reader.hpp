#pragma once
// The host side of a BNO08x in UART-RVC mode: a thread that reads the
// stream from the port, decodes it (bno08x_rvc.hpp), turns each frame into a
// reading in the trunk's frame (the part's mounting taken out, angular rate
// from the attitude's change between frames, as the stream carries none),
// stamps it on the run's clock when it arrived, and posts it to a mailbox
// the cycle takes from without waiting.

#include <atomic>
#include <cstdint>
#include <memory>
#include <thread>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/imu/bno08x_rvc.hpp"
#include "animrt/bridge/imu/imu_config.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/imu.hpp"
#include "animrt/core/mailbox.hpp"

namespace animrt::imu {

// The trunk's reading from the part's: q_trunk = q_part * conj(q_mount), and
// the acceleration rotated into the trunk frame.
ImuReading to_trunk(const ImuReading& part, const std::array<double, 4>& mount);

class RvcReader {
 public:
  // Readings are stamped `clock.now() - start` (seconds).
  RvcReader(std::unique_ptr<ByteTransport> line, const ImuConfig& config, const Clock& clock,
            Nanos start);
  ~RvcReader();
  RvcReader(const RvcReader&) = delete;
  RvcReader& operator=(const RvcReader&) = delete;

  Mailbox<ImuReading>& readings() { return readings_; }
  std::uint64_t frames() const { return frames_.load(std::memory_order_relaxed); }
  std::uint64_t checksum_errors() const { return checksum_errors_.load(std::memory_order_relaxed); }
  std::uint64_t lost_frames() const { return lost_.load(std::memory_order_relaxed); }

 private:
  void serve();

  std::unique_ptr<ByteTransport> line_;
  std::array<double, 4> mount_;
  double frame_s_;
  const Clock& clock_;
  Nanos start_;
  RvcStream stream_;
  Mailbox<ImuReading> readings_;
  ImuReading last_;
  bool have_last_ = false;
  std::atomic<std::uint64_t> frames_{0}, checksum_errors_{0}, lost_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace animrt::imu
