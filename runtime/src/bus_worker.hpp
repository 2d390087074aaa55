#pragma once
// One I/O thread per bus, so a slow or dead bus never holds up the others.
// The loop posts a read (and later a write) and waits for the reads with a
// deadline; a bus that misses it keeps its last measurement and is skipped
// until its thread is idle again. Hand-over is lock-free: sequence counters
// with release/acquire ordering, and futex waits on them (no mutex, no
// allocation after start()).
//
// Ownership: positions(), commands(), failures() and failing() belong to
// the worker thread while a request is pending, and to the loop thread while
// idle(). The worker never writes the bus's DeviceStatus: a request the bus
// threw on is counted here, and the loop combines the two.

#include <pthread.h>

#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/core/clock.hpp"
#include "emergency_slots.hpp"

namespace animrt {

// The start routine of every BusWorker thread (tests tell run threads apart
// by it).
using ThreadRoutine = void* (*)(void*);
ThreadRoutine bus_worker_thread_routine();

class BusWorker {
 public:
  // `done` is bumped (and woken) after every completed request of any worker.
  BusWorker(ActuatorBus& bus, std::span<const double> initial_positions,
            std::atomic<std::uint32_t>& done);
  ~BusWorker();
  BusWorker(const BusWorker&) = delete;
  BusWorker& operator=(const BusWorker&) = delete;

  // Starts the I/O thread. realtime_priority > 0: the thread is created with
  // SCHED_FIFO at that priority (PTHREAD_EXPLICIT_SCHED, so it never runs a
  // single instruction at the default policy). When that is not permitted
  // it starts as a normal thread instead, never fatal. Returns whether the
  // requested priority took effect (true when none was asked); the note
  // says what happened, for the run summary.
  bool start(int realtime_priority);  // 0: inherit the default policy
  void stop();
  bool realtime() const { return realtime_; }
  const std::string& priority_note() const { return priority_note_; }

  bool idle() const {
    return read_done_.load(std::memory_order_acquire) ==
               read_req_.load(std::memory_order_relaxed) &&
           write_done_.load(std::memory_order_acquire) ==
               write_req_.load(std::memory_order_relaxed);
  }
  bool read_done() const {
    return read_done_.load(std::memory_order_acquire) == read_req_.load(std::memory_order_relaxed);
  }
  bool write_done() const {
    return write_done_.load(std::memory_order_acquire) ==
           write_req_.load(std::memory_order_relaxed);
  }
  void post_read();
  void post_write();

  std::span<double> positions() { return positions_; }
  std::span<double> commands() { return commands_; }
  // Per device: requests the bus threw on while the device was not marked
  // faulted (each a timeout of that device, for the run's view), and
  // whether one threw since the device's latest answered read (its health
  // is a timeout, whatever its bus's status says).
  std::span<const std::uint64_t> failures() const { return failures_; }
  std::span<const std::uint8_t> failing() const { return failing_; }
  // Read + write time of the last completed cycle, and how many have completed.
  Nanos last_io_ns() const { return io_ns_.load(std::memory_order_acquire); }
  std::uint64_t io_cycles() const { return io_cycles_.load(std::memory_order_acquire); }

  // Entry of the I/O thread (public only for the pthread trampoline).
  void run_for_thread();

 private:
  void run();
  void signal_done();
  // A fatal-error handler asked for torque off: switch the bus off and
  // touch it no more. Returns whether it did.
  bool honour_emergency();
  template <typename F>
  void guarded(bool reading, F&& io);

  ActuatorBus& bus_;
  std::atomic<std::uint32_t>& done_;
  std::vector<double> positions_;
  std::vector<double> commands_;
  std::vector<std::uint64_t> failures_;
  std::vector<std::uint8_t> failing_;
  // The thread's wake word: in its emergency slot when it has one (so a
  // fatal-error handler can wake it: emergency_stop.hpp), else own_wake_.
  EmergencySlot* emergency_ = nullptr;
  std::atomic<std::uint32_t> own_wake_{0};
  std::atomic<std::uint32_t>* wake_ = &own_wake_;
  std::atomic<std::uint32_t> read_req_{0}, read_done_{0}, write_req_{0}, write_done_{0};
  std::atomic<bool> stop_{false};
  std::atomic<Nanos> io_ns_{0};
  std::atomic<std::uint64_t> io_cycles_{0};
  Nanos read_ns_ = 0;
  pthread_t thread_{};
  bool running_ = false;
  bool realtime_ = false;
  std::string priority_note_;
};

}  // namespace animrt
