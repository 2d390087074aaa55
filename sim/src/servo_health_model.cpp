#include "animrt/sim/servo_health_model.hpp"

#include <algorithm>
#include <cmath>

namespace animrt::sim {

ServoHealthModel::ServoHealthModel(const SimHealthSettings& settings, int device_id, Nanos start)
    : settings_(settings),
      start_(start),
      time_(start),
      current_a_(settings.idle_current_a),
      temperature_c_(settings.ambient_c),
      supply_v_(settings.supply_v) {
  settings_.inject.clear();
  for (const SimHealthInjection& i : settings.inject) {
    if (i.device_id == device_id) pending_.push_back(i);
  }
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const auto& a, const auto& b) { return a.at_s < b.at_s; });
}

void ServoHealthModel::apply(const SimHealthInjection& injection) {
  using Kind = SimHealthInjection::Kind;
  switch (injection.kind) {
    case Kind::temperature:
      temperature_c_ = injection.value;
      break;
    case Kind::blocked:
      blocked_ = injection.value != 0.0;
      break;
    case Kind::supply:
      supply_v_ = injection.value;
      break;
    case Kind::hardware_error:
      injected_bits_ = static_cast<std::uint8_t>(injection.value);
      break;
  }
}

void ServoHealthModel::advance(Nanos now, double speed_rad_s, bool torque_on) {
  if (now < time_) return;
  const double dt = to_seconds(now - time_);
  time_ = now;
  const bool stalled = blocked_ && torque_on;
  current_a_ = stalled
                   ? settings_.stall_current_a
                   : settings_.idle_current_a + settings_.current_per_rad_s *
                                                    std::abs(speed_rad_s) * (torque_on ? 1.0 : 0.0);
  stalled_s_ = stalled ? stalled_s_ + dt : 0.0;
  // First order towards the temperature this current holds, exact for a
  // current constant over the step.
  const double target = settings_.ambient_c + settings_.heat_c_per_a2 * current_a_ * current_a_;
  if (settings_.thermal_tau_s > 0.0) {
    temperature_c_ = target + (temperature_c_ - target) * std::exp(-dt / settings_.thermal_tau_s);
  }
  while (next_ < pending_.size() &&
         start_ + static_cast<Nanos>(pending_[next_].at_s * 1e9) <= now) {
    apply(pending_[next_++]);
  }
}

std::uint8_t ServoHealthModel::error_bits(double temperature_limit_c, double min_voltage_v,
                                          double max_voltage_v) const {
  std::uint8_t bits = injected_bits_;
  const double v = voltage_v();
  if (v < min_voltage_v || v > max_voltage_v) bits |= kInputVoltageBit;
  if (temperature_c_ > temperature_limit_c) bits |= kOverheatingBit;
  if (stalled_s_ >= settings_.overload_s) bits |= kOverloadBit;
  return bits;
}

}  // namespace animrt::sim
