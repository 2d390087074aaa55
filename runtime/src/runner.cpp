#include "animrt/runtime/runner.hpp"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "animrt/core/error.hpp"
#include "animrt/runtime/loop_stats.hpp"
#include "animrt/runtime/pose_ramp.hpp"
#include "animrt/runtime/realtime.hpp"
#include "animrt/runtime/safety_filter.hpp"
#include "animrt/runtime/telemetry.hpp"
#include "bus_worker.hpp"

namespace animrt {
namespace {

constexpr std::size_t kTelemetryCapacity = 1 << 14;  // records (~80 s at 200 Hz)
constexpr double kSettledVelocity = 1e-3;            // rad/s: the stop ramp has ended
constexpr double kMaxSettleTime = 2.0;               // s after the stop ramp, at most
// Real time: how long the loop waits for the buses' reads, as a fraction of
// the period. A bus that has not answered by then keeps its last measurement
// this cycle, and the others go on without it.
constexpr double kReadBudget = 0.6;

enum class Phase { start_ramp, motion, stop_ramp, done };

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

// Where a joint's actuator lives.
struct JointSlot {
  std::size_t bus = 0;
  std::size_t device = 0;
};

}  // namespace

struct Runner::Impl {
  RobotConfig config;
  std::vector<std::unique_ptr<ActuatorBus>> buses;
  std::unique_ptr<MotionSource> motion;

  std::vector<JointSlot> slots;  // per joint
  std::vector<std::vector<double>> bus_positions;
  std::vector<std::vector<double>> bus_commands;
  std::vector<JointLimits> limits;
  std::vector<double> home;

  void log(const RunOptions& options, const std::string& message) const {
    if (options.log) options.log(message);
  }
  // The loop's own record of faulted devices; a bus's DeviceStatus::faulted
  // follows it whenever the bus's I/O thread is idle.
  std::vector<std::vector<std::uint8_t>> faulted;
  bool joint_faulted(std::size_t j) const { return faulted[slots[j].bus][slots[j].device] != 0; }
  // Reads every bus; io_time gets each bus's read time (wall clock).
  void read_all(std::vector<double>& measured, const MonotonicClock& wall,
                std::vector<Nanos>& io_time) {
    for (std::size_t b = 0; b < buses.size(); ++b) {
      const Nanos t0 = wall.now();
      buses[b]->read(bus_positions[b]);
      io_time[b] = wall.now() - t0;
    }
    for (std::size_t j = 0; j < slots.size(); ++j) {
      measured[j] = bus_positions[slots[j].bus][slots[j].device];
    }
  }
};

Runner::Runner(RobotConfig config, std::vector<std::unique_ptr<ActuatorBus>> buses,
               std::unique_ptr<MotionSource> motion)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.config = std::move(config);
  m.buses = std::move(buses);
  m.motion = std::move(motion);
  const std::size_t n = m.config.joints.size();
  m.slots.resize(n);
  std::vector<bool> bound(n, false);
  for (std::size_t b = 0; b < m.buses.size(); ++b) {
    const auto& actuators = m.buses[b]->config().actuators;
    m.bus_positions.emplace_back(actuators.size(), 0.0);
    m.bus_commands.emplace_back(actuators.size(), 0.0);
    for (std::size_t d = 0; d < actuators.size(); ++d) {
      const int j = actuators[d].joint_index;
      if (j < 0 || static_cast<std::size_t>(j) >= n) {
        throw std::logic_error("actuator bound to an unknown joint index");
      }
      m.slots[j] = JointSlot{b, d};
      bound[j] = true;
    }
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (!bound[j]) throw std::logic_error("joint " + m.config.joints[j].name + " has no actuator");
    m.limits.push_back(m.config.joints[j].limits);
    m.home.push_back(m.config.joints[j].home);
  }
}

Runner::~Runner() = default;

RunSummary Runner::run(const RunOptions& options) {
  Impl& m = *impl_;
  const std::size_t n = m.config.joints.size();
  const MonotonicClock wall;
  const Clock& clock = options.lockstep_clock ? static_cast<const Clock&>(*options.lockstep_clock)
                                              : static_cast<const Clock&>(wall);
  const Nanos period = from_seconds(1.0 / m.config.rate_hz);
  const double dt = to_seconds(period);

  RunSummary summary;
  summary.robot = m.config.name;
  summary.backend = options.backend_name;
  summary.lockstep = options.lockstep_clock != nullptr;
  summary.rate_hz = m.config.rate_hz;

  // --- configure -----------------------------------------------------------
  for (auto& bus : m.buses) {
    m.log(options, fmt::format("configure: bus {} ({}, {} devices)", bus->config().name,
                               bus->config().port, bus->config().actuators.size()));
    bus->configure();
  }
  std::vector<double> measured(n, 0.0);
  std::vector<Nanos> io_time(m.buses.size(), 0);
  m.read_all(measured, wall, io_time);

  // --- activate --------------------------------------------------------------
  std::size_t activated = 0;
  try {
    for (; activated < m.buses.size(); ++activated) m.buses[activated]->activate();
  } catch (...) {
    for (std::size_t b = 0; b < activated; ++b) m.buses[b]->deactivate();
    throw;
  }
  m.log(options, "activate: torque on; ramping from the measured pose to the first pose");

  // Everything the cycle touches is allocated here, before it starts.
  SafetyFilter filter(m.limits, dt);
  filter.reset(measured);
  std::vector<double> targets(n), commands(n), previous_commands(measured);
  std::vector<double> first_pose(m.home);
  m.motion->sample(0.0, first_pose);
  PoseRamp ramp(n);
  ramp.plan(measured, first_pose, m.limits, m.config.safety.start_ramp_s);
  std::vector<double> ramp_from(n), ramp_to(n);

  std::vector<double> sq_error(n, 0.0), max_error(n, 0.0);
  std::uint64_t error_samples = 0;
  std::vector<std::vector<Nanos>> last_ok(m.buses.size());
  m.faulted.assign(m.buses.size(), {});
  for (std::size_t b = 0; b < m.buses.size(); ++b) {
    last_ok[b].assign(m.buses[b]->devices().size(), clock.now());
    m.faulted[b].assign(m.buses[b]->devices().size(), 0);
  }
  // One I/O thread per bus (started below, after the real-time request).
  std::atomic<std::uint32_t> io_done{0};
  std::vector<std::unique_ptr<BusWorker>> workers;
  for (std::size_t b = 0; b < m.buses.size(); ++b) {
    workers.push_back(std::make_unique<BusWorker>(*m.buses[b], m.bus_positions[b], io_done));
  }
  std::vector<std::uint8_t> fresh(m.buses.size(), 0);    // a read to use this cycle
  std::vector<std::uint8_t> pending(m.buses.size(), 0);  // a read posted, not yet used
  std::vector<std::uint64_t> late_cycles(m.buses.size(), 0);
  std::vector<std::uint64_t> io_seen(m.buses.size(), 0);
  MicrosHistogram period_hist, jitter_hist, busy_hist;
  std::vector<MicrosHistogram> bus_hist(m.buses.size());
  std::vector<std::string> fault_lines;
  fault_lines.reserve(n);
  // Fault events are recorded as (bus, device, health) in the cycle and turned
  // into text afterwards.
  struct FaultEvent {
    std::size_t bus, device;
    DeviceHealth health;
    double at;
  };
  std::vector<FaultEvent> fault_events;
  fault_events.reserve(n);

  TelemetryRing ring(1 + 2 * n, kTelemetryCapacity);
  std::optional<TelemetryWriter> writer;
  std::vector<double> record(1 + 2 * n);
  if (!options.telemetry_path.empty()) {
    std::vector<std::string> names;
    for (const auto& joint : m.config.joints) names.push_back(joint.name);
    writer.emplace(options.telemetry_path, names, ring);
  }

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
  for (auto& w : workers)
    w->start(summary.sched_fifo ? std::max(1, summary.sched_priority - 1) : 0);
  // Waits until every bus with a posted request of the kind is done, or
  // until `deadline` (wall clock; < 0: no limit, as in lockstep).
  auto wait_for = [&](bool reads, Nanos deadline) {
    for (;;) {
      const std::uint32_t seen = io_done.load(std::memory_order_acquire);
      bool all = true;
      for (auto& w : workers) all = all && (reads ? w->read_done() : w->write_done());
      if (all) return;
      Nanos timeout = -1;
      if (deadline >= 0) {
        timeout = deadline - wall.now();
        if (timeout <= 0) return;
      }
      futex_wait(io_done, seen, timeout);
    }
  };

  // --- run -----------------------------------------------------------------
  const Nanos watchdog = from_seconds(m.config.safety.watchdog_timeout_s);
  const Nanos start = clock.now();
  Nanos deadline = start;
  Nanos previous_wake = -1;
  Phase phase = Phase::start_ramp;
  double phase_start = 0.0;  // seconds since `start`
  double motion_start = 0.0;
  std::uint64_t cycle = 0;
  bool fault = false;
  bool stop_requested = false;

  auto begin_stop = [&](double now_s) {
    const auto position = filter.position();
    for (std::size_t j = 0; j < n; ++j) {
      ramp_from[j] = position[j];
      // A faulted joint cannot be commanded: it is held where it was.
      ramp_to[j] = m.joint_faulted(j) ? position[j] : m.home[j];
    }
    ramp.plan(ramp_from, ramp_to, m.limits, m.config.safety.stop_ramp_s);
    if (phase == Phase::motion) {
      summary.motion_time_s = now_s - motion_start;
      if (options.on_motion_end) options.on_motion_end();
    }
    phase = Phase::stop_ramp;
    phase_start = now_s;
  };

  while (phase != Phase::done) {
    if (options.lockstep_clock) options.lockstep_clock->set(deadline);
    const Nanos wake = clock.now();
    const Nanos wake_wall = wall.now();
    jitter_hist.add(to_seconds(wake - deadline));
    if (previous_wake >= 0) period_hist.add(to_seconds(wake - previous_wake));
    previous_wake = wake;
    const double now_s = to_seconds(deadline - start);  // nominal time: smooth motion

    // read: every idle bus reads on its own thread; a bus still busy from an
    // earlier cycle is late and keeps its last measurement.
    // A read that finished after an earlier cycle's budget is used now (and
    // its bus writes this cycle); an idle bus gets a new read.
    for (std::size_t b = 0; b < workers.size(); ++b) {
      fresh[b] = 0;
      if (pending[b]) {
        if (workers[b]->read_done()) {
          pending[b] = 0;
          fresh[b] = 1;
        }
      } else if (workers[b]->idle()) {
        if (workers[b]->io_cycles() != io_seen[b]) {
          io_seen[b] = workers[b]->io_cycles();
          bus_hist[b].add(to_seconds(workers[b]->last_io_ns()));
        }
        // Faults decided while the bus was busy reach its status now.
        auto devices = m.buses[b]->devices();
        for (std::size_t d = 0; d < devices.size(); ++d) devices[d].faulted = m.faulted[b][d] != 0;
        workers[b]->post_read();
        pending[b] = 1;
      }
    }
    wait_for(true, options.lockstep_clock
                       ? Nanos{-1}
                       : wake_wall + static_cast<Nanos>(kReadBudget * static_cast<double>(period)));
    for (std::size_t b = 0; b < workers.size(); ++b) {
      if (pending[b] && workers[b]->read_done()) {
        pending[b] = 0;
        fresh[b] = 1;
      }
      if (!fresh[b]) ++late_cycles[b];
    }
    for (std::size_t j = 0; j < n; ++j) {
      if (fresh[m.slots[j].bus])
        measured[j] = workers[m.slots[j].bus]->positions()[m.slots[j].device];
    }

    // watchdog: a device silent (or answering garbage) for too long, or one
    // reporting a hardware error, is faulted. A late bus is judged by its
    // answers once its I/O thread is done (every transaction is bounded by
    // the bus timeout); only a bus stuck for ten watchdog times (a thread
    // that never returns) is faulted without them. A descheduled I/O thread
    // on a loaded machine is therefore not mistaken for silent devices.
    for (std::size_t b = 0; b < m.buses.size(); ++b) {
      const std::size_t count = m.faulted[b].size();
      auto devices = m.buses[b]->devices();
      for (std::size_t d = 0; d < count; ++d) {
        if (m.faulted[b][d]) continue;
        if (!fresh[b] && wake - last_ok[b][d] <= 10 * watchdog) continue;
        const DeviceHealth health = fresh[b] ? devices[d].health : DeviceHealth::timeout;
        if (health == DeviceHealth::ok) {
          last_ok[b][d] = wake;
        } else if (health == DeviceHealth::hardware_error || wake - last_ok[b][d] > watchdog) {
          m.faulted[b][d] = 1;
          if (fresh[b]) devices[d].faulted = true;
          fault = true;
          fault_events.push_back(FaultEvent{b, d, health, now_s});
        }
      }
    }

    // error of the last command against what was measured since
    for (std::size_t j = 0; j < n; ++j) {
      if (m.joint_faulted(j) || cycle == 0) continue;
      const double e = std::abs(previous_commands[j] - measured[j]);
      sq_error[j] += e * e;
      max_error[j] = std::max(max_error[j], e);
    }
    if (cycle > 0) ++error_samples;

    // phase changes
    const bool stop_now = options.stop_request && options.stop_request->load();
    if (phase != Phase::stop_ramp) {
      if (fault) {
        begin_stop(now_s);
      } else if (stop_now) {
        stop_requested = true;
        begin_stop(now_s);
      } else if (phase == Phase::motion && options.duration_s > 0.0 &&
                 now_s - motion_start >= options.duration_s) {
        begin_stop(now_s);
      } else if (phase == Phase::start_ramp && now_s - phase_start >= ramp.duration()) {
        phase = Phase::motion;
        motion_start = now_s;
        if (options.on_motion_start) options.on_motion_start(deadline);
      }
    }

    // sample
    switch (phase) {
      case Phase::start_ramp:
      case Phase::stop_ramp:
        ramp.sample(now_s - phase_start, targets);
        break;
      case Phase::motion:
        std::copy(m.home.begin(), m.home.end(), targets.begin());
        m.motion->sample(now_s - motion_start, targets);
        break;
      case Phase::done:
        break;
    }
    for (std::size_t j = 0; j < n; ++j) {
      if (m.joint_faulted(j)) targets[j] = filter.position()[j];
    }

    // filter, write
    filter.step(targets, commands);
    for (std::size_t j = 0; j < n; ++j) {
      if (fresh[m.slots[j].bus])
        workers[m.slots[j].bus]->commands()[m.slots[j].device] = commands[j];
    }
    for (std::size_t b = 0; b < workers.size(); ++b) {
      if (fresh[b]) workers[b]->post_write();
    }
    // Lockstep: the writes land before the clock moves on (deterministic).
    if (options.lockstep_clock) wait_for(false, -1);
    std::copy(commands.begin(), commands.end(), previous_commands.begin());

    // telemetry
    if (writer) {
      record[0] = now_s;
      std::copy(commands.begin(), commands.end(), record.begin() + 1);
      std::copy(measured.begin(), measured.end(), record.begin() + 1 + static_cast<long>(n));
      ring.push(record);
    }

    if (phase == Phase::stop_ramp && now_s - phase_start >= ramp.duration()) {
      double fastest = 0.0;
      for (double v : filter.velocity()) fastest = std::max(fastest, std::abs(v));
      if (fastest < kSettledVelocity || now_s - phase_start >= ramp.duration() + kMaxSettleTime) {
        phase = Phase::done;
      }
    }

    ++cycle;
    busy_hist.add(to_seconds(wall.now() - wake_wall));
    deadline += period;
    if (options.lockstep_clock == nullptr) {
      const Nanos late = clock.now() - deadline;
      if (late > 0) {
        ++summary.overruns;
        // Missed whole cycles are skipped, not caught up in a burst.
        if (late > period) deadline += (late / period) * period;
      }
      sleep_until(deadline);
    }
  }
  for (auto& w : workers) w->stop();
  for (std::size_t b = 0; b < m.buses.size(); ++b) {
    if (workers[b]->io_cycles() != io_seen[b])
      bus_hist[b].add(to_seconds(workers[b]->last_io_ns()));
    auto devices = m.buses[b]->devices();
    for (std::size_t d = 0; d < devices.size(); ++d) devices[d].faulted = m.faulted[b][d] != 0;
  }
  if (realtime) release_realtime();

  // --- deactivate --------------------------------------------------------------
  for (auto& bus : m.buses) bus->deactivate();
  m.log(options, "deactivate: torque off");
  if (writer) writer->finish();

  summary.end_reason =
      fault ? EndReason::fault : (stop_requested ? EndReason::signal : EndReason::duration);
  summary.cycles = cycle;
  summary.period = summarize(period_hist);
  summary.jitter = summarize(jitter_hist);
  summary.busy = summarize(busy_hist);
  for (std::size_t b = 0; b < m.buses.size(); ++b) {
    summary.buses.push_back(
        BusReport{m.buses[b]->config().name, summarize(bus_hist[b]), late_cycles[b]});
    const auto& actuators = m.buses[b]->config().actuators;
    auto devices = m.buses[b]->devices();
    for (std::size_t d = 0; d < devices.size(); ++d) {
      summary.devices.push_back(
          DeviceReport{m.buses[b]->config().name, actuators[d].joint, devices[d]});
    }
  }
  for (const auto& event : fault_events) {
    const auto& bus = m.buses[event.bus]->config();
    const auto& actuator = bus.actuators[event.device];
    summary.faults.push_back(
        fmt::format("bus {} id {} ({}): {} at t={:.3f} s; other joints ramped to home", bus.name,
                    actuator.device_id, actuator.joint,
                    event.health == DeviceHealth::hardware_error
                        ? "hardware error reported"
                        : fmt::format("no valid answer for more than {} s (last: {})",
                                      m.config.safety.watchdog_timeout_s, to_string(event.health)),
                    event.at));
  }
  for (std::size_t j = 0; j < n; ++j) {
    const double rms =
        error_samples ? std::sqrt(sq_error[j] / static_cast<double>(error_samples)) : 0.0;
    summary.joints.push_back(JointReport{m.config.joints[j].name, rms, max_error[j],
                                         m.config.joints[j].type == JointType::prismatic});
  }
  if (writer) {
    summary.telemetry_file = options.telemetry_path;
    summary.telemetry_records = writer->written();
    summary.telemetry_dropped = ring.dropped();
  }
  return summary;
}

}  // namespace animrt
