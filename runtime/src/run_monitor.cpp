#include "animrt/runtime/run_monitor.hpp"

#include <cmath>
#include <thread>

namespace animrt {
namespace {

// The block's layout: a header, then words per joint, bus and device.
enum Header : std::size_t {
  kT,
  kPhase,
  kMotionTime,
  kCycles,
  kOverruns,
  kSkipped,
  kManual,
  kSteered,
  kSpeed,
  kTurn,
  kShow,
  kShowPlaying,
  kShowPosition,
  kShowDuration,
  kHeaderWords
};
constexpr std::size_t kJointWords = 4;    // cmd, meas, vel, manual pose
constexpr std::size_t kDeviceWords = 14;  // id, health, faulted, 6 counters, 5 health values
// valid, quaternion (4), rates (3), time, late cycles, missing reports, faulted
constexpr std::size_t kImuWords = 12;
constexpr std::size_t kTimingCapacity = 1 << 13;  // cycles (40 s at 200 Hz unread)
constexpr std::size_t kEventCapacity = 256;
constexpr std::size_t kEventWidth = 8;

RunPhaseView view_of(Phase phase) {
  switch (phase) {
    case Phase::start_ramp:
      return RunPhaseView::start_ramp;
    case Phase::motion:
      return RunPhaseView::motion;
    case Phase::stop_ramp:
      return RunPhaseView::stop_ramp;
    case Phase::done:
      return RunPhaseView::ended;
  }
  return RunPhaseView::ended;
}

double as_double(std::uint64_t word) { return std::bit_cast<double>(word); }

}  // namespace

const char* to_string(RunPhaseView phase) {
  switch (phase) {
    case RunPhaseView::configure:
      return "configure";
    case RunPhaseView::start_ramp:
      return "start_ramp";
    case RunPhaseView::motion:
      return "motion";
    case RunPhaseView::stop_ramp:
      return "stop_ramp";
    case RunPhaseView::ended:
      return "ended";
  }
  return "ended";
}

RunMonitor::RunMonitor(const RobotModel& model)
    : model_(model),
      joints_(model.joint_count()),
      buses_(model.buses.size()),
      imus_(model.imus.size()),
      timing_(4, kTimingCapacity),
      events_(kEventWidth, kEventCapacity) {
  for (const BusModel& bus : model.buses) {
    device_offset_.push_back(devices_);
    devices_ += bus.joint.size();
  }
  imu_words_ = kHeaderWords + kJointWords * joints_ + buses_ + kDeviceWords * devices_;
  word_count_ = imu_words_ + kImuWords * imus_;
  words_ = std::make_unique<std::atomic<std::uint64_t>[]>(word_count_);
  for (std::size_t i = 0; i < word_count_; ++i) words_[i].store(0, std::memory_order_relaxed);
  store_u(kPhase, static_cast<std::uint64_t>(RunPhaseView::configure));
  // Device ids are known before the run.
  for (std::size_t b = 0; b < buses_; ++b) {
    for (std::size_t d = 0; d < model.buses[b].device_id.size(); ++d) {
      const std::size_t w =
          kHeaderWords + kJointWords * joints_ + buses_ + kDeviceWords * (device_offset_[b] + d);
      store_u(w, static_cast<std::uint64_t>(model.buses[b].device_id[d]));
    }
  }
}

void RunMonitor::begin_write() {
  const std::uint64_t s = sequence_.load(std::memory_order_relaxed);
  sequence_.store(s + 1, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
}

void RunMonitor::end_write() {
  sequence_.store(sequence_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
}

void RunMonitor::publish(double t, const CycleState& state, std::span<const double> commands,
                         std::span<const std::span<const DeviceStatus>> devices,
                         std::uint64_t overruns, std::uint64_t skipped, const MotionCommand* steer,
                         std::span<const ImuIo> imus) {
  if (steer) {
    steered_ = true;
    steer_ = *steer;
  }
  begin_write();
  store(kT, t);
  store_u(kPhase, static_cast<std::uint64_t>(view_of(state.phase())));
  const bool in_motion = state.phase() == Phase::motion;
  store(kMotionTime, in_motion ? t - state.motion_start() : state.motion_time());
  store_u(kCycles, state.cycles());
  store_u(kOverruns, overruns);
  store_u(kSkipped, skipped);
  store_u(kManual, state.manual() ? 1 : 0);
  store_u(kSteered, steered_ ? 1 : 0);
  store(kSpeed, steer_.speed_m_s);
  store(kTurn, steer_.turn_rad_s);
  const ShowPosition& show = state.show();
  store_u(kShow, show.show ? 1 : 0);
  store_u(kShowPlaying, show.playing ? 1 : 0);
  store(kShowPosition, show.position_s);
  store(kShowDuration, show.duration_s);
  const auto measured = state.measured();
  const auto velocity = state.command_velocity();
  const auto manual = state.manual_pose();
  for (std::size_t j = 0; j < joints_; ++j) {
    const std::size_t w = kHeaderWords + kJointWords * j;
    store(w, commands[j]);
    store(w + 1, measured[j]);
    store(w + 2, velocity[j]);
    store(w + 3, manual[j]);
  }
  const std::size_t bus_words = kHeaderWords + kJointWords * joints_;
  const auto late = state.late_cycles();
  for (std::size_t b = 0; b < buses_; ++b) store_u(bus_words + b, late[b]);
  const std::size_t device_words = bus_words + buses_;
  const auto& faulted = state.faulted();
  for (std::size_t b = 0; b < buses_ && b < devices.size(); ++b) {
    for (std::size_t d = 0; d < faulted[b].size(); ++d) {
      const std::size_t w = device_words + kDeviceWords * (device_offset_[b] + d);
      store_u(w + 2, faulted[b][d]);
      if (devices[b].size() <= d) continue;
      const DeviceStatus& s = devices[b][d];
      store_u(w + 1, static_cast<std::uint64_t>(s.health));
      store_u(w + 3, s.transactions);
      store_u(w + 4, s.timeouts);
      store_u(w + 5, s.crc_errors);
      store_u(w + 6, s.protocol_errors);
      store_u(w + 7, s.hardware_errors);
      store_u(w + 8, s.exceptions);
      store(w + 9, s.reading.temperature_c);
      store(w + 10, s.reading.current_a);
      store(w + 11, s.reading.voltage_v);
      store(w + 13, s.reading.torque_nm);
      store(w + 12, s.reading.has_error_bits ? static_cast<double>(s.reading.error_bits)
                                             : HealthReading::kNone);
    }
  }
  publish_imus(state, imus);
  end_write();
}

void RunMonitor::publish_imus(const CycleState& state, std::span<const ImuIo> imus) {
  const auto late = state.imu_late_cycles();
  const auto faulted = state.imu_faulted();
  for (std::size_t i = 0; i < imus_ && i < imus.size(); ++i) {
    const std::size_t w = imu_words_ + kImuWords * i;
    const ImuReading& r = imus[i].reading;
    store_u(w, imus[i].valid ? 1 : 0);
    for (std::size_t k = 0; k < 4; ++k) store(w + 1 + k, r.quat[k]);
    for (std::size_t k = 0; k < 3; ++k) store(w + 5 + k, r.rate_rad_s[k]);
    store(w + 8, r.time_s);
    store_u(w + 9, i < late.size() ? late[i] : 0);
    store_u(w + 10, state.imu_missing(i, model_.imus[i].rate_hz));
    store_u(w + 11, i < faulted.size() ? faulted[i] : 0);
  }
}

void RunMonitor::publish_ended() {
  begin_write();
  store_u(kPhase, static_cast<std::uint64_t>(RunPhaseView::ended));
  store_u(kManual, 0);
  end_write();
}

void RunMonitor::publish_sample(double t, RunPhaseView phase, std::uint64_t cycle,
                                std::span<const double> cmd, std::span<const double> meas,
                                std::span<const double> vel) {
  begin_write();
  store(kT, t);
  store_u(kPhase, static_cast<std::uint64_t>(phase));
  store(kMotionTime, t);
  store_u(kCycles, cycle);
  for (std::size_t j = 0; j < joints_ && j < cmd.size(); ++j) {
    const std::size_t w = kHeaderWords + kJointWords * j;
    store(w, cmd[j]);
    store(w + 1, meas[j]);
    store(w + 2, vel[j]);
  }
  end_write();
}

void RunMonitor::push_timing(const CycleTiming& timing) {
  const double record[4] = {timing.t_s, timing.period_s, timing.jitter_s, timing.busy_s};
  timing_.push(record);
}

void RunMonitor::push_event(const CycleEvent& e) {
  const double record[kEventWidth] = {static_cast<double>(e.kind),
                                      e.t,
                                      static_cast<double>(e.joint),
                                      static_cast<double>(e.bus),
                                      static_cast<double>(e.device),
                                      static_cast<double>(e.health),
                                      e.value,
                                      static_cast<double>(e.check)};
  events_.push(record);
}

void RunMonitor::read(RunView& view) const {
  scratch_.resize(word_count_);
  for (;;) {
    const std::uint64_t s0 = sequence_.load(std::memory_order_acquire);
    if (s0 & 1) {
      std::this_thread::yield();
      continue;
    }
    for (std::size_t i = 0; i < word_count_; ++i) {
      scratch_[i] = words_[i].load(std::memory_order_relaxed);
    }
    std::atomic_thread_fence(std::memory_order_acquire);
    if (sequence_.load(std::memory_order_relaxed) == s0) {
      view.published = s0 != 0;
      break;
    }
  }
  const auto& w = scratch_;
  view.t_s = as_double(w[kT]);
  view.phase = static_cast<RunPhaseView>(w[kPhase]);
  view.motion_time_s = as_double(w[kMotionTime]);
  view.cycles = w[kCycles];
  view.overruns = w[kOverruns];
  view.skipped = w[kSkipped];
  view.manual = w[kManual] != 0;
  view.steered = w[kSteered] != 0;
  view.steer = MotionCommand{as_double(w[kSpeed]), as_double(w[kTurn])};
  view.show = ShowPosition{w[kShow] != 0, w[kShowPlaying] != 0, as_double(w[kShowPosition]),
                           as_double(w[kShowDuration])};
  view.cmd.resize(joints_);
  view.meas.resize(joints_);
  view.vel.resize(joints_);
  view.manual_pose.resize(joints_);
  for (std::size_t j = 0; j < joints_; ++j) {
    const std::size_t i = kHeaderWords + kJointWords * j;
    view.cmd[j] = as_double(w[i]);
    view.meas[j] = as_double(w[i + 1]);
    view.vel[j] = as_double(w[i + 2]);
    view.manual_pose[j] = as_double(w[i + 3]);
  }
  const std::size_t bus_words = kHeaderWords + kJointWords * joints_;
  view.late.assign(w.begin() + static_cast<long>(bus_words),
                   w.begin() + static_cast<long>(bus_words + buses_));
  view.devices.resize(devices_);
  for (std::size_t k = 0; k < devices_; ++k) {
    const std::size_t i = bus_words + buses_ + kDeviceWords * k;
    DeviceStatus& s = view.devices[k];
    s.device_id = static_cast<int>(w[i]);
    s.health = static_cast<DeviceHealth>(w[i + 1]);
    s.faulted = w[i + 2] != 0;
    s.transactions = w[i + 3];
    s.timeouts = w[i + 4];
    s.crc_errors = w[i + 5];
    s.protocol_errors = w[i + 6];
    s.hardware_errors = w[i + 7];
    s.exceptions = w[i + 8];
    s.reading.temperature_c = as_double(w[i + 9]);
    s.reading.current_a = as_double(w[i + 10]);
    s.reading.voltage_v = as_double(w[i + 11]);
    s.reading.torque_nm = as_double(w[i + 13]);
    const double bits = as_double(w[i + 12]);
    s.reading.has_error_bits = !std::isnan(bits);
    s.reading.error_bits = s.reading.has_error_bits ? static_cast<std::uint32_t>(bits) : 0;
  }
  view.imus.resize(imus_);
  for (std::size_t i = 0; i < imus_; ++i) {
    const std::size_t k = imu_words_ + kImuWords * i;
    ImuView& imu = view.imus[i];
    imu.valid = w[k] != 0;
    for (std::size_t c = 0; c < 4; ++c) imu.reading.quat[c] = as_double(w[k + 1 + c]);
    for (std::size_t c = 0; c < 3; ++c) imu.reading.rate_rad_s[c] = as_double(w[k + 5 + c]);
    imu.reading.time_s = as_double(w[k + 8]);
    imu.late_cycles = w[k + 9];
    imu.missing_reports = w[k + 10];
    imu.faulted = w[k + 11] != 0;
  }
}

bool RunMonitor::pop_timing(CycleTiming& timing) {
  double record[4];
  if (!timing_.pop(record)) return false;
  timing = CycleTiming{record[0], record[1], record[2], record[3]};
  return true;
}

bool RunMonitor::pop_event(CycleEvent& e) {
  double r[kEventWidth];
  if (!events_.pop(r)) return false;
  e = CycleEvent{static_cast<EventKind>(static_cast<int>(r[0])),
                 r[1],
                 static_cast<int>(r[2]),
                 static_cast<std::size_t>(r[3]),
                 static_cast<std::size_t>(r[4]),
                 static_cast<DeviceHealth>(static_cast<int>(r[5])),
                 r[6],
                 static_cast<HealthCheck>(static_cast<int>(r[7]))};
  return true;
}

}  // namespace animrt
