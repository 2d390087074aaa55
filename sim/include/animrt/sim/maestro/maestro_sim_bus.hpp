#pragma once
// Simulated Pololu Maestro boards of one serial line behind a pty: compact
// commands reach every board, Pololu-form commands only the board with that
// device number. Answers go back in command order.
//
// Time: as DynamixelSimBus. A command takes effect at the Clock's time when
// the thread handles it; in lockstep, commands that get no answer (Set
// Target, Set Multiple Targets, ...) take effect at the time of the last
// answered command, i.e. in the cycle that sent them.

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/maestro/maestro_codec.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/thread_priority.hpp"
#include "animrt/sim/maestro/maestro_board.hpp"
#include "animrt/sim/maestro/pty_pair.hpp"
#include "animrt/sim/simulated_bus.hpp"

namespace animrt::sim {

struct MaestroSimStats {
  std::uint64_t commands = 0;         // commands obeyed (any board)
  std::uint64_t protocol_errors = 0;  // malformed input seen on the line
};

class MaestroSimBus final : public SimulatedBus {
 public:
  MaestroSimBus(const BusConfig& config, const Clock& clock);
  ~MaestroSimBus() override;

  const std::string& endpoint() const override { return pty_.path(); }
  std::string describe() const override;
  void start() override;
  void stop() override;
  std::string raise_priority(int priority) override { return set_fifo_priority(thread_, priority); }
  // By the device ids of the BusConfig (channel, or 100 * device + channel);
  // these act on the whole board of that channel.
  void set_device_responding(int device_id, bool responding) override;
  // `error_bits` are Maestro error register bits (low byte).
  void set_device_hardware_error(int device_id, std::uint8_t error_bits) override;
  double device_position(int device_id) const override;
  std::shared_ptr<LockstepLine> lockstep_line() const override { return line_; }

  MaestroSimStats stats() const;
  // Output pulse (quarter-us) of a channel, for tests.
  std::uint16_t pulse(int device_id) const;

 private:
  struct Where {
    MaestroBoard* board;
    int channel;
    const ActuatorBinding* binding;
  };
  Where find(int device_id) const;
  void serve();
  void process(const std::uint8_t* bytes, std::size_t n);

  BusConfig config_;
  const Clock& clock_;
  PtyPair pty_;
  WakePipe wake_;
  bool lockstep_;
  std::shared_ptr<LockstepLine> line_;  // lockstep only
  Nanos last_time_;
  mutable std::mutex mutex_;  // guards boards_
  std::vector<MaestroBoard> boards_;
  maestro::Parser parser_;
  std::vector<std::uint8_t> answers_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> commands_{0};
  std::atomic<std::uint64_t> protocol_errors_{0};
};

}  // namespace animrt::sim
