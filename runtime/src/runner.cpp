#include "animrt/runtime/runner.hpp"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "animrt/core/error.hpp"
#include "animrt/runtime/cycle.hpp"
#include "animrt/runtime/loop_stats.hpp"
#include "animrt/runtime/realtime.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "animrt/runtime/telemetry.hpp"
#include "bus_worker.hpp"
#include "futex.hpp"

namespace animrt {
namespace {

constexpr std::size_t kTelemetryCapacity = 1 << 14;  // records (~80 s at 200 Hz)
// Real time: how long after its deadline a cycle waits for the buses' reads,
// as a fraction of the period. A bus that has not answered by then keeps its
// last measurement this cycle, and the others go on without it.
constexpr double kReadBudget = 0.6;

TimingSummary summarize(const MicrosHistogram& h) {
  return TimingSummary{h.count(), h.quantile(0.5), h.quantile(0.99), h.max()};
}

void sleep_until(Nanos deadline) {
  timespec ts{};
  ts.tv_sec = deadline / 1'000'000'000;
  ts.tv_nsec = deadline % 1'000'000'000;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

// Owns activation: whatever ends the run (return, exception), every bus that
// was switched on is switched off. A bus counts as on from the moment its
// activate() is called, so one that fails half-way is switched off too.
class ActivationGuard {
 public:
  explicit ActivationGuard(std::vector<std::unique_ptr<ActuatorBus>>& buses) : buses_(buses) {}
  ~ActivationGuard() { release(); }
  ActivationGuard(const ActivationGuard&) = delete;
  ActivationGuard& operator=(const ActivationGuard&) = delete;

  void activate_all() {
    while (activated_ < buses_.size()) buses_[activated_++]->activate();
    for (auto& bus : buses_) bus->arm_device_guard();
  }
  void release() {
    for (std::size_t b = 0; b < activated_; ++b) buses_[b]->deactivate();
    activated_ = 0;
  }

 private:
  std::vector<std::unique_ptr<ActuatorBus>>& buses_;
  std::size_t activated_ = 0;
};

std::string joint_value(double value, bool prismatic, int decimals = 1) {
  return prismatic ? fmt::format("{:.{}f} mm", value * 1e3, decimals)
                   : fmt::format("{:.{}f} deg", rad_to_deg(value), decimals);
}

// The joint that makes the start ramp longest, for the refusal message.
std::string slowest_start(const RobotModel& m, std::span<const double> measured,
                          std::span<const double> first) {
  std::size_t worst = 0;
  double worst_time = -1.0;
  for (std::size_t j = 0; j < m.joint_count(); ++j) {
    const double time = std::abs(first[j] - measured[j]) / m.limits[j].max_velocity;
    if (time > worst_time) {
      worst_time = time;
      worst = j;
    }
  }
  return fmt::format("joint {} is measured at {} and the motion starts at {}", m.joint_names[worst],
                     joint_value(measured[worst], m.prismatic[worst] != 0),
                     joint_value(first[worst], m.prismatic[worst] != 0));
}

std::string describe_event(const RobotModel& m,
                           const std::vector<std::unique_ptr<ActuatorBus>>& buses,
                           const CycleEvent& e) {
  const bool prismatic = e.joint >= 0 && m.prismatic[static_cast<std::size_t>(e.joint)] != 0;
  switch (e.kind) {
    case EventKind::device_fault: {
      const auto& bus = buses[e.bus]->config();
      const auto& actuator = bus.actuators[e.device];
      return fmt::format("bus {} id {} ({}): {} at t={:.3f} s; other joints ramped to home",
                         bus.name, actuator.device_id, actuator.joint,
                         e.health == DeviceHealth::hardware_error
                             ? "hardware error reported"
                             : fmt::format("no valid answer for more than {} s (last: {})",
                                           m.safety.watchdog_timeout_s, to_string(e.health)),
                         e.t);
    }
    case EventKind::following_error: {
      const auto& bus = buses[e.bus]->config();
      const auto& actuator = bus.actuators[e.device];
      const double limit = m.following_error[static_cast<std::size_t>(e.joint)];
      return fmt::format(
          "bus {} id {} ({}): RMS following error {} over the last {} s (limit {}) at t={:.3f} "
          "s; the joint is held, other joints ramped to home (two servos answering under each "
          "other's ids? a blocked or unpowered joint?)",
          bus.name, actuator.device_id, actuator.joint, joint_value(e.value, prismatic, 2),
          m.safety.following_error_window_s, joint_value(limit, prismatic), e.t);
    }
    case EventKind::motion_fault:
      return fmt::format(
          "motion {}: joint {} got a non-finite target ({}) at t={:.3f} s of the run; it never "
          "reached the joint, which braked from its last command, and the run ramped to home",
          m.motion, m.joint_names[static_cast<std::size_t>(e.joint)],
          std::isnan(e.value) ? "NaN" : (e.value > 0 ? "+inf" : "-inf"), e.t);
    default:
      return {};
  }
}

}  // namespace

struct Runner::Impl {
  RobotConfig config;
  RobotModel model;
  std::vector<std::unique_ptr<ActuatorBus>> buses;
  std::unique_ptr<MotionSource> motion;

  void log(const RunOptions& options, const std::string& message) const {
    if (options.log) options.log(message);
  }
};

Runner::Runner(RobotConfig config, std::vector<std::unique_ptr<ActuatorBus>> buses,
               std::unique_ptr<MotionSource> motion)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = std::move(config);
  m.buses = std::move(buses);
  m.motion = std::move(motion);
  std::vector<const BusConfig*> bus_configs;
  for (const auto& bus : m.buses) bus_configs.push_back(&bus->config());
  m.model = make_robot_model(m.config, bus_configs);
}

Runner::~Runner() = default;

const RobotModel& Runner::model() const { return impl_->model; }

RunSummary Runner::run(const RunOptions& options) {
  Impl& m = *impl_;
  const RobotModel& model = m.model;
  const std::size_t n = model.joint_count();
  const std::size_t bus_count = m.buses.size();
  const MonotonicClock wall;
  const Clock& clock = options.lockstep_clock ? static_cast<const Clock&>(*options.lockstep_clock)
                                              : static_cast<const Clock&>(wall);
  const Nanos period = model.period;
  // The motion reads the run's clock from its start on; whatever ends the
  // run, it lets go of it here, before the clock can go.
  struct MotionClockRelease {
    MotionSource& motion;
    ~MotionClockRelease() { motion.stop(); }
  } motion_clock_release{*m.motion};

  RunSummary summary;
  summary.robot = m.config.name;
  summary.backend = options.backend_name;
  summary.lockstep = options.lockstep_clock != nullptr;
  summary.rate_hz = m.config.rate_hz;

  // Real time from configure on: under load its transactions miss their
  // timeouts as the cycle's would. The simulated devices' threads just below
  // the bus I/O threads, since every transaction waits on their answers.
  const bool realtime = options.request_realtime && options.lockstep_clock == nullptr;
  if (realtime) {
    RealtimeStatus rt = request_realtime(options.realtime_priority);
    summary.sched_fifo = rt.sched_fifo;
    summary.sched_priority = rt.priority;
    summary.sched_note = rt.sched_note;
    summary.memory_locked = rt.memory_locked;
    summary.mlock_note = rt.mlock_note;
  } else {
    summary.sched_note = options.lockstep_clock ? "lockstep: not requested" : "not requested";
    summary.mlock_note = summary.sched_note;
  }
  struct RealtimeRelease {
    bool on;
    ~RealtimeRelease() {
      if (on) release_realtime();
    }
  } realtime_release{realtime};
  if (realtime && options.raise_device_threads) {
    summary.device_thread_notes =
        options.raise_device_threads(std::max(1, options.realtime_priority - 2));
  }

  // --- configure -----------------------------------------------------------
  std::vector<std::vector<double>> bus_positions;
  for (auto& bus : m.buses) {
    m.log(options, fmt::format("configure: bus {} ({}, {} devices)", bus->config().name,
                               bus->config().port, bus->config().actuators.size()));
    bus->configure();
    bus_positions.emplace_back(bus->config().actuators.size(), 0.0);
  }
  std::vector<double> measured(n, 0.0);
  for (std::size_t b = 0; b < bus_count; ++b) m.buses[b]->read(bus_positions[b]);
  for (std::size_t j = 0; j < n; ++j) {
    measured[j] = bus_positions[model.slots[j].bus][model.slots[j].device];
  }

  // --- plan: everything the cycle touches is allocated here ----------------
  std::vector<double> first_pose(model.home);
  m.motion->sample(0.0, first_pose);
  for (std::size_t j = 0; j < n; ++j) {
    if (!std::isfinite(first_pose[j])) {
      throw InputError(m.config.motion.where, "motion",
                       fmt::format("the first pose of joint {} is not finite ({})",
                                   model.joint_names[j], first_pose[j]));
    }
  }
  CycleState state(model);
  const double start_ramp = state.begin(model, measured, first_pose);
  if (start_ramp > model.safety.start_ramp_max_s) {
    throw DeviceError(fmt::format(
        "start ramp: {}; within the joint limits the ramp would take {:.1f} s, more than "
        "safety.start_ramp_max_s ({} s). Nothing was switched on: bring the figure nearer its "
        "first pose, or raise the limit",
        slowest_start(model, measured, first_pose), start_ramp, model.safety.start_ramp_max_s));
  }

  TelemetryRing ring(1 + 2 * n, kTelemetryCapacity);
  std::optional<TelemetryWriter> writer;
  std::vector<double> record(1 + 2 * n);
  if (!options.telemetry_path.empty()) {
    writer.emplace(options.telemetry_path, model.joint_names, ring);
  }
  MicrosHistogram period_hist, jitter_hist, busy_hist;
  std::vector<MicrosHistogram> bus_hist(bus_count);
  std::vector<BusIo> io(bus_count);
  std::vector<std::vector<DeviceHealth>> health(bus_count);
  std::vector<std::uint8_t> pending(bus_count, 0);  // a read posted, not yet used
  std::vector<std::uint64_t> io_seen(bus_count, 0);
  for (std::size_t b = 0; b < bus_count; ++b) {
    health[b].assign(m.buses[b]->devices().size(), DeviceHealth::ok);
  }

  // Declared before the I/O threads, so that on any exit the threads stop
  // first and the buses are switched off after them.
  ActivationGuard activation(m.buses);
  std::atomic<std::uint32_t> io_done{0};
  std::vector<std::unique_ptr<BusWorker>> workers;
  for (std::size_t b = 0; b < bus_count; ++b) {
    workers.push_back(std::make_unique<BusWorker>(*m.buses[b], bus_positions[b], io_done));
    const int priority = summary.sched_fifo ? std::max(1, summary.sched_priority - 1) : 0;
    if (!workers.back()->start(priority) && priority > 0) {
      summary.io_thread_notes.push_back(
          fmt::format("bus {}: {}", m.buses[b]->config().name, workers.back()->priority_note()));
    }
  }
  // Waits until every bus with a posted request of the kind is done, or
  // until `deadline` (CLOCK_MONOTONIC; < 0: no limit, as in lockstep).
  auto wait_for = [&](bool reads, Nanos deadline) {
    for (;;) {
      const std::uint32_t seen = io_done.load(std::memory_order_acquire);
      bool all = true;
      for (auto& w : workers) all = all && (reads ? w->read_done() : w->write_done());
      if (all || (deadline >= 0 && wall.now() >= deadline)) return;
      futex_wait_until(io_done, seen, deadline);
    }
  };
  // Faults the cycle decided reach a bus's status while its thread is idle.
  auto publish_faults = [&](std::size_t b) {
    auto devices = m.buses[b]->devices();
    for (std::size_t d = 0; d < devices.size(); ++d) {
      devices[d].faulted = state.faulted()[b][d] != 0;
    }
  };

  // --- activate --------------------------------------------------------------
  // A stop requested while the buses were brought up: nothing is switched on.
  if (options.controls && options.controls->stop.load()) {
    m.log(options, "stop requested before activation: nothing was switched on");
    if (options.monitor) options.monitor->publish_ended();
    summary.end_reason = EndReason::signal;
    for (std::size_t b = 0; b < bus_count; ++b) {
      summary.buses.push_back(BusReport{m.buses[b]->config().name, {}, 0});
    }
    return summary;
  }
  activation.activate_all();
  m.log(options, "activate: torque on; ramping from the measured pose to the first pose");

  // --- run -----------------------------------------------------------------
  const Nanos start = clock.now();
  Nanos deadline = start;
  Nanos previous_wake = -1;
  double last_period_s = -1.0;
  CycleInputs in;
  in.buses = io;
  in.motion_duration_s = options.duration_s;
  MotionCommand steer;
  ShowCommand show;
  JogCommand jog;
  constexpr std::size_t kManualPerCycle = 64;
  std::vector<ManualTarget> manual(kManualPerCycle);
  RunMonitor* const monitor = options.monitor;
  std::vector<std::span<const DeviceStatus>> monitor_devices(bus_count);
  bool torque_off_now = false;
  while (!state.done()) {
    if (options.lockstep_clock) options.lockstep_clock->set(deadline);
    const Nanos wake = clock.now();
    const Nanos wake_wall = wall.now();
    jitter_hist.add(to_seconds(wake - deadline));
    if (previous_wake >= 0) {
      last_period_s = to_seconds(wake - previous_wake);
      period_hist.add(last_period_s);
    }
    previous_wake = wake;

    // read: every idle bus reads on its own thread; a bus still busy from an
    // earlier cycle is late. A read that came back after an earlier cycle's
    // budget is used now.
    for (std::size_t b = 0; b < bus_count; ++b) {
      io[b].fresh = false;
      if (pending[b]) continue;
      if (!workers[b]->idle()) continue;
      if (workers[b]->io_cycles() != io_seen[b]) {
        io_seen[b] = workers[b]->io_cycles();
        bus_hist[b].add(to_seconds(workers[b]->last_io_ns()));
      }
      publish_faults(b);
      workers[b]->post_read();
      pending[b] = 1;
    }
    // The budget counts from the deadline, not from a late wake-up.
    wait_for(true, options.lockstep_clock
                       ? Nanos{-1}
                       : deadline + static_cast<Nanos>(kReadBudget * static_cast<double>(period)));
    for (std::size_t b = 0; b < bus_count; ++b) {
      if (!pending[b] || !workers[b]->read_done()) continue;
      pending[b] = 0;
      io[b].fresh = true;
      auto devices = m.buses[b]->devices();
      for (std::size_t d = 0; d < devices.size(); ++d) health[b][d] = devices[d].health;
      io[b].positions = workers[b]->positions();
      io[b].health = health[b];
    }

    in.t = to_seconds(deadline - start);  // nominal time: smooth motion
    in.stop = options.controls && options.controls->stop.load(std::memory_order_relaxed);
    in.abort = options.controls && options.controls->abort.load(std::memory_order_relaxed);
    in.steer = options.controls && options.controls->steer.take(steer) ? &steer : nullptr;
    in.jog = options.controls && options.controls->jog.take(jog) ? &jog : nullptr;
    in.show = options.controls && options.controls->show.take(show) ? &show : nullptr;
    // Targets first, then the mode: a target posted after manual mode was
    // switched on is never taken for one sent before it.
    std::size_t manual_count = 0;
    if (options.controls) {
      double target[2];
      while (manual_count < manual.size() && options.controls->manual_targets.pop(target)) {
        manual[manual_count++] = ManualTarget{static_cast<int>(target[0]), target[1]};
      }
      in.manual = options.controls->manual.load(std::memory_order_acquire);
    }
    in.manual_targets = std::span<const ManualTarget>(manual.data(), manual_count);
    const CycleOutputs& out = step(model, *m.motion, state, in);
    if (monitor) {
      // Before the writes are posted: a fresh bus's I/O thread is idle, so
      // its device statuses hold still while they are copied.
      for (std::size_t b = 0; b < bus_count; ++b) {
        monitor_devices[b] = io[b].fresh ? std::span<const DeviceStatus>(m.buses[b]->devices())
                                         : std::span<const DeviceStatus>();
      }
      monitor->publish(in.t, state, out.commands, monitor_devices, summary.overruns,
                       summary.skipped_cycles, in.steer);
      for (const CycleEvent& e : out.events) monitor->push_event(e);
    }
    if (out.show_controlled && options.on_show_command) {
      options.on_show_command(show, in.t - state.motion_start());
    }
    for (const CycleEvent& e : out.events) {
      if (e.kind == EventKind::motion_started) {
        m.motion->start(MotionClock{&clock, deadline, options.lockstep_clock != nullptr});
        if (options.on_motion_start) options.on_motion_start(deadline);
      }
      if (e.kind == EventKind::motion_ended && options.on_motion_end) options.on_motion_end();
    }
    if (out.torque_off_now) {
      torque_off_now = true;
      break;
    }

    // write
    for (std::size_t b = 0; b < bus_count; ++b) {
      if (!out.write[b]) continue;
      std::copy(out.bus_commands[b].begin(), out.bus_commands[b].end(),
                workers[b]->commands().begin());
      workers[b]->post_write();
    }
    // Lockstep: the writes land before the clock moves on (deterministic).
    if (options.lockstep_clock) wait_for(false, -1);

    if (writer) {
      record[0] = in.t;
      std::copy(out.commands.begin(), out.commands.end(), record.begin() + 1);
      const auto seen = state.measured();
      std::copy(seen.begin(), seen.end(), record.begin() + 1 + static_cast<long>(n));
      ring.push(record);
    }

    const Nanos busy = wall.now() - wake_wall;
    busy_hist.add(to_seconds(busy));
    if (monitor) {
      monitor->push_timing(CycleTiming{in.t, period_hist.count() ? last_period_s : -1.0,
                                       to_seconds(wake - deadline), to_seconds(busy)});
    }
    if (options.lockstep_clock) {
      deadline += period;
    } else {
      const NextDeadline next = next_deadline(deadline, clock.now(), period);
      deadline = next.deadline;
      if (next.overrun) ++summary.overruns;
      summary.skipped_cycles += next.skipped;
      sleep_until(deadline);
    }
  }
  for (auto& w : workers) w->stop();
  if (monitor) monitor->publish_ended();
  for (std::size_t b = 0; b < bus_count; ++b) {
    if (workers[b]->io_cycles() != io_seen[b]) {
      bus_hist[b].add(to_seconds(workers[b]->last_io_ns()));
    }
    publish_faults(b);
  }

  // --- deactivate --------------------------------------------------------------
  activation.release();
  m.log(options, torque_off_now ? "deactivate: torque switched off at once, without the stop ramp"
                                : "deactivate: torque off");
  if (writer) writer->finish();

  const CycleEnd& end = state.end();
  summary.end_reason =
      end.fault ? EndReason::fault : (end.stopped ? EndReason::signal : EndReason::duration);
  summary.motion_time_s = state.motion_time();
  summary.cycles = state.cycles();
  summary.period = summarize(period_hist);
  summary.jitter = summarize(jitter_hist);
  summary.busy = summarize(busy_hist);
  for (std::size_t b = 0; b < bus_count; ++b) {
    summary.buses.push_back(
        BusReport{m.buses[b]->config().name, summarize(bus_hist[b]), state.late_cycles()[b]});
    const auto& actuators = m.buses[b]->config().actuators;
    auto devices = m.buses[b]->devices();
    for (std::size_t d = 0; d < devices.size(); ++d) {
      summary.devices.push_back(
          DeviceReport{m.buses[b]->config().name, actuators[d].joint, devices[d]});
    }
  }
  for (const CycleEvent& e : state.log()) {
    if (e.kind == EventKind::stop_deadline) {
      summary.torque_cut = fmt::format(
          "the stop ramp had not ended {} s after the stop (safety.stop_deadline_s): torque "
          "switched off at once at t={:.3f} s",
          e.value, e.t);
    } else if (e.kind == EventKind::aborted) {
      summary.torque_cut =
          fmt::format("second stop request at t={:.3f} s: torque switched off at once", e.t);
    } else if (std::string line = describe_event(model, m.buses, e); !line.empty()) {
      summary.faults.push_back(std::move(line));
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    summary.joints.push_back(JointReport{model.joint_names[j], state.rms_error(j),
                                         state.max_error(j), model.prismatic[j] != 0});
  }
  if (writer) {
    summary.telemetry_file = options.telemetry_path;
    summary.telemetry_records = writer->written();
    summary.telemetry_dropped = ring.dropped();
    summary.telemetry_lost = writer->lost();
    if (writer->error() != 0) summary.telemetry_error = std::strerror(writer->error());
  }
  return summary;
}

}  // namespace animrt
