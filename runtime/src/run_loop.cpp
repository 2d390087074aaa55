#include "run_loop.hpp"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <cmath>

#include "animrt/runtime/robot_config.hpp"
#include "futex.hpp"

namespace animrt {
namespace {

constexpr std::size_t kTelemetryCapacity = 1 << 14;  // records (~80 s at 200 Hz)
// A bus that has not answered by then keeps its last measurement this
// cycle, and the others go on without it.
constexpr double kReadBudget = kReadBudgetFraction;
constexpr std::size_t kManualPerCycle = 64;  // manual targets taken per cycle, at most
// Lockstep: how long (wall time) a cycle waits for an IMU's frame due by its
// time before it goes on without it (the cycle then counts it late).
constexpr Nanos kLockstepImuWait = 500'000'000;

void sleep_until_deadline(Nanos deadline) {
  timespec ts{};
  ts.tv_sec = deadline / 1'000'000'000;
  ts.tv_nsec = deadline % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

constexpr std::size_t kHealthColumns = 5;  // temperature, current, voltage, torque, error bits
constexpr std::size_t kImuColumns = 7;     // attitude (w, x, y, z), angular rates (x, y, z)
constexpr const char* kImuSuffixes[kImuColumns] = {
    "_qw", "_qx", "_qy", "_qz", "_rate_x_rad_s", "_rate_y_rad_s", "_rate_z_rad_s"};

std::vector<JointSlot> health_slots(const std::vector<std::unique_ptr<ActuatorBus>>& buses) {
  std::vector<JointSlot> slots;
  for (std::size_t b = 0; b < buses.size(); ++b) {
    if (!buses[b]->reads_health()) continue;
    for (std::size_t d = 0; d < buses[b]->config().actuators.size(); ++d) slots.push_back({b, d});
  }
  return slots;
}

const Clock& run_clock(const RunOptions& options, const MonotonicClock& wall) {
  return options.lockstep_clock ? static_cast<const Clock&>(*options.lockstep_clock)
                                : static_cast<const Clock&>(wall);
}

}  // namespace

void ActivationGuard::activate_all() {
  while (activated_ < buses_.size()) buses_[activated_++]->activate();
  for (auto& bus : buses_) bus->arm_device_guard();
}

void ActivationGuard::release() {
  for (std::size_t b = 0; b < activated_; ++b) buses_[b]->deactivate();
  activated_ = 0;
}

RunLoop::RunLoop(const RobotModel& model, std::vector<std::unique_ptr<ActuatorBus>>& buses,
                 MotionSource& motion, const RunOptions& options, CycleState& state,
                 std::span<const std::vector<double>> bus_positions, RunSummary& summary)
    : model_(model),
      buses_(buses),
      motion_(motion),
      options_(options),
      state_(state),
      summary_(summary),
      clock_(run_clock(options, wall_)),
      period_(model.period),
      health_columns_(health_slots(buses)),
      ring_(1 + 2 * model.joint_count() + kHealthColumns * health_columns_.size() +
                kImuColumns * model.imus.size(),
            kTelemetryCapacity),
      record_(ring_.width()),
      bus_hist_(buses.size()),
      io_(buses.size()),
      health_(buses.size()),
      readings_(buses.size()),
      view_(buses.size()),
      pending_(buses.size(), 0),
      io_seen_(buses.size(), 0),
      manual_(kManualPerCycle),
      monitor_devices_(buses.size()),
      activation_(buses) {
  if (!options.telemetry_path.empty()) {
    for (const JointSlot& slot : health_columns_) {
      const std::string& joint = buses[slot.bus]->config().actuators[slot.device].joint;
      for (const char* suffix :
           {"_temp_c", "_current_a", "_voltage_v", "_torque_nm", "_error_bits"}) {
        health_names_.push_back(joint + suffix);
      }
    }
    for (const ImuModel& imu : model.imus) {
      for (const char* suffix : kImuSuffixes) health_names_.push_back(imu.name + suffix);
    }
    writer_.emplace(options.telemetry_path, model.joint_names, ring_, health_names_);
  }
  if (!options.record_path.empty()) {
    recorder_.emplace(options.record_path, model);
    add_record_channels();
    recorder_->start();
    status_every_ = std::max<std::size_t>(1, static_cast<std::size_t>(model.rate_hz / 10.0));
  }
  for (std::size_t b = 0; b < buses.size(); ++b) {
    const auto devices = buses[b]->devices();
    health_[b].assign(devices.size(), DeviceHealth::ok);
    readings_[b].assign(devices.size(), HealthReading{});
    view_[b].assign(devices.begin(), devices.end());
  }
  in_.buses = io_;
  imu_io_.resize(model.imus.size());
  imu_silent_.assign(model.imus.size(), 0);
  in_.imus = imu_io_;
  in_.motion_duration_s = options.duration_s;
  for (std::size_t b = 0; b < buses.size(); ++b) {
    workers_.push_back(std::make_unique<BusWorker>(*buses[b], bus_positions[b], io_done_));
    const int priority = summary.sched_fifo ? std::max(1, summary.sched_priority - 1) : 0;
    if (!workers_.back()->start(priority) && priority > 0) {
      summary.io_thread_notes.push_back(
          fmt::format("bus {}: {}", buses[b]->config().name, workers_.back()->priority_note()));
    }
  }
}

bool RunLoop::run() {
  start_ = clock_.now();
  deadline_ = start_;
  while (!state_.done()) {
    const Wake woke = wake();
    post_reads();
    // The budget counts from the deadline, not from a late wake-up.
    wait_for(true,
             options_.lockstep_clock
                 ? Nanos{-1}
                 : deadline_ + static_cast<Nanos>(kReadBudget * static_cast<double>(period_)));
    take_reads();
    gather_inputs();
    const CycleOutputs& out = step(model_, motion_, state_, in_);
    publish(out);
    if (options_.heartbeat) options_.heartbeat->beat(state_.phase());
    notify(out);
    if (out.torque_off_now) return true;
    post_writes(out);
    record(out);
    pace(woke);
  }
  return false;
}

void RunLoop::finish() {
  for (auto& w : workers_) w->stop();
  if (options_.monitor) options_.monitor->publish_ended();
  if (options_.heartbeat) options_.heartbeat->end();
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    count_io(b);
    mark_faults(b);
    update_view(b);
  }
  activation_.release();
  if (options_.heartbeat) options_.heartbeat->released();
  if (writer_) writer_->finish();
  if (recorder_) recorder_->finish();
}

RunLoop::Wake RunLoop::wake() {
  if (options_.lockstep_clock) options_.lockstep_clock->set(deadline_);
  const Wake woke{clock_.now(), wall_.now()};
  jitter_hist_.add(to_seconds(woke.run - deadline_));
  if (previous_wake_ >= 0) {
    last_period_s_ = to_seconds(woke.run - previous_wake_);
    period_hist_.add(last_period_s_);
  }
  previous_wake_ = woke.run;
  return woke;
}

// Every idle bus reads on its own thread; a bus still busy from an earlier
// cycle is late. A read that came back after an earlier cycle's budget is
// used now.
void RunLoop::post_reads() {
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    io_[b].fresh = false;
    if (pending_[b] || !workers_[b]->idle()) continue;
    count_io(b);
    mark_faults(b);
    workers_[b]->post_read();
    pending_[b] = 1;
  }
}

// Waits until every bus with a posted request of the kind is done, or until
// `deadline` (CLOCK_MONOTONIC; < 0: no limit, as in lockstep).
void RunLoop::wait_for(bool reads, Nanos deadline) {
  for (;;) {
    const std::uint32_t seen = io_done_.load(std::memory_order_acquire);
    bool all = true;
    for (auto& w : workers_) all = all && (reads ? w->read_done() : w->write_done());
    if (all || (deadline >= 0 && wall_.now() >= deadline)) return;
    futex_wait_until(io_done_, seen, deadline);
  }
}

void RunLoop::take_reads() {
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    if (!pending_[b] || !workers_[b]->read_done()) continue;
    pending_[b] = 0;
    io_[b].fresh = true;
    update_view(b);
    for (std::size_t d = 0; d < view_[b].size(); ++d) {
      health_[b][d] = view_[b][d].health;
      readings_[b][d] = view_[b][d].reading;
    }
    io_[b].positions = workers_[b]->positions();
    io_[b].health = health_[b];
    io_[b].readings = readings_[b];
  }
}

// The IMU's newest reading. In lockstep the part's frames follow the
// simulated clock, so the cycle waits (boundedly, as for a lockstep bus)
// for the frame due by its time: a lockstep run sees every frame whatever
// the machine's load.
void RunLoop::take_imu(std::size_t i) {
  Mailbox<ImuReading>& box = *options_.imu_readings[i];
  ImuIo& io = imu_io_[i];
  const auto take = [&] {
    if (!box.take(io.reading)) return false;
    io.valid = true;
    io.reading.time_s -= to_seconds(start_);  // on the run's clock -> since the run began
    imu_silent_[i] = 0;
    return true;
  };
  take();
  // A part that has fallen silent costs one wait, not one per cycle.
  if (!options_.lockstep_clock || imu_silent_[i]) return;
  // A simulated part sends on whole multiples of its period on the clock;
  // a frame due before the run began may have been dropped as old by the
  // reader when it opened the line, so only later ones are waited for.
  const double rate = model_.imus[i].rate_hz;
  const double due = std::floor(to_seconds(deadline_) * rate + 1e-9) / rate - to_seconds(start_);
  if (due <= 1e-9) return;
  const Nanos give_up = wall_.now() + kLockstepImuWait;
  while ((!io.valid || io.reading.time_s < due - 1e-9) && wall_.now() < give_up) {
    sleep_until_deadline(wall_.now() + 100'000);
    take();
  }
  if (!io.valid || io.reading.time_s < due - 1e-9) imu_silent_[i] = 1;
}

void RunLoop::gather_inputs() {
  RunControls* const controls = options_.controls;
  in_.t = to_seconds(deadline_ - start_);  // nominal time: smooth motion
  in_.stop = controls && controls->stop.load(std::memory_order_relaxed);
  in_.abort = controls && controls->abort.load(std::memory_order_relaxed);
  in_.steer = controls && controls->steer.take(steer_) ? &steer_ : nullptr;
  in_.jog = controls && controls->jog.take(jog_) ? &jog_ : nullptr;
  in_.show = controls && controls->show.take(show_) ? &show_ : nullptr;
  for (std::size_t i = 0; i < imu_io_.size() && i < options_.imu_readings.size(); ++i) {
    if (options_.imu_readings[i]) take_imu(i);
  }
  // Targets first, then the mode: a target posted after manual mode was
  // switched on is never taken for one sent before it.
  std::size_t count = 0;
  if (controls) {
    double target[2];
    while (count < manual_.size() && controls->manual_targets.pop(target)) {
      manual_[count++] = ManualTarget{static_cast<int>(target[0]), target[1]};
    }
    in_.manual = controls->manual.load(std::memory_order_acquire);
  }
  in_.manual_targets = std::span<const ManualTarget>(manual_.data(), count);
}

void RunLoop::publish(const CycleOutputs& out) {
  RunMonitor* const monitor = options_.monitor;
  if (!monitor) return;
  // Before the writes are posted: a fresh bus's view was taken while its
  // I/O thread was idle; a late bus keeps its last published statuses.
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    monitor_devices_[b] =
        io_[b].fresh ? std::span<const DeviceStatus>(view_[b]) : std::span<const DeviceStatus>();
  }
  monitor->publish(in_.t, state_, out.commands, monitor_devices_, summary_.overruns,
                   summary_.skipped_cycles, in_.steer, in_.imus);
  for (const CycleEvent& e : out.events) monitor->push_event(e);
}

void RunLoop::notify(const CycleOutputs& out) {
  if (out.show_controlled && options_.on_show_command) {
    options_.on_show_command(show_, in_.t - state_.motion_start());
  }
  for (const CycleEvent& e : out.events) {
    if (e.kind == EventKind::motion_started) {
      motion_.start(MotionClock{&clock_, deadline_, options_.lockstep_clock != nullptr});
      if (options_.on_motion_start) options_.on_motion_start(deadline_);
    }
    if (e.kind == EventKind::motion_ended && options_.on_motion_end) options_.on_motion_end();
  }
}

void RunLoop::post_writes(const CycleOutputs& out) {
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    if (!out.write[b]) continue;
    std::copy(out.bus_commands[b].begin(), out.bus_commands[b].end(),
              workers_[b]->commands().begin());
    workers_[b]->post_write();
  }
  // Lockstep: the writes land before the clock moves on (deterministic).
  if (options_.lockstep_clock) wait_for(false, -1);
}

void RunLoop::record(const CycleOutputs& out) {
  if (writer_) {
    record_[0] = in_.t;
    std::copy(out.commands.begin(), out.commands.end(), record_.begin() + 1);
    const auto seen = state_.measured();
    std::copy(seen.begin(), seen.end(), record_.begin() + 1 + static_cast<long>(seen.size()));
    std::size_t k = 1 + 2 * seen.size();
    for (const JointSlot& slot : health_columns_) {
      const HealthReading& r = readings_[slot.bus][slot.device];
      record_[k++] = r.temperature_c;
      record_[k++] = r.current_a;
      record_[k++] = r.voltage_v;
      record_[k++] = r.torque_nm;
      record_[k++] = r.has_error_bits ? static_cast<double>(r.error_bits) : HealthReading::kNone;
    }
    for (const ImuIo& imu : imu_io_) {
      for (double q : imu.reading.quat) record_[k++] = imu.valid ? q : HealthReading::kNone;
      for (double w : imu.reading.rate_rad_s) record_[k++] = imu.valid ? w : HealthReading::kNone;
    }
    ring_.push(record_);
  }
  if (recorder_) record_mcap(out);
}

// Device health (per device, for buses that read it) and every IMU's
// reading, besides the recorder's own joint, event, loop and status channels.
void RunLoop::add_record_channels() {
  if (!health_columns_.empty()) {
    health_seen_.assign(health_columns_.size(), 0);
    health_channel_ = recorder_->add(
        RecordChannel{"health",
                      "animrt.DeviceHealth",
                      {"temperature_c", "current_a", "voltage_v", "torque_nm", "error_bits"},
                      true,
                      kTelemetryCapacity});
  }
  if (!model_.imus.empty()) {
    imu_channel_ = recorder_->add(
        RecordChannel{"/imu",
                      "animrt.Imu",
                      {"imu", "qw", "qx", "qy", "qz", "rate_x_rad_s", "rate_y_rad_s",
                       "rate_z_rad_s", "accel_x_m_s2", "accel_y_m_s2", "accel_z_m_s2", "measured_s",
                       "late_cycles", "missing_reports"},
                      false,
                      kTelemetryCapacity});
  }
}

void RunLoop::record_mcap_health() {
  McapRecorder& r = *recorder_;
  if (health_channel_ != static_cast<std::size_t>(-1)) {
    for (std::size_t k = 0; k < health_columns_.size(); ++k) {
      const JointSlot& slot = health_columns_[k];
      const HealthReading& h = readings_[slot.bus][slot.device];
      if (h.reads == health_seen_[k]) continue;  // only new readings
      health_seen_[k] = h.reads;
      const double rec[] = {
          in_.t,
          static_cast<double>(r.device_index(slot.bus, slot.device)),
          h.temperature_c,
          h.current_a,
          h.voltage_v,
          h.torque_nm,
          h.has_error_bits ? static_cast<double>(h.error_bits) : HealthReading::kNone};
      r.push(health_channel_, rec);
    }
  }
  if (imu_channel_ == static_cast<std::size_t>(-1)) return;
  for (std::size_t i = 0; i < imu_io_.size(); ++i) {
    if (!imu_io_[i].valid) continue;
    const ImuReading& m = imu_io_[i].reading;
    // The cycle's counts so far: cycles the reading was late, reports the
    // part did not send (a recording shows when an IMU faltered).
    const double late = static_cast<double>(state_.imu_late_cycles()[i]);
    const double missing = static_cast<double>(state_.imu_missing(i, model_.imus[i].rate_hz));
    const double rec[] = {in_.t,           static_cast<double>(i),
                          m.quat[0],       m.quat[1],
                          m.quat[2],       m.quat[3],
                          m.rate_rad_s[0], m.rate_rad_s[1],
                          m.rate_rad_s[2], m.accel_m_s2[0],
                          m.accel_m_s2[1], m.accel_m_s2[2],
                          m.time_s,        late,
                          missing};
    r.push(imu_channel_, rec);
  }
}

void RunLoop::record_mcap(const CycleOutputs& out) {
  McapRecorder& r = *recorder_;
  r.push_joints(in_.t, out.commands, state_.measured());
  if (in_.stop && !stop_recorded_) {
    stop_recorded_ = true;
    r.push_stop_request(in_.t);
  }
  for (const CycleEvent& e : out.events) r.push_event(e);
  record_mcap_health();
  if (state_.cycles() % status_every_ != 0) return;
  for (std::size_t b = 0; b < buses_.size(); ++b) {
    for (std::size_t d = 0; d < view_[b].size(); ++d) {
      const DeviceStatus& s = view_[b][d];
      const double status[] = {in_.t,
                               static_cast<double>(r.device_index(b, d)),
                               static_cast<double>(s.health),
                               s.faulted ? 1.0 : 0.0,
                               static_cast<double>(s.transactions),
                               static_cast<double>(s.timeouts),
                               static_cast<double>(s.crc_errors),
                               static_cast<double>(s.protocol_errors),
                               static_cast<double>(s.hardware_errors),
                               static_cast<double>(s.hardware_error_status)};
      r.push(r.device_status_channel(), status);
    }
  }
}

void RunLoop::pace(const Wake& woke) {
  const Nanos busy = wall_.now() - woke.wall;
  busy_hist_.add(to_seconds(busy));
  if (recorder_) {
    recorder_->push_loop(in_.t, period_hist_.count() ? last_period_s_ : 0.0,
                         to_seconds(woke.run - deadline_), to_seconds(busy), summary_.overruns,
                         summary_.skipped_cycles);
  }
  if (options_.monitor) {
    options_.monitor->push_timing(CycleTiming{in_.t, period_hist_.count() ? last_period_s_ : -1.0,
                                              to_seconds(woke.run - deadline_), to_seconds(busy)});
  }
  if (options_.lockstep_clock) {
    deadline_ += period_;
    return;
  }
  const NextDeadline next = next_deadline(deadline_, clock_.now(), period_);
  deadline_ = next.deadline;
  if (next.overrun) ++summary_.overruns;
  summary_.skipped_cycles += next.skipped;
  sleep_until_deadline(deadline_);
}

// The cycle's faults reach the bus while its I/O thread is idle: the bus
// marks them in its own statuses and skips those devices from then on.
void RunLoop::mark_faults(std::size_t b) {
  ActuatorBus& bus = *buses_[b];
  const auto devices = bus.devices();
  const auto& faulted = state_.faulted()[b];
  const auto& off = state_.switch_off()[b];
  for (std::size_t d = 0; d < devices.size(); ++d) {
    if (!faulted[d] || devices[d].faulted) continue;
    if (off[d]) {
      bus.switch_off(d);
    } else {
      bus.mark_faulted(d);
    }
  }
}

// While bus b's I/O thread is idle: its statuses as the run sees them.
void RunLoop::update_view(std::size_t b) {
  const auto devices = buses_[b]->devices();
  const BusWorker& worker = *workers_[b];
  const auto failures = worker.failures();
  const auto failing = worker.failing();
  const auto& faulted = state_.faulted()[b];
  for (std::size_t d = 0; d < devices.size(); ++d) {
    DeviceStatus& v = view_[b][d];
    v = devices[d];
    v.timeouts += failures[d];
    if (failing[d]) v.health = DeviceHealth::timeout;
    v.faulted = faulted[d] != 0;
  }
}

// A completed read + write since the last look: its time.
void RunLoop::count_io(std::size_t b) {
  if (workers_[b]->io_cycles() == io_seen_[b]) return;
  io_seen_[b] = workers_[b]->io_cycles();
  bus_hist_[b].add(to_seconds(workers_[b]->last_io_ns()));
}

}  // namespace animrt
