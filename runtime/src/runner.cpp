#include "animrt/runtime/runner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include "animrt/core/error.hpp"
#include "animrt/runtime/cycle.hpp"
#include "animrt/runtime/realtime.hpp"
#include "animrt/runtime/robot_model.hpp"
#include "bus_failures.hpp"
#include "run_loop.hpp"

namespace animrt {
namespace {

TimingSummary summarize(const MicrosHistogram& h) {
  return TimingSummary{h.count(), h.quantile(0.5), h.quantile(0.99), h.max()};
}

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

// "temperature 85 C (fault limit 75 C)", for a health event.
std::string describe_health(const HealthLimits& lim, const CycleEvent& e,
                            const std::string& error_text) {
  const bool fault = e.kind == EventKind::health_fault;
  switch (e.check) {
    case HealthCheck::temperature:
      return fmt::format("temperature {:g} C ({} limit {:g} C)", e.value,
                         fault ? "fault" : "warning",
                         fault ? lim.temperature_fault_c : lim.temperature_warn_c);
    case HealthCheck::voltage:
      return fmt::format("undervoltage: supply {:.1f} V ({} limit {:g} V)", e.value,
                         fault ? "fault" : "warning",
                         fault ? lim.voltage_fault_v : lim.voltage_warn_v);
    case HealthCheck::stall:
      return fmt::format(
          "stall: current {:.2f} A (limit {:g} A) for {:g} s while the joint did not follow",
          e.value, lim.stall_current_a, lim.stall_time_s);
    case HealthCheck::error_bits:
      if (e.value < 0.0) return "the device reports a hardware error (its error bits are not read)";
      return fmt::format("device error bits 0x{:02X}{}", static_cast<unsigned>(e.value),
                         error_text.empty() ? "" : " (" + error_text + ")");
    case HealthCheck::none:
      break;
  }
  return "health";
}

// describe_health with the device's own words for its error bits.
std::string health_text(const RobotModel& m, const std::vector<std::unique_ptr<ActuatorBus>>& buses,
                        const CycleEvent& e) {
  const std::string words =
      e.check == HealthCheck::error_bits && e.value >= 0.0
          ? buses[e.bus]->error_words(e.device, static_cast<std::uint32_t>(e.value))
          : std::string();
  return describe_health(m.buses[e.bus].health_of(e.device), e, words);
}

std::string describe_event(const RobotModel& m,
                           const std::vector<std::unique_ptr<ActuatorBus>>& buses,
                           const std::vector<std::string>& lag_notes, const CycleEvent& e) {
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
      const auto joint = static_cast<std::size_t>(e.joint);
      const double limit = m.following_error[joint];
      // A motion faster than the servos turn (found on load) comes first.
      const std::string lag =
          joint < lag_notes.size() && !lag_notes[joint].empty() ? lag_notes[joint] + "? " : "";
      return fmt::format(
          "bus {} id {} ({}): RMS following error {} over the last {} s (limit {}) at t={:.3f} "
          "s; the joint is held, other joints ramped to home ({}two servos answering under each "
          "other's ids? a blocked or unpowered joint?)",
          bus.name, actuator.device_id, actuator.joint, joint_value(e.value, prismatic, 2),
          m.safety.following_error_window_s, joint_value(limit, prismatic), e.t, lag);
    }
    case EventKind::health_fault: {
      const auto& bus = buses[e.bus]->config();
      const auto& actuator = bus.actuators[e.device];
      return fmt::format(
          "bus {} id {} ({}): {}; at t={:.3f} s; the device was switched off, "
          "other joints ramped to home",
          bus.name, actuator.device_id, actuator.joint, health_text(m, buses, e), e.t);
    }
    case EventKind::motion_fault:
      return fmt::format(
          "motion {}: joint {} got a non-finite target ({}) at t={:.3f} s of the run; it never "
          "reached the joint, which braked from its last command, and the run ramped to home",
          m.motion, m.joint_names[static_cast<std::size_t>(e.joint)],
          std::isnan(e.value) ? "NaN" : (e.value > 0 ? "+inf" : "-inf"), e.t);
    case EventKind::sensor_stale:
      return fmt::format(
          "IMU {}: no reading for {:.3f} s (stale_timeout_s {}) at t={:.3f} s; joints ramped to "
          "home",
          m.imus[e.bus].name, e.value, m.imus[e.bus].stale_timeout_s, e.t);
    case EventKind::tilted:
      return fmt::format(
          "tilt watch: the trunk tilted {:.1f} deg (safety.tilt_limit_deg {:.1f} for {} s) at "
          "t={:.3f} s; {}",
          e.value * 180.0 / M_PI, m.safety.tilt_limit_rad * 180.0 / M_PI, m.safety.tilt_time_s, e.t,
          m.safety.on_tilt == SafetyConfig::OnTilt::hold
              ? fmt::format("every joint held where it was for {} s, then torque off",
                            m.safety.tilt_hold_s)
              : std::string("torque switched off at once"));
    default:
      return {};
  }
}

// Real time from configure on: under load its transactions miss their
// timeouts as the cycle's would. The simulated devices' threads just below
// the bus I/O threads, since every transaction waits on their answers. What
// was granted goes in the summary; it is released when the run ends.
class RealtimeScope {
 public:
  RealtimeScope(const RunOptions& options, RunSummary& summary)
      : on_(options.request_realtime && options.lockstep_clock == nullptr) {
    if (on_) {
      const RealtimeStatus rt = request_realtime(options.realtime_priority);
      summary.sched_fifo = rt.sched_fifo;
      summary.sched_priority = rt.priority;
      summary.sched_note = rt.sched_note;
      summary.memory_locked = rt.memory_locked;
      summary.mlock_note = rt.mlock_note;
    } else {
      summary.sched_note = options.lockstep_clock ? "lockstep: not requested" : "not requested";
      summary.mlock_note = summary.sched_note;
    }
    if (on_ && options.raise_device_threads) {
      summary.device_thread_notes =
          options.raise_device_threads(std::max(1, options.realtime_priority - 2));
    }
  }
  ~RealtimeScope() {
    if (on_) release_realtime();
  }
  RealtimeScope(const RealtimeScope&) = delete;
  RealtimeScope& operator=(const RealtimeScope&) = delete;

 private:
  bool on_;
};

}  // namespace

struct Runner::Impl {
  RobotConfig config;
  RobotModel model;
  std::vector<std::unique_ptr<ActuatorBus>> buses;
  std::unique_ptr<MotionSource> motion;

  void log(const RunOptions& options, const std::string& message) const {
    if (options.log) options.log(message);
  }

  // The lifecycle's stages, in the order run() takes them.
  RunSummary begin_summary(const RunOptions& options) const;
  std::vector<std::vector<double>> configure(const RunOptions& options);
  std::vector<double> measured_pose(std::span<const std::vector<double>> bus_positions) const;
  void plan_start(CycleState& state, std::span<const double> measured) const;
  RunSummary stopped_before_activation(const RunOptions& options, RunSummary summary) const;
  void report(const RunLoop& loop, const CycleState& state, const RunOptions& options,
              RunSummary& summary) const;
  void report_events(const CycleState& state, RunSummary& summary) const;
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

RunSummary Runner::Impl::begin_summary(const RunOptions& options) const {
  RunSummary summary;
  summary.robot = config.name;
  summary.backend = options.backend_name;
  summary.lockstep = options.lockstep_clock != nullptr;
  summary.rate_hz = config.rate_hz;
  return summary;
}

// Opens every bus and reads where its devices are; returns the positions per
// bus and device. Every bus is tried before giving up, so that one error
// names every port that cannot be opened (a figure with three unplugged
// adapters is not fixed one run at a time).
std::vector<std::vector<double>> Runner::Impl::configure(const RunOptions& options) {
  std::vector<std::vector<double>> bus_positions;
  std::vector<std::string> failed;
  for (auto& bus : buses) {
    log(options, fmt::format("configure: bus {} ({}, {} devices)", bus->config().name,
                             bus->config().port, bus->config().actuators.size()));
    try {
      bus->configure();
    } catch (const DeviceError& e) {
      failed.emplace_back(e.what());
    }
    bus_positions.emplace_back(bus->config().actuators.size(), 0.0);
  }
  if (!failed.empty()) throw DeviceError(bus_failures(failed, buses.size()));
  for (std::size_t b = 0; b < buses.size(); ++b) buses[b]->read(bus_positions[b]);
  return bus_positions;
}

std::vector<double> Runner::Impl::measured_pose(
    std::span<const std::vector<double>> bus_positions) const {
  std::vector<double> measured(model.joint_count(), 0.0);
  for (std::size_t j = 0; j < measured.size(); ++j) {
    measured[j] = bus_positions[model.slots[j].bus][model.slots[j].device];
  }
  return measured;
}

// The start ramp from the measured pose to the motion's first pose; refuses a
// first pose that is not finite and a ramp longer than its limit, before
// anything is switched on.
void Runner::Impl::plan_start(CycleState& state, std::span<const double> measured) const {
  std::vector<double> first_pose(model.home);
  motion->sample(0.0, first_pose);
  for (std::size_t j = 0; j < model.joint_count(); ++j) {
    if (!std::isfinite(first_pose[j])) {
      throw InputError(config.motion.where, "motion",
                       fmt::format("the first pose of joint {} is not finite ({})",
                                   model.joint_names[j], first_pose[j]));
    }
  }
  const double start_ramp = state.begin(model, measured, first_pose);
  if (start_ramp > model.safety.start_ramp_max_s) {
    throw DeviceError(fmt::format(
        "start ramp: {}; within the joint limits the ramp would take {:.1f} s, more than "
        "safety.start_ramp_max_s ({} s). Nothing was switched on: bring the figure nearer its "
        "first pose, or raise the limit",
        slowest_start(model, measured, first_pose), start_ramp, model.safety.start_ramp_max_s));
  }
}

RunSummary Runner::Impl::stopped_before_activation(const RunOptions& options,
                                                   RunSummary summary) const {
  log(options, "stop requested before activation: nothing was switched on");
  if (options.monitor) options.monitor->publish_ended();
  summary.end_reason = EndReason::signal;
  for (const auto& bus : buses) summary.buses.push_back(BusReport{bus->config().name, {}, 0});
  return summary;
}

void Runner::Impl::report(const RunLoop& loop, const CycleState& state, const RunOptions& options,
                          RunSummary& summary) const {
  const CycleEnd& end = state.end();
  summary.end_reason =
      end.fault ? EndReason::fault : (end.stopped ? EndReason::signal : EndReason::duration);
  summary.motion_time_s = state.motion_time();
  summary.cycles = state.cycles();
  summary.period = summarize(loop.period());
  summary.jitter = summarize(loop.jitter());
  summary.busy = summarize(loop.busy());
  for (std::size_t b = 0; b < buses.size(); ++b) {
    const BusConfig& bus = buses[b]->config();
    summary.buses.push_back(BusReport{bus.name, summarize(loop.bus_io(b)), state.late_cycles()[b]});
    const auto devices = loop.device_view(b);
    for (std::size_t d = 0; d < devices.size(); ++d) {
      summary.devices.push_back(
          DeviceReport{bus.name, bus.actuators[d].joint, devices[d], state.health_stats()[b][d]});
    }
  }
  for (std::size_t i = 0; i < model.imus.size(); ++i) {
    summary.imus.push_back(
        ImuReport{model.imus[i].name, state.imu_readings(i), state.imu_late_cycles()[i],
                  state.imu_missing(i, model.imus[i].rate_hz), state.imu_faulted()[i] != 0});
  }
  report_events(state, summary);
  for (std::size_t j = 0; j < model.joint_count(); ++j) {
    summary.joints.push_back(JointReport{model.joint_names[j], state.rms_error(j),
                                         state.max_error(j), model.prismatic[j] != 0});
  }
  if (const TelemetryWriter* writer = loop.telemetry()) {
    summary.telemetry_file = options.telemetry_path;
    summary.telemetry_records = writer->written();
    summary.telemetry_dropped = loop.telemetry_dropped();
    summary.telemetry_lost = writer->lost();
    if (writer->error() != 0) summary.telemetry_error = std::strerror(writer->error());
  }
}

// The run's end in the recording's /events, then the file is closed and
// what reached it goes in the summary.
static void close_recording(McapRecorder& recording, const RunOptions& options,
                            RunSummary& summary) {
  // The faults and a torque cut are in /events already, at their cycles.
  const std::pair<LogLevel, std::string> end{
      summary.end_reason == EndReason::fault ? LogLevel::error : LogLevel::info,
      fmt::format("run ended: {} after {} cycles", to_string(summary.end_reason), summary.cycles)};
  recording.close({&end, 1});
  summary.record_file = options.record_path;
  summary.record_messages = recording.messages();
  summary.record_dropped = recording.dropped();
  summary.record_lost = recording.lost();
  if (recording.error() != 0) summary.record_error = std::strerror(recording.error());
}

void Runner::Impl::report_events(const CycleState& state, RunSummary& summary) const {
  for (const CycleEvent& e : state.log()) {
    if (e.kind == EventKind::stop_deadline) {
      summary.torque_cut = fmt::format(
          "the stop ramp had not ended {} s after the stop (safety.stop_deadline_s): torque "
          "switched off at once at t={:.3f} s",
          e.value, e.t);
    } else if (e.kind == EventKind::aborted) {
      summary.torque_cut =
          fmt::format("second stop request at t={:.3f} s: torque switched off at once", e.t);
    } else if (e.kind == EventKind::health_warning) {
      const auto& bus = buses[e.bus]->config();
      const auto& actuator = bus.actuators[e.device];
      summary.health_warnings.push_back(fmt::format("bus {} id {} ({}): {} at t={:.3f} s", bus.name,
                                                    actuator.device_id, actuator.joint,
                                                    health_text(model, buses, e), e.t));
    } else if (e.kind == EventKind::stop_unreached) {
      const auto joint = static_cast<std::size_t>(e.joint);
      summary.stop_warnings.push_back(fmt::format(
          "joint {}: {} off its stop pose when torque went off at t={:.3f} s, the stop's wait "
          "for the joints over (blocked, or slower than the stop ramp?)",
          model.joint_names[joint], joint_value(e.value, model.prismatic[joint] != 0), e.t));
    } else if (std::string line = describe_event(model, buses, config.lag_notes, e);
               !line.empty()) {
      summary.faults.push_back(std::move(line));
    }
  }
}

RunSummary Runner::run(const RunOptions& options) {
  Impl& m = *impl_;
  RunSummary summary = m.begin_summary(options);
  const RealtimeScope realtime(options, summary);
  const std::vector<std::vector<double>> bus_positions = m.configure(options);
  // Everything the cycle touches is allocated from here to activation.
  CycleState state(m.model);
  m.plan_start(state, m.measured_pose(bus_positions));
  RunLoop loop(m.model, m.buses, *m.motion, options, state, bus_positions, summary);
  // A stop requested while the buses were brought up: nothing is switched on.
  if (options.controls && options.controls->stop.load()) {
    return m.stopped_before_activation(options, std::move(summary));
  }
  loop.activate();
  m.log(options, "activate: torque on; ramping from the measured pose to the first pose");
  const bool torque_cut = loop.run();
  loop.finish();
  m.log(options, torque_cut ? "deactivate: torque switched off at once, without the stop ramp"
                            : "deactivate: torque off");
  m.report(loop, state, options, summary);
  if (McapRecorder* recording = loop.recording()) close_recording(*recording, options, summary);
  return summary;
}

}  // namespace animrt
