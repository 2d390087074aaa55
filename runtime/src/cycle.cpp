#include "animrt/runtime/cycle.hpp"

#include <algorithm>
#include <cmath>

namespace animrt {
namespace {

constexpr double kSettledVelocity = 1e-3;  // rad/s: the stop ramp has ended
// A joint has arrived at the stop pose when measured this close to it (rad
// or m) for kArrivedHold seconds on end: near enough, and still.
constexpr double kArrivedRad = 0.05;  // about 3 deg
constexpr double kArrivedM = 0.003;
constexpr double kArrivedHold = 0.05;
// A late bus is judged by its answers once its I/O thread is done (every
// transaction is bounded by the bus timeout); only a bus stuck for ten
// watchdog times, at most the watchdog plus two seconds (a thread that never
// returns), is faulted without them, so a descheduled I/O thread on a loaded
// machine is not taken for silent devices.
double late_bus_grace(double watchdog) { return std::min(10.0 * watchdog, watchdog + 2.0); }
constexpr std::size_t kEventLogCapacity = 256;
// Times are seconds in doubles; comparisons allow for their rounding, so
// "more than 0.1 s" means what it says at 2.4 - 2.3 too.
constexpr double kTimeEps = 1e-9;

// NaN-aware running extremes: a NaN reading leaves them as they are.
void keep_min(double& best, double v) {
  if (!std::isnan(v) && (std::isnan(best) || v < best)) best = v;
}
void keep_max(double& best, double v) {
  if (!std::isnan(v) && (std::isnan(best) || v > best)) best = v;
}
// v beyond a limit that is set (a NaN limit or reading is never beyond).
bool above(double v, double limit) { return !std::isnan(limit) && v > limit; }
bool below(double v, double limit) { return !std::isnan(limit) && v < limit; }

}  // namespace

const char* to_string(HealthCheck check) {
  switch (check) {
    case HealthCheck::temperature:
      return "temperature";
    case HealthCheck::voltage:
      return "undervoltage";
    case HealthCheck::stall:
      return "stall";
    case HealthCheck::error_bits:
      return "device error bits";
    case HealthCheck::none:
      break;
  }
  return "none";
}

CycleState::CycleState(const RobotModel& model)
    : filter_(model.limits, model.dt), ramp_(model.joint_count()), slots_(model.slots) {
  const std::size_t n = model.joint_count();
  const std::size_t buses = model.buses.size();
  measured_.assign(n, 0.0);
  targets_.assign(n, 0.0);
  ramp_from_.assign(n, 0.0);
  ramp_to_.assign(n, 0.0);
  jog_.assign(n, 0.0);
  manual_pose_.assign(n, 0.0);
  active_.assign(n, 0);
  window_ = std::max<std::size_t>(
      1, static_cast<std::size_t>(std::lround(model.safety.following_error_window_s / model.dt)));
  err_ring_.assign(n * window_, 0.0);
  err_next_.assign(n, 0);
  err_count_.assign(n, 0);
  err_sum_.assign(n, 0.0);
  sq_error_.assign(n, 0.0);
  max_error_.assign(n, 0.0);
  error_samples_.assign(n, 0);
  late_cycles_.assign(buses, 0);
  for (const BusModel& bus : model.buses) {
    last_sent_.emplace_back(bus.joint.size(), 0.0);
    faulted_.emplace_back(bus.joint.size(), 0);
    health_track_.emplace_back(bus.joint.size());
    health_stats_.emplace_back(bus.joint.size());
    switch_off_.emplace_back(bus.joint.size(), 0);
    last_ok_.emplace_back(bus.joint.size(), 0.0);
    out_.bus_commands.emplace_back(bus.joint.size(), 0.0);
  }
  imu_late_.assign(model.imus.size(), 0);
  imu_track_.assign(model.imus.size(), ImuTrack{});
  imu_faulted_.assign(model.imus.size(), 0);
  out_.commands.assign(n, 0.0);
  out_.write.assign(buses, 0);
  // A cycle emits at most a few events per joint and device.
  out_.events.reserve(4 * n + 8);
  log_.reserve(kEventLogCapacity);
}

std::uint64_t CycleState::imu_missing(std::size_t i, double rate_hz) const {
  const ImuTrack& track = imu_track_[i];
  if (track.last < 0.0) return 0;
  // Since the last reading: the reports whose successor is due by now.
  const double silent = std::floor((imu_now_ - track.last) * rate_hz - 1e-6);
  return track.missing + static_cast<std::uint64_t>(std::max(0.0, silent));
}

bool CycleState::joint_faulted(std::size_t j) const {
  return faulted_[slots_[j].bus][slots_[j].device] != 0;
}

double CycleState::rms_error(std::size_t j) const {
  return error_samples_[j] ? std::sqrt(sq_error_[j] / static_cast<double>(error_samples_[j])) : 0.0;
}

double CycleState::begin(const RobotModel& model, std::span<const double> measured,
                         std::span<const double> first_pose) {
  std::copy(measured.begin(), measured.end(), measured_.begin());
  filter_.reset(measured);
  // Until the first write, every device holds the goal it got at activation:
  // where it was measured.
  for (std::size_t j = 0; j < slots_.size(); ++j) {
    last_sent_[slots_[j].bus][slots_[j].device] = measured[j];
  }
  phase_ = Phase::start_ramp;
  phase_start_ = 0.0;
  ramp_.plan(measured, first_pose, model.limits, model.safety.start_ramp_s);
  return ramp_.duration();
}

void CycleState::emit(const CycleEvent& event) {
  if (out_.events.size() < out_.events.capacity()) out_.events.push_back(event);
  if (log_.size() < log_.capacity()) log_.push_back(event);
}

void CycleState::begin_stop(const RobotModel& model, double t) {
  const auto position = filter_.position();
  for (std::size_t j = 0; j < slots_.size(); ++j) {
    ramp_from_[j] = position[j];
    // A faulted joint cannot be commanded: it is held where it was.
    ramp_to_[j] = joint_faulted(j) ? position[j] : model.home[j];
  }
  ramp_.plan(ramp_from_, ramp_to_, model.limits, model.safety.stop_ramp_s);
  if (phase_ == Phase::motion) {
    motion_time_ = t - motion_start_;
    emit(CycleEvent{EventKind::motion_ended, t});
  }
  // After a wind-down the stop began at its request: the deadline counts from there.
  if (phase_ != Phase::stop_ramp) stop_start_ = t;
  phase_ = Phase::stop_ramp;
  phase_start_ = t;
  arrived_since_ = -1.0;
  wind_end_ = -1.0;
}

void CycleState::request_stop(const RobotModel& model, MotionSource& motion, double t) {
  // The wind-down leaves the ramp and the settling their time before the
  // stop deadline, which counts from the request: the motion is granted
  // the rest and eases to rest within it. The cut is kept as a guard.
  const double room =
      model.safety.stop_deadline_s - model.safety.stop_ramp_s - kStopSettleTime - model.dt;
  const double wind = phase_ == Phase::motion && !manual_ && room >= model.dt
                          ? std::min(motion.wind_down(t - motion_start_, room), room)
                          : 0.0;
  if (!(wind >= model.dt)) {
    begin_stop(model, t);
    return;
  }
  motion_time_ = t - motion_start_;
  emit(CycleEvent{EventKind::motion_ended, t});
  phase_ = Phase::stop_ramp;
  phase_start_ = t;
  stop_start_ = t;
  arrived_since_ = -1.0;
  wind_end_ = t + wind;
}

void CycleState::begin_hold(const RobotModel& model, double t) {
  // Every joint holds where the filter has it: the filter brakes what still
  // moves within the limits, and nothing heads for home.
  const auto position = filter_.position();
  std::copy(position.begin(), position.end(), ramp_from_.begin());
  std::copy(position.begin(), position.end(), ramp_to_.begin());
  ramp_.plan(ramp_from_, ramp_to_, model.limits, model.safety.tilt_hold_s);
  if (phase_ == Phase::motion) {
    motion_time_ = t - motion_start_;
    emit(CycleEvent{EventKind::motion_ended, t});
  }
  phase_ = Phase::stop_ramp;
  phase_start_ = t;
  stop_start_ = t;
  arrived_since_ = -1.0;
  wind_end_ = -1.0;
}

// The stages of step(), in the order it runs them. Each reads and writes the
// cycle state only; none allocates.
struct CycleStages {
  // Controls from outside, read once at the start of the cycle.
  static void take_controls(const RobotModel& model, MotionSource& motion, CycleState& s,
                            const CycleInputs& in) {
    // A winding-down walk is not steered back into walking.
    if (in.steer && !s.winding_down()) motion.steer(*in.steer);
    const JogCommand* jog = in.jog;
    if (jog && jog->joint >= 0 && static_cast<std::size_t>(jog->joint) < model.joint_count() &&
        std::isfinite(jog->offset)) {
      s.jog_[static_cast<std::size_t>(jog->joint)] = jog->offset;
    }
  }

  // Measurements: a late bus keeps its last ones.
  static void take_measurements(CycleState& s, const CycleInputs& in) {
    for (std::size_t b = 0; b < in.buses.size(); ++b) {
      if (!in.buses[b].fresh) ++s.late_cycles_[b];
    }
    for (std::size_t j = 0; j < s.slots_.size(); ++j) {
      const JointSlot slot = s.slots_[j];
      const BusIo& io = in.buses[slot.bus];
      s.active_[j] = io.fresh ? 1 : 0;
      if (io.fresh && std::isfinite(io.positions[slot.device])) {
        s.measured_[j] = io.positions[slot.device];
      }
    }
  }

  // Watchdog: a device silent (or answering garbage) for longer than the
  // watchdog, or one reporting a hardware error, is faulted. Returns whether
  // a device faulted this cycle.
  static bool watch_devices(const RobotModel& model, CycleState& s, const CycleInputs& in) {
    const double t = in.t;
    if (s.cycles_ == 0) {
      for (auto& bus : s.last_ok_) std::fill(bus.begin(), bus.end(), t);
    }
    const double watchdog = model.safety.watchdog_timeout_s;
    bool fault = false;
    for (std::size_t b = 0; b < in.buses.size(); ++b) {
      const BusIo& io = in.buses[b];
      for (std::size_t d = 0; d < s.faulted_[b].size(); ++d) {
        if (s.faulted_[b][d]) continue;
        double& last_ok = s.last_ok_[b][d];
        if (!io.fresh && t - last_ok <= late_bus_grace(watchdog) + kTimeEps) continue;
        const DeviceHealth health = io.fresh ? io.health[d] : DeviceHealth::timeout;
        // A device's own error flag (Dynamixel's Alert, a drive's fault
        // state) is its error bits: with `error_bits: warn` or `ignore` it
        // answered, and is not faulted for it (one that switched itself off
        // is found by its following error). Warned here only when its bits
        // are not read (health off); read, the health check warns.
        const HealthLimits::Bits bits = model.buses[b].health_of(d).error_bits;
        if (health == DeviceHealth::hardware_error && bits != HealthLimits::Bits::fault) {
          last_ok = t;
          auto& warned = s.health_track_[b][d].warned;
          const auto bit =
              static_cast<std::uint8_t>(1u << static_cast<unsigned>(HealthCheck::error_bits));
          const bool read = d < io.readings.size() && io.readings[d].has_error_bits;
          if (bits == HealthLimits::Bits::warn && !read && !(warned & bit)) {
            warned |= bit;
            ++s.health_stats_[b][d].warnings;
            s.emit(CycleEvent{EventKind::health_warning, t, model.buses[b].joint[d], b, d,
                              DeviceHealth::ok, -1.0, HealthCheck::error_bits});
          }
          continue;
        }
        if (health == DeviceHealth::ok) {
          last_ok = t;
        } else if (health == DeviceHealth::hardware_error || t - last_ok > watchdog + kTimeEps) {
          s.faulted_[b][d] = 1;
          fault = true;
          s.emit(CycleEvent{EventKind::device_fault, t, model.buses[b].joint[d], b, d, health});
        }
      }
    }
    return fault;
  }

  // Health: each new reading against its bus's limits. A fault switches
  // the device off and ramps the others home; a warning is an event, once
  // per episode (until the value is back inside), and counted.
  static bool watch_health(const RobotModel& model, CycleState& s, const CycleInputs& in) {
    const double t = in.t;
    bool fault = false;
    for (std::size_t b = 0; b < in.buses.size(); ++b) {
      const BusIo& io = in.buses[b];
      if (!io.fresh || io.readings.empty()) continue;
      for (std::size_t d = 0; d < s.faulted_[b].size() && d < io.readings.size(); ++d) {
        const HealthLimits& lim = model.buses[b].health_of(d);
        const HealthReading& r = io.readings[d];
        CycleState::HealthTrack& track = s.health_track_[b][d];
        if (s.faulted_[b][d] || r.reads == track.reads) continue;
        track.reads = r.reads;
        HealthStats& st = s.health_stats_[b][d];
        ++st.readings;
        keep_min(st.min_temperature_c, r.temperature_c);
        keep_max(st.max_temperature_c, r.temperature_c);
        keep_max(st.peak_current_a, r.current_a);
        keep_min(st.min_voltage_v, r.voltage_v);
        keep_max(st.peak_torque_nm, r.torque_nm);

        const auto emit = [&](EventKind kind, HealthCheck check, double value) {
          s.emit(
              CycleEvent{kind, t, model.buses[b].joint[d], b, d, DeviceHealth::ok, value, check});
        };
        // The worst finding of this reading: a fault ends the device.
        HealthCheck faulty = HealthCheck::none;
        double faulty_value = 0.0;
        const auto judge = [&](HealthCheck check, bool is_fault, bool is_warning, double value) {
          const auto bit = static_cast<std::uint8_t>(1u << static_cast<unsigned>(check));
          if (is_fault && faulty == HealthCheck::none) {
            faulty = check;
            faulty_value = value;
          } else if (is_warning && !is_fault) {
            if (!(track.warned & bit)) {
              track.warned |= bit;
              ++st.warnings;
              emit(EventKind::health_warning, check, value);
            }
          } else if (!is_fault) {
            track.warned &= static_cast<std::uint8_t>(~bit);
          }
        };
        judge(HealthCheck::temperature, above(r.temperature_c, lim.temperature_fault_c),
              above(r.temperature_c, lim.temperature_warn_c), r.temperature_c);
        judge(HealthCheck::voltage, below(r.voltage_v, lim.voltage_fault_v),
              below(r.voltage_v, lim.voltage_warn_v), r.voltage_v);
        const bool bits = r.has_error_bits && r.error_bits != 0;
        judge(HealthCheck::error_bits, bits && lim.error_bits == HealthLimits::Bits::fault,
              bits && lim.error_bits == HealthLimits::Bits::warn,
              static_cast<double>(r.error_bits));
        // Stall: a high current while the joint stays away from its command.
        const int j = model.buses[b].joint[d];
        const double error =
            j >= 0 ? std::abs(s.last_sent_[b][d] - s.measured_[static_cast<std::size_t>(j)]) : 0.0;
        if (above(r.current_a, lim.stall_current_a) && error > lim.stall_error_rad) {
          if (track.stall_since < 0.0) track.stall_since = t;
          if (t - track.stall_since >= lim.stall_time_s - kTimeEps) {
            judge(HealthCheck::stall, true, false, r.current_a);
          }
        } else {
          track.stall_since = -1.0;
        }
        if (faulty != HealthCheck::none) {
          s.faulted_[b][d] = 1;
          s.switch_off_[b][d] = 1;
          fault = true;
          emit(EventKind::health_fault, faulty, faulty_value);
        }
      }
    }
    return fault;
  }

  // IMUs: a reading older than one report and one loop period is late (the last one is
  // kept, as a late bus keeps its measurement); older than the part's stale
  // timeout, the sensor is faulted and the figure ramps home, as after a
  // silent servo. The trunk's reading goes to the motion while it is fresh.
  static bool watch_imus(const RobotModel& model, CycleState& s, const CycleInputs& in) {
    const double t = in.t;
    if (s.cycles_ == 0) s.imu_start_ = t;
    s.imu_now_ = t;
    s.sensors_.imu = nullptr;
    bool fault = false;
    for (std::size_t i = 0; i < model.imus.size(); ++i) {
      const ImuIo* io = i < in.imus.size() ? &in.imus[i] : nullptr;
      const bool valid = io && io->valid;
      const double age = valid ? t - io->reading.time_s : t - s.imu_start_;
      if (age > 1.0 / model.imus[i].rate_hz + model.dt + kTimeEps) ++s.imu_late_[i];
      CycleState::ImuTrack& track = s.imu_track_[i];
      if (valid && io->reading.time_s > track.last + kTimeEps) {
        if (track.last >= 0.0) {
          const double periods = (io->reading.time_s - track.last) * model.imus[i].rate_hz;
          track.missing += static_cast<std::uint64_t>(std::max(0.0, std::round(periods) - 1.0));
        }
        track.last = io->reading.time_s;
        ++track.readings;
      }
      const bool stale = age > model.imus[i].stale_timeout_s + kTimeEps;
      if (stale && !s.imu_faulted_[i]) {
        s.imu_faulted_[i] = 1;
        fault = true;
        s.emit(CycleEvent{EventKind::sensor_stale, t, -1, i, 0, DeviceHealth::timeout, age});
      }
      if (i == 0 && valid && !s.imu_faulted_[i]) {
        s.trunk_ = io->reading;
        s.sensors_.imu = &s.trunk_;
      }
    }
    return fault;
  }

  // Tilt watch: the trunk's roll or pitch beyond the limit for the set time
  // ends the motion, by a hold or by torque off (SafetyConfig::on_tilt).
  // Returns whether torque went off (the run ended here).
  static bool watch_tilt(const RobotModel& model, CycleState& s, double t, CycleOutputs& out) {
    if (!s.sensors_.imu) {
      s.tilt_since_ = -1.0;
      return false;
    }
    const auto& q = s.sensors_.imu->quat;
    const double tilt = std::max(std::abs(roll_of(q)), std::abs(pitch_of(q)));
    s.max_tilt_ = std::max(s.max_tilt_, tilt);
    const SafetyConfig& safety = model.safety;
    if (safety.tilt_limit_rad <= 0.0 || s.end_.tilted || tilt <= safety.tilt_limit_rad) {
      s.tilt_since_ = -1.0;
      return false;
    }
    if (s.tilt_since_ < 0.0) s.tilt_since_ = t;
    if (t - s.tilt_since_ < safety.tilt_time_s - kTimeEps) return false;
    s.emit(CycleEvent{EventKind::tilted, t, -1, 0, 0, DeviceHealth::ok, tilt});
    s.end_.tilted = true;
    s.end_.fault = true;
    if (safety.on_tilt == SafetyConfig::OnTilt::hold) {
      s.begin_hold(model, t);
      return false;
    }
    if (s.phase_ == Phase::motion) {
      s.motion_time_ = t - s.motion_start_;
      s.emit(CycleEvent{EventKind::motion_ended, t});
    }
    s.end_.torque_cut = true;
    s.phase_ = Phase::done;
    out.torque_off_now = true;
    return true;
  }

  // Adds joint j's squared error to its window; returns the window's RMS
  // once the window is full, else -1.
  static double window_rms(CycleState& s, std::size_t j, double sq) {
    double& slot_sq = s.err_ring_[j * s.window_ + s.err_next_[j]];
    s.err_sum_[j] += sq - slot_sq;
    slot_sq = sq;
    s.err_next_[j] = (s.err_next_[j] + 1) % s.window_;
    if (s.err_next_[j] == 0) {  // once per window: the running sum starts afresh
      double sum = 0.0;
      for (std::size_t k = 0; k < s.window_; ++k) sum += s.err_ring_[j * s.window_ + k];
      s.err_sum_[j] = sum;
    }
    s.err_count_[j] = std::min(s.err_count_[j] + 1, s.window_);
    if (s.err_count_[j] < s.window_) return -1.0;
    return std::sqrt(std::max(0.0, s.err_sum_[j]) / static_cast<double>(s.window_));
  }

  // Following error: the last command a device was sent against what it
  // measured since. A joint whose RMS error over the last window is above
  // the limit is faulted like a silent device (held; the others ramp home).
  static bool watch_following_error(const RobotModel& model, CycleState& s, double t) {
    if (s.cycles_ == 0) return false;
    bool fault = false;
    for (std::size_t j = 0; j < s.slots_.size(); ++j) {
      const JointSlot slot = s.slots_[j];
      if (!s.active_[j] || s.joint_faulted(j)) continue;
      const double e = std::abs(s.last_sent_[slot.bus][slot.device] - s.measured_[j]);
      s.sq_error_[j] += e * e;
      s.max_error_[j] = std::max(s.max_error_[j], e);
      ++s.error_samples_[j];
      const double rms = window_rms(s, j, e * e);
      if (rms > model.following_error[j]) {
        s.faulted_[slot.bus][slot.device] = 1;
        fault = true;
        s.emit(CycleEvent{EventKind::following_error, t, static_cast<int>(j), slot.bus, slot.device,
                          DeviceHealth::ok, rms});
      }
    }
    return fault;
  }

  // Torque off at once: a second stop request, or a stop that ran over.
  // Returns whether the run ended here.
  static bool cut_torque(const RobotModel& model, CycleState& s, const CycleInputs& in,
                         CycleOutputs& out) {
    const double t = in.t;
    const bool overran = s.phase_ == Phase::stop_ramp &&
                         t - s.stop_start_ >= model.safety.stop_deadline_s - kTimeEps;
    if (!in.abort && !overran) return false;
    if (in.abort) {
      s.emit(CycleEvent{EventKind::aborted, t});
    } else {
      s.emit(CycleEvent{EventKind::stop_deadline, t, -1, 0, 0, DeviceHealth::ok,
                        model.safety.stop_deadline_s});
    }
    if (s.phase_ == Phase::motion) {
      s.motion_time_ = t - s.motion_start_;
      s.emit(CycleEvent{EventKind::motion_ended, t});
    }
    s.end_.torque_cut = true;
    s.end_.stopped = s.end_.stopped || in.abort;
    s.phase_ = Phase::done;
    out.torque_off_now = true;
    return true;
  }

  // Phase changes: a fault or a stop starts the stop ramp, so does the end of
  // the motion's duration; the end of the start ramp starts the motion.
  static void change_phase(const RobotModel& model, MotionSource& motion, CycleState& s,
                           const CycleInputs& in, bool fault) {
    const double t = in.t;
    if (s.phase_ == Phase::stop_ramp) {
      // A wind-down ends in the ramp home, at its end or at once on a fault.
      if (s.winding_down() && (fault || t >= s.wind_end_ - kTimeEps)) s.begin_stop(model, t);
      return;
    }
    if (fault) {
      s.begin_stop(model, t);
    } else if (in.stop) {
      s.end_.stopped = true;
      s.request_stop(model, motion, t);
    } else if (s.phase_ == Phase::motion && in.motion_duration_s > 0.0 &&
               t - s.motion_start_ >= in.motion_duration_s - kTimeEps) {
      s.request_stop(model, motion, t);
    } else if (s.phase_ == Phase::start_ramp &&
               t - s.phase_start_ >= s.ramp_.duration() - kTimeEps) {
      s.phase_ = Phase::motion;
      s.motion_start_ = t;
      s.emit(CycleEvent{EventKind::motion_started, t});
    }
  }

  // Manual mode: on, the joints hold where the filter has them and move
  // only by manual targets (clamped to the limits); off, the motion's
  // targets return, and the filter makes the way back smooth.
  static void take_manual(const RobotModel& model, CycleState& s, const CycleInputs& in) {
    if (s.phase_ != Phase::motion) {
      s.manual_ = false;
      return;
    }
    if (in.manual && !s.manual_) {
      const auto held = s.filter_.position();
      std::copy(held.begin(), held.end(), s.manual_pose_.begin());
    }
    s.manual_ = in.manual;
    if (!s.manual_) return;
    for (const ManualTarget& target : in.manual_targets) {
      if (target.joint < 0 || static_cast<std::size_t>(target.joint) >= model.joint_count() ||
          !std::isfinite(target.position)) {
        continue;
      }
      const auto j = static_cast<std::size_t>(target.joint);
      s.manual_pose_[j] =
          std::clamp(target.position, model.limits[j].min_position, model.limits[j].max_position);
    }
  }

  // A show's transport acts at the motion's time, before it is sampled.
  static void control_show(MotionSource& motion, CycleState& s, const CycleInputs& in,
                           CycleOutputs& out) {
    if (s.phase_ != Phase::motion || !in.show) return;
    motion.control(*in.show, in.t - s.motion_start_);
    out.show_controlled = true;
  }

  // The motion's targets plus the jog; a non-finite one is a motion fault:
  // the joint holds its last command and the run ramps home.
  static void sample_motion(const RobotModel& model, MotionSource& motion, CycleState& s,
                            double t) {
    std::copy(model.home.begin(), model.home.end(), s.targets_.begin());
    s.sensors_.positions = s.measured_;
    motion.sense(s.sensors_);
    motion.sample(t - s.motion_start_, s.targets_);
    bool bad = false;
    for (std::size_t j = 0; j < s.targets_.size(); ++j) {
      if (std::isfinite(s.targets_[j])) continue;
      s.emit(CycleEvent{EventKind::motion_fault, t, static_cast<int>(j), s.slots_[j].bus,
                        s.slots_[j].device, DeviceHealth::ok, s.targets_[j]});
      bad = true;
    }
    if (bad) {
      s.end_.fault = true;
      s.begin_stop(model, t);
    } else {
      for (std::size_t j = 0; j < s.targets_.size(); ++j) s.targets_[j] += s.jog_[j];
    }
  }

  // This cycle's targets: the manual pose, the motion, or the ramp; a faulted
  // joint is held where the filter has it.
  static void sample_targets(const RobotModel& model, MotionSource& motion, CycleState& s,
                             double t) {
    if (s.phase_ == Phase::motion && s.manual_) {
      std::copy(s.manual_pose_.begin(), s.manual_pose_.end(), s.targets_.begin());
    } else if (s.phase_ == Phase::motion || s.winding_down()) {
      sample_motion(model, motion, s, t);
    }
    if (s.phase_ != Phase::motion && !s.winding_down()) {
      s.ramp_.sample(t - s.phase_start_, s.targets_);
    }
    s.show_ = motion.show_position(s.phase_ == Phase::motion       ? t - s.motion_start_
                                   : s.phase_ == Phase::start_ramp ? 0.0
                                                                   : s.motion_time_);
    const auto position = s.filter_.position();
    for (std::size_t j = 0; j < s.targets_.size(); ++j) {
      if (s.joint_faulted(j)) s.targets_[j] = position[j];
    }
  }

  // Filter, and route the commands to the buses that take a write; a late
  // bus's joints hold the last command it was sent.
  static void filter_and_route(CycleState& s, const CycleInputs& in, CycleOutputs& out) {
    s.filter_.step(s.targets_, out.commands, s.active_);
    for (std::size_t b = 0; b < in.buses.size(); ++b) out.write[b] = in.buses[b].fresh ? 1 : 0;
    for (std::size_t j = 0; j < s.slots_.size(); ++j) {
      const JointSlot slot = s.slots_[j];
      if (!s.active_[j]) continue;
      out.bus_commands[slot.bus][slot.device] = out.commands[j];
      s.last_sent_[slot.bus][slot.device] = out.commands[j];
    }
  }

  // A joint that can move and was measured away from its stop pose this
  // cycle. A faulted joint is held, and one whose device did not answer
  // this cycle has no measurement: neither is waited for (the watchdogs
  // judge a silent device).
  static bool off_stop_pose(const RobotModel& model, const CycleState& s, std::size_t j, double t) {
    const JointSlot slot = s.slots_[j];
    if (s.joint_faulted(j) || !s.active_[j] || s.last_ok_[slot.bus][slot.device] != t) {
      return false;
    }
    const double tolerance = model.prismatic[j] ? kArrivedM : kArrivedRad;
    return !(std::abs(s.measured_[j] - s.ramp_to_[j]) <= tolerance);
  }

  // How long after its start a stop waits for the joints: the settling
  // time after the ramp, ending a cycle before the stop deadline would cut
  // torque without the warning.
  static double settle_limit(const RobotModel& model, const CycleState& s) {
    const double before = s.phase_start_ - s.stop_start_;  // a wind-down's
    return std::min(s.ramp_.duration() + kStopSettleTime,
                    std::max(s.ramp_.duration(), model.safety.stop_deadline_s - model.dt - before));
  }

  // The run is done once the stop ramp has ended, the command is at rest and
  // every joint that can move is measured at the stop pose, still: after a
  // stalled cycle the command may rest while the servos still travel, and
  // torque off there would drop them short of home. A joint that has not
  // arrived a bounded time after the ramp is named, and torque goes off.
  static void settle(const RobotModel& model, CycleState& s, double t) {
    if (s.phase_ != Phase::stop_ramp || s.winding_down() ||
        t - s.phase_start_ < s.ramp_.duration()) {
      return;
    }
    double fastest = 0.0;
    for (double v : s.filter_.velocity()) fastest = std::max(fastest, std::abs(v));
    bool arrived = fastest < kSettledVelocity;
    for (std::size_t j = 0; arrived && j < s.slots_.size(); ++j) {
      arrived = !off_stop_pose(model, s, j, t);
    }
    if (!arrived) {
      s.arrived_since_ = -1.0;
    } else if (s.arrived_since_ < 0.0) {
      s.arrived_since_ = t;
    }
    if (arrived && t - s.arrived_since_ >= kArrivedHold - kTimeEps) {
      s.phase_ = Phase::done;
    } else if (t - s.phase_start_ >= settle_limit(model, s) - kTimeEps) {
      for (std::size_t j = 0; j < s.slots_.size(); ++j) {
        if (!off_stop_pose(model, s, j, t)) continue;
        s.emit(CycleEvent{EventKind::stop_unreached, t, static_cast<int>(j), s.slots_[j].bus,
                          s.slots_[j].device, DeviceHealth::ok, s.measured_[j] - s.ramp_to_[j]});
      }
      s.phase_ = Phase::done;
    }
  }
};

const CycleOutputs& step(const RobotModel& model, MotionSource& motion, CycleState& s,
                         const CycleInputs& in) {
  using S = CycleStages;
  CycleOutputs& out = s.out_;
  out.events.clear();
  out.show_controlled = false;
  std::fill(out.write.begin(), out.write.end(), 0);
  if (s.phase_ == Phase::done) return out;

  S::take_controls(model, motion, s, in);
  S::take_measurements(s, in);
  // Health first: a device that reports why it fails is named for it.
  const bool health_fault = S::watch_health(model, s, in);
  const bool device_fault = S::watch_devices(model, s, in) || health_fault;
  const bool following_fault = S::watch_following_error(model, s, in.t);
  const bool sensor_fault = S::watch_imus(model, s, in);
  const bool fault = device_fault || following_fault || sensor_fault;
  if (fault) s.end_.fault = true;
  if (S::watch_tilt(model, s, in.t, out)) {
    ++s.cycles_;
    return out;
  }
  if (S::cut_torque(model, s, in, out)) {
    ++s.cycles_;
    return out;
  }
  S::change_phase(model, motion, s, in, fault);
  S::take_manual(model, s, in);
  S::control_show(motion, s, in, out);
  S::sample_targets(model, motion, s, in.t);
  S::filter_and_route(s, in, out);
  S::settle(model, s, in.t);
  ++s.cycles_;
  return out;
}

NextDeadline next_deadline(Nanos deadline, Nanos now, Nanos period) {
  NextDeadline next{deadline + period, false, 0};
  const Nanos late = now - next.deadline;
  if (late > 0) {
    next.overrun = true;
    if (late >= period) {
      next.skipped = static_cast<std::uint64_t>(late / period);
      next.deadline += static_cast<Nanos>(next.skipped) * period;
    }
  }
  return next;
}

}  // namespace animrt
