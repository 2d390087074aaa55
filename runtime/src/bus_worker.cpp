#include "bus_worker.hpp"

#include <pthread.h>
#include <sched.h>

#include <cstring>
#include <string>
#include <system_error>

#include "futex.hpp"

namespace animrt {

BusWorker::BusWorker(ActuatorBus& bus, std::span<const double> initial_positions,
                     std::atomic<std::uint32_t>& done)
    : bus_(bus),
      done_(done),
      positions_(initial_positions.begin(), initial_positions.end()),
      commands_(initial_positions.begin(), initial_positions.end()),
      failures_(bus.devices().size(), 0),
      failing_(bus.devices().size(), 0) {}

BusWorker::~BusWorker() { stop(); }

namespace {

void* thread_main(void* worker) {
  static_cast<BusWorker*>(worker)->run_for_thread();
  return nullptr;
}

}  // namespace

ThreadRoutine bus_worker_thread_routine() { return thread_main; }

void BusWorker::run_for_thread() { run(); }

bool BusWorker::start(int realtime_priority) {
  if (running_) return realtime_ || realtime_priority <= 0;
  stop_ = false;
  realtime_ = false;
  emergency_ = claim_emergency_slot();
  wake_ = emergency_ != nullptr ? &emergency_->wake : &own_wake_;
  priority_note_.clear();
  int rc = -1;
  if (realtime_priority > 0) {
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    sched_param param{};
    param.sched_priority = realtime_priority;
    int why = pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
    if (why == 0) why = pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
    if (why == 0) why = pthread_attr_setschedparam(&attr, &param);
    if (why == 0) why = pthread_create(&thread_, &attr, thread_main, this);
    pthread_attr_destroy(&attr);
    rc = why;
    if (rc == 0) {
      realtime_ = true;
      priority_note_ = "SCHED_FIFO " + std::to_string(realtime_priority);
    } else {
      priority_note_ = "SCHED_FIFO " + std::to_string(realtime_priority) + " not permitted (" +
                       std::strerror(rc) + "), normal thread";
    }
  }
  if (rc != 0) {
    rc = pthread_create(&thread_, nullptr, thread_main, this);
    if (rc != 0) {
      release_emergency_slot(emergency_);
      emergency_ = nullptr;
      wake_ = &own_wake_;
      throw std::system_error(rc, std::generic_category(), "bus I/O thread");
    }
    if (priority_note_.empty()) priority_note_ = "default scheduling";
  }
  running_ = true;
  return realtime_ || realtime_priority <= 0;
}

void BusWorker::stop() {
  if (!running_) return;
  stop_.store(true, std::memory_order_release);
  wake_->fetch_add(1, std::memory_order_release);
  futex_wake_all(*wake_);
  pthread_join(thread_, nullptr);
  release_emergency_slot(emergency_);
  emergency_ = nullptr;
  wake_ = &own_wake_;
  running_ = false;
}

void BusWorker::post_read() {
  read_req_.fetch_add(1, std::memory_order_release);
  wake_->fetch_add(1, std::memory_order_release);
  futex_wake_all(*wake_);
}

void BusWorker::post_write() {
  write_req_.fetch_add(1, std::memory_order_release);
  wake_->fetch_add(1, std::memory_order_release);
  futex_wake_all(*wake_);
}

void BusWorker::signal_done() {
  done_.fetch_add(1, std::memory_order_release);
  futex_wake_all(done_);
}

template <typename F>
void BusWorker::guarded(bool reading, F&& io) {
  const auto devices = bus_.devices();
  try {
    io();
    // The read gave every device it asked (every one not faulted) a health
    // of its own.
    if (!reading) return;
    for (std::size_t d = 0; d < devices.size(); ++d) {
      if (!devices[d].faulted) failing_[d] = 0;
    }
  } catch (...) {
    // Last line of defence only: the buses report a gone line as timeouts
    // and never throw in read()/write(). Should one still throw, its devices
    // count a timeout (in the worker's records: the bus's statuses are the
    // bus's) and the loop's watchdog turns that into a fault.
    for (std::size_t d = 0; d < devices.size(); ++d) {
      if (devices[d].faulted) continue;
      ++failures_[d];
      failing_[d] = 1;
    }
  }
}

bool BusWorker::honour_emergency() {
  if (emergency_ == nullptr || emergency_->request.load(std::memory_order_acquire) == 0) {
    return false;
  }
  try {
    bus_.deactivate();  // never throws; the guard is for a bus that breaks that
  } catch (...) {
  }
  report_emergency_done(*emergency_);
  return true;
}

void BusWorker::run() {
  set_thread_emergency_slot(emergency_);
  const MonotonicClock wall;
  for (;;) {
    const std::uint32_t seen = wake_->load(std::memory_order_acquire);
    if (honour_emergency()) return;
    if (stop_.load(std::memory_order_acquire)) return;
    bool worked = false;
    const std::uint32_t rr = read_req_.load(std::memory_order_acquire);
    if (rr != read_done_.load(std::memory_order_relaxed)) {
      const Nanos t0 = wall.now();
      guarded(true, [this] { bus_.read(positions_); });
      read_ns_ = wall.now() - t0;
      read_done_.store(rr, std::memory_order_release);
      signal_done();
      worked = true;
    }
    if (honour_emergency()) return;  // no goal after a read the request interrupted
    const std::uint32_t wr = write_req_.load(std::memory_order_acquire);
    if (wr != write_done_.load(std::memory_order_relaxed)) {
      const Nanos t0 = wall.now();
      guarded(false, [this] { bus_.write(commands_); });
      io_ns_.store(read_ns_ + (wall.now() - t0), std::memory_order_relaxed);
      io_cycles_.fetch_add(1, std::memory_order_release);
      write_done_.store(wr, std::memory_order_release);
      signal_done();
      worked = true;
    }
    if (!worked) futex_wait_until(*wake_, seen, -1);
  }
}

}  // namespace animrt
