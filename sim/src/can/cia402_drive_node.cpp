#include "animrt/sim/can/cia402_drive_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "animrt/core/joint.hpp"
#include "animrt/sim/dynamixel_servo.hpp"  // initial_offset_rad

namespace animrt::sim {
namespace {

using canopen::NmtState;
using cia402::State;
namespace ac = canopen::abort_code;
namespace obj = cia402::obj;

constexpr std::int32_t kTargetWindow = 20;  // counts: "target reached"
constexpr std::uint16_t kEmcyRpdoLength = 0x8210;
constexpr std::uint16_t kEmcyHeartbeat = 0x8130;    // life guard or heartbeat error
constexpr std::uint8_t kCommunicationError = 0x10;  // error register bit 4
// The drive's own overtemperature trip (sim.health.trip_c), as the injected
// overheating condition; a fault reset clears it this far below the trip.
constexpr std::uint8_t kOverheating = 0x04;
constexpr double kTripHysteresisC = 5.0;

// Error register (1001h) bits for an EMCY code's class.
std::uint8_t error_register_for(std::uint16_t code) {
  if (code == 0) return 0;
  std::uint8_t reg = 0x01;  // generic
  switch (code >> 12) {
    case 0x2:
      reg |= 0x02;
      break;  // current
    case 0x3:
      reg |= 0x04;
      break;  // voltage
    case 0x4:
      reg |= 0x08;
      break;  // temperature
    case 0x8:
      reg |= (code & 0xFF00) == 0x8100 || (code & 0xFF00) == 0x8200 ? 0x10 : 0x20;
      break;
    default:
      break;
  }
  return reg;
}

}  // namespace

std::uint16_t Cia402DriveNode::emcy_code_for(std::uint8_t bits) {
  // The Dynamixel-flavoured injection bits of SimulatedBus, as a drive reports them.
  if (bits & 0x20) return 0x2310;  // overload: continuous over-current
  if (bits & 0x04) return 0x4310;  // overheating: drive temperature
  if (bits & 0x01) return 0x3210;  // input voltage: DC link over-voltage
  if (bits & 0x10) return 0x2320;  // electrical shock: short circuit
  if (bits & 0x08) return 0x7305;  // motor encoder: incremental sensor 1 fault
  return 0x1000;                   // generic
}

Cia402DriveNode::Cia402DriveNode(const ActuatorBinding& binding, const SimBusSettings& settings,
                                 Nanos now)
    : binding_(binding),
      settings_(settings),
      node_(static_cast<std::uint8_t>(binding.device_id)),
      motor_(static_cast<double>(binding.to_ticks(initial_offset_rad(binding.device_id))),
             settings.time_constant_s, settings.max_speed_rad_s * binding.ticks_per_rad, now),
      health_(settings.health, binding.device_id, now) {
  reset_application(now);
}

std::vector<canid_t> Cia402DriveNode::listens_to() const {
  std::vector<canid_t> ids{canopen::kNmtId, canopen::kSyncId, canopen::kRpdo1Base + node_,
                           canopen::kRsdoBase + node_};
  // Heartbeats of every other node: the consumer's producer is set at run time.
  for (canid_t n = 1; n <= static_cast<canid_t>(canopen::kMaxNodeId); ++n) {
    if (n != node_) ids.push_back(canopen::kHeartbeatBase + n);
  }
  return ids;
}

void Cia402DriveNode::reset_application(Nanos now) {
  od_ = {
      {obj::device_type, 0, 4, Access::ro, false, false, kDriveDeviceType},
      {obj::error_register, 0, 1, Access::ro, false, true, 0},
      {obj::heartbeat_consumer, 0, 1, Access::ro, false, false, 1},
      {obj::heartbeat_consumer, 1, 4, Access::rw, false, false, 0},
      {obj::heartbeat_time, 0, 2, Access::rw, false, false, 0},
      {obj::identity, 0, 1, Access::ro, false, false, 4},
      {obj::identity, 1, 4, Access::ro, false, false, kDriveVendorId},
      {obj::identity, 2, 4, Access::ro, false, false, kDriveProductCode},
      {obj::identity, 3, 4, Access::ro, false, false, 0x00010000},
      {obj::identity, 4, 4, Access::ro, false, false, 1000u + node_},
      {obj::abort_connection_option, 0, 2, Access::rw, false, false,
       static_cast<std::uint16_t>(AbortConnection::fault)},
      {obj::error_code, 0, 2, Access::ro, false, true, 0},
      {obj::controlword, 0, 2, Access::rw, true, false, 0},
      {obj::statusword, 0, 2, Access::ro, false, true, 0},
      {obj::quick_stop_option, 0, 2, Access::rw, false, false, 6},
      {obj::modes_of_operation, 0, 1, Access::rw, true, false,
       static_cast<std::uint8_t>(cia402::kModeCsp)},
      {obj::modes_of_operation_display, 0, 1, Access::ro, false, true,
       static_cast<std::uint8_t>(cia402::kModeCsp)},
      {obj::position_actual, 0, 4, Access::ro, false, true, 0},
      {obj::velocity_actual, 0, 4, Access::ro, false, true, 0},
      {obj::target_position, 0, 4, Access::rw, true, false, 0},
      {obj::home_offset, 0, 4, Access::rw, false, false, 0},
      {obj::homing_method, 0, 1, Access::rw, false, false,
       static_cast<std::uint8_t>(cia402::kHomingHere)},
      {obj::homing_speeds, 0, 1, Access::ro, false, false, 2},
      {obj::homing_speeds, 1, 4, Access::rw, false, false, 0},
      {obj::homing_speeds, 2, 4, Access::rw, false, false, 0},
      {obj::homing_accel, 0, 4, Access::rw, false, false, 0},
      {obj::motor_rated_current, 0, 4, Access::rw, false, false, kRatedCurrentMa},
      {obj::current_actual, 0, 2, Access::ro, false, true, 0},
      {obj::dc_link_voltage, 0, 4, Access::ro, false, true, 0},
  };
  // The manufacturer object the drive reports its temperature in, if the
  // device's config names one (CiA 402 defines none).
  const auto joint = options_of<Cia402JointOptions>(binding_.options);
  if (joint.has_temperature) {
    const Cia402Temperature& t = joint.temperature;
    od_.push_back(
        {t.index, t.subindex, static_cast<std::uint8_t>(t.bits / 8), Access::ro, false, true, 0});
  }
  reset_communication();
  state_ = State::switch_on_disabled;  // transitions 0 and 1 are immediate here
  last_controlword_ = 0;
  motor_.hold(now);
  find(obj::target_position, 0)->value = static_cast<std::uint32_t>(counts(now));
  homing_attained_ = false;
  homing_error_ = false;
  search_.reset();
}

std::int32_t Cia402DriveNode::counts(Nanos now) const {
  return static_cast<std::int32_t>(std::lround(motor_.position(now))) + position_offset_;
}

HomingSearch::Switches Cia402DriveNode::switches() const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  HomingSearch::Switches out{kInf, -kInf, -kInf, kInf};  // none fitted: never active
  const double per_deg = binding_.ticks_per_rad * deg_to_rad(1.0);
  for (const SimDriveSwitches& s : settings_.switches) {
    if (s.device_id != binding_.device_id) continue;
    if (s.has_home) {
      out.home_from = s.home_from_deg * per_deg;
      out.home_to = s.home_to_deg * per_deg;
    }
    out.negative_limit = s.negative_limit_deg * per_deg;
    out.positive_limit = s.positive_limit_deg * per_deg;
  }
  return out;
}

void Cia402DriveNode::start_homing(Nanos now) {
  homing_attained_ = false;
  homing_error_ = false;
  const auto method = static_cast<std::int8_t>(find(obj::homing_method, 0)->value);
  if (HomingSearch::is_switch_method(method)) {
    search_.emplace(method, switches(), motor_.position(now), find(obj::homing_speeds, 1)->value,
                    find(obj::homing_speeds, 2)->value, now);
    return;
  }
  // 35/37: the present position is the home; it reads the home offset.
  const auto offset = static_cast<std::int32_t>(find(obj::home_offset, 0)->value);
  position_offset_ = offset - static_cast<std::int32_t>(std::lround(motor_.position(now)));
  find(obj::target_position, 0)->value = static_cast<std::uint32_t>(counts(now));
  homing_attained_ = true;
}

void Cia402DriveNode::advance_search(Nanos now) {
  if (!search_) return;
  search_->advance(now);
  motor_.hold(now);
  motor_.offset(search_->position() - motor_.position(now));
  if (search_->phase() == HomingSearch::Phase::searching) return;
  if (search_->phase() == HomingSearch::Phase::attained) {
    const auto offset = static_cast<std::int32_t>(find(obj::home_offset, 0)->value);
    position_offset_ = offset - static_cast<std::int32_t>(std::lround(search_->position()));
    find(obj::target_position, 0)->value = static_cast<std::uint32_t>(counts(now));
    homing_attained_ = true;
  } else {
    homing_error_ = true;
  }
  search_.reset();
}

void Cia402DriveNode::stop_search(Nanos now) {
  advance_search(now);
  search_.reset();
}

void Cia402DriveNode::reset_communication() {
  // Drop the communication area (1000h-1FFFh) and rebuild it with defaults.
  std::erase_if(od_, [](const Entry& e) { return e.index >= 0x1400 && e.index < 0x2000; });
  // Default mapping of a CiA 402 drive: RPDO1 controlword, TPDO1 statusword.
  const std::uint32_t node = node_;
  od_.push_back({0x1400, 0, 1, Access::ro, false, false, 2});
  od_.push_back({0x1400, 1, 4, Access::rw, false, false, canopen::kRpdo1Base + node});
  od_.push_back({0x1400, 2, 1, Access::rw, false, false, 255});
  od_.push_back({0x1600, 0, 1, Access::rw, false, false, 1});
  for (std::uint8_t s = 1; s <= 8; ++s) {
    od_.push_back({0x1600, s, 4, Access::rw, false, false,
                   s == 1 ? canopen::mapping(obj::controlword, 0, 16) : 0});
  }
  od_.push_back({0x1800, 0, 1, Access::ro, false, false, 2});
  od_.push_back({0x1800, 1, 4, Access::rw, false, false, canopen::kTpdo1Base + node});
  od_.push_back({0x1800, 2, 1, Access::rw, false, false, 255});
  od_.push_back({0x1A00, 0, 1, Access::rw, false, false, 1});
  for (std::uint8_t s = 1; s <= 8; ++s) {
    od_.push_back({0x1A00, s, 4, Access::rw, false, false,
                   s == 1 ? canopen::mapping(obj::statusword, 0, 16) : 0});
  }
  od_.push_back({0x1801, 0, 1, Access::ro, false, false, 2});
  od_.push_back(
      {0x1801, 1, 4, Access::rw, false, false, cia402::kPdoInvalid | (canopen::kTpdo2Base + node)});
  od_.push_back({0x1801, 2, 1, Access::rw, false, false, 255});
  od_.push_back({0x1A01, 0, 1, Access::rw, false, false, 0});
  for (std::uint8_t s = 1; s <= 8; ++s) od_.push_back({0x1A01, s, 4, Access::rw, false, false, 0});
  if (Entry* e = find(obj::heartbeat_time, 0)) e->value = 0;
  if (Entry* e = find(obj::heartbeat_consumer, 1)) e->value = 0;
  consumer_armed_ = false;
  rpdo_pending_ = false;
  sync_count_ = 0;
  boot_pending_ = true;
}

void Cia402DriveNode::boot(FrameList& out) {
  boot_pending_ = false;
  nmt_ = NmtState::pre_operational;
  out.push_back(canopen::heartbeat(node_, NmtState::boot_up));
}

Cia402DriveNode::Entry* Cia402DriveNode::find(std::uint16_t index, std::uint8_t sub) {
  for (Entry& e : od_) {
    if (e.index == index && e.sub == sub) return &e;
  }
  return nullptr;
}

bool Cia402DriveNode::index_exists(std::uint16_t index) const {
  return std::any_of(od_.begin(), od_.end(), [&](const Entry& e) { return e.index == index; });
}

std::uint16_t Cia402DriveNode::statusword(Nanos now) const {
  std::uint16_t sw = cia402::state_bits(state_) | 0x0200;  // remote
  if (state_ == State::ready_to_switch_on || state_ == State::switched_on ||
      state_ == State::operation_enabled || state_ == State::quick_stop_active) {
    sw |= 0x0010;  // voltage enabled
  }
  if (homing_mode()) {
    // Searching: bits 10, 12, 13 clear. Not started (or interrupted):
    // target reached alone; done: attained too; failed: homing error.
    if (search_) return sw;
    sw |= cia402::kSwTargetReached;
    if (homing_attained_) sw |= cia402::kSwHomingAttained;
    if (homing_error_) sw |= cia402::kSwHomingError;
    return sw;
  }
  if (state_ == State::operation_enabled) {
    sw |= 0x1000;  // CSP: following the target
    const auto target = static_cast<std::int32_t>(
        const_cast<Cia402DriveNode*>(this)->find(obj::target_position, 0)->value);
    if (std::abs(static_cast<double>(target) - counts(now)) <= kTargetWindow) sw |= 0x0400;
  } else {
    sw |= 0x0400;
  }
  return sw;
}

std::uint32_t Cia402DriveNode::read_value(const Entry& e, Nanos now) const {
  switch (e.index) {
    case obj::statusword:
      return statusword(now);
    case obj::position_actual:
      return static_cast<std::uint32_t>(counts(now));
    case obj::velocity_actual:
      return static_cast<std::uint32_t>(
          static_cast<std::int32_t>(std::lround(motor_.velocity(now))));
    case obj::current_actual: {
      const double rated_a =
          const_cast<Cia402DriveNode*>(this)->find(obj::motor_rated_current, 0)->value / 1000.0;
      const double per_mille =
          rated_a > 0.0 ? std::clamp(1000.0 * health_.current_a() / rated_a, -32768.0, 32767.0)
                        : 0.0;
      return static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(per_mille)));
    }
    case obj::dc_link_voltage:
      return static_cast<std::uint32_t>(std::lround(std::max(0.0, health_.voltage_v()) * 1000.0));
    default:
      return e.index >= 0x2000 && e.index < 0x6000 ? manufacturer_value(e) : e.value;
  }
}

std::uint32_t Cia402DriveNode::manufacturer_value(const Entry& e) const {
  const auto joint = options_of<Cia402JointOptions>(binding_.options);
  const Cia402Temperature& t = joint.temperature;
  if (!joint.has_temperature || e.index != t.index || e.sub != t.subindex) return e.value;
  const double top = t.bits == 8 ? 255.0 : 65535.0;
  const double lo = t.is_signed ? -(top + 1.0) / 2.0 : 0.0;
  const double hi = t.is_signed ? (top - 1.0) / 2.0 : top;
  const double raw = std::clamp(std::round(health_.temperature_c() / t.scale), lo, hi);
  return static_cast<std::uint32_t>(static_cast<std::int32_t>(raw)) &
         static_cast<std::uint32_t>(top);
}

double Cia402DriveNode::joint_position(Nanos now) const { return binding_.to_rad(counts(now)); }

std::uint32_t Cia402DriveNode::cob_id(const Pdo& pdo) const {
  return const_cast<Cia402DriveNode*>(this)->find(pdo.comm, 1)->value;
}

std::uint8_t Cia402DriveNode::transmission_type(const Pdo& pdo) const {
  return static_cast<std::uint8_t>(const_cast<Cia402DriveNode*>(this)->find(pdo.comm, 2)->value);
}

std::uint32_t Cia402DriveNode::mapped_bits(const Pdo& pdo, std::uint8_t count) const {
  std::uint32_t bits = 0;
  auto* self = const_cast<Cia402DriveNode*>(this);
  for (std::uint8_t s = 1; s <= count && s <= 8; ++s) bits += self->find(pdo.map, s)->value & 0xFF;
  return bits;
}

std::uint32_t Cia402DriveNode::check_mapping(const Pdo& pdo, std::uint8_t sub,
                                             std::uint32_t value) const {
  auto* self = const_cast<Cia402DriveNode*>(this);
  if ((cob_id(pdo) & cia402::kPdoInvalid) == 0) return ac::device_state;  // PDO still valid
  if (sub == 0) {
    if (value > 8) return ac::value_range;
    if (mapped_bits(pdo, static_cast<std::uint8_t>(value)) > 64) return ac::pdo_length;
    return 0;
  }
  if (self->find(pdo.map, 0)->value != 0) return ac::device_state;  // sub 0 must be 0 first
  if (value == 0) return 0;
  const auto index = static_cast<std::uint16_t>(value >> 16);
  const auto s = static_cast<std::uint8_t>(value >> 8);
  const std::uint8_t bits = value & 0xFF;
  const Entry* target = self->find(index, s);
  if (!target) return index_exists(index) ? ac::no_subindex : ac::no_object;
  if (!(pdo.receive ? target->rx_mappable : target->tx_mappable)) return ac::not_mappable;
  if (bits != 8u * target->size) return ac::length_mismatch;
  return 0;
}

std::uint32_t Cia402DriveNode::write(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                                     std::uint8_t size, bool from_pdo, Nanos now, FrameList& out) {
  Entry* e = find(index, sub);
  if (!e) return index_exists(index) ? ac::no_subindex : ac::no_object;
  if (e->access == Access::ro) return ac::read_only;
  if (size != 0 && size != e->size) return ac::length_mismatch;
  for (const Pdo& pdo : {kRpdo, kTpdo, kTpdo2}) {
    if (index == pdo.map) {
      if (const std::uint32_t a = check_mapping(pdo, sub, value)) return a;
    }
    if (index == pdo.comm && sub == 2 && value > 240 && value < 254) return ac::value_range;
  }
  switch (index) {
    case obj::modes_of_operation: {
      const auto mode = static_cast<std::int8_t>(value);
      if (mode != cia402::kModeCsp && mode != cia402::kModeHoming) return ac::value_range;
      homing_attained_ = false;
      homing_error_ = false;
      stop_search(now);
      find(obj::modes_of_operation_display, 0)->value = value & 0xFF;
      break;
    }
    case obj::homing_method: {
      const auto method = static_cast<std::int8_t>(value);
      if (method != cia402::kHomingHere && method != cia402::kHomingHereOld &&
          !HomingSearch::is_switch_method(method)) {
        return ac::value_range;
      }
      break;
    }
    case obj::controlword:
      e->value = value & 0xFFFF;
      controlword(static_cast<std::uint16_t>(value), now, out);
      return 0;
    case obj::target_position:
      e->value = value;
      if (state_ == State::operation_enabled && !health_.blocked() && !homing_mode()) {
        motor_.set_goal(static_cast<double>(static_cast<std::int32_t>(value) - position_offset_),
                        now);
      }
      return 0;
    case obj::heartbeat_time:
      next_heartbeat_ = now;  // restart the producer with the new period
      break;
    case obj::heartbeat_consumer:
      if ((value & 0xFF000000u) != 0) return ac::value_range;  // reserved bits
      consumer_armed_ = false;  // watches from the next heartbeat of that node
      break;
    case obj::abort_connection_option: {
      const auto code = static_cast<std::int16_t>(value);
      if (code > 3) return ac::value_range;  // < 0: manufacturer-specific, taken as a fault
      break;
    }
    default:
      break;
  }
  (void)from_pdo;
  e->value = value;
  return 0;
}

// ---- state machine -----------------------------------------------------------

void Cia402DriveNode::enter_state(State state, Nanos now) {
  if (state != State::operation_enabled) stop_search(now);
  state_ = state;
  if (state_ == State::operation_enabled) {
    // Take over at the present position: the target was set to it beforehand.
    if (homing_mode()) {
      motor_.hold(now);  // homing on the current position moves nothing
    } else {
      motor_.set_goal(
          static_cast<double>(static_cast<std::int32_t>(find(obj::target_position, 0)->value) -
                              position_offset_),
          now);
    }
  } else {
    motor_.hold(now);
  }
}

void Cia402DriveNode::controlword(std::uint16_t value, Nanos now, FrameList& out) {
  const cia402::Command command = cia402::decode_controlword(value, last_controlword_);
  const bool start =
      (value & cia402::kCwHomingStart) != 0 && (last_controlword_ & cia402::kCwHomingStart) == 0;
  const bool halt =
      (value & cia402::kCwHomingStart) == 0 && (last_controlword_ & cia402::kCwHomingStart) != 0;
  last_controlword_ = value;
  if (start && state_ == State::operation_enabled && homing_mode()) start_homing(now);
  if (halt) stop_search(now);  // interrupted: stops where it has got to
  if (command == cia402::Command::fault_reset && state_ == State::fault) {
    advance_health(now, out);     // cooled enough since the trip?
    if (condition_ != 0) return;  // the cause is still there: stays in fault
    find(obj::error_register, 0)->value = 0;
    find(obj::error_code, 0)->value = 0;
    heartbeat_error_ = false;
    emit_emcy(0x0000, out);  // error reset
  }
  const State next = cia402::next_state(state_, command);
  if (next != state_) enter_state(next, now);
}

void Cia402DriveNode::emit_emcy(std::uint16_t code, FrameList& out) {
  canopen::Emcy e;
  e.code = code;
  e.error_register = static_cast<std::uint8_t>(find(obj::error_register, 0)->value);
  if (nmt_ != NmtState::stopped) out.push_back(canopen::emcy(node_, e));
}

void Cia402DriveNode::set_fault(std::uint8_t bits, Nanos now, FrameList& out) {
  condition_ = bits;
  if (bits == 0) return;
  const std::uint16_t code = emcy_code_for(bits);
  find(obj::error_code, 0)->value = code;
  find(obj::error_register, 0)->value = error_register_for(code);
  enter_state(State::fault_reaction_active, now);
  enter_state(State::fault, now);  // the reaction (stop) is immediate here
  emit_emcy(code, out);
}

void Cia402DriveNode::reboot(Nanos now, FrameList& out) {
  condition_ = 0;
  overheated_ = false;
  reset_application(now);
  boot(out);
}

// ---- heartbeat consumer -----------------------------------------------------

void Cia402DriveNode::consume_heartbeat(const can_frame& f, Nanos now, FrameList& out) {
  const std::uint32_t entry = find(obj::heartbeat_consumer, 1)->value;
  const canid_t producer = (entry >> 16) & 0x7F;
  if ((entry & 0xFFFF) == 0 || f.len != 1 || (f.can_id & CAN_SFF_MASK) != 0x700 + producer) return;
  // A boot-up message is no sign of life yet; any other state is.
  if (f.data[0] == static_cast<std::uint8_t>(NmtState::boot_up)) return;
  consumer_armed_ = true;
  last_consumed_ = now;
  if (heartbeat_error_) {
    // The producer is back: the communication error is gone (a fault it
    // caused stays until a fault reset).
    heartbeat_error_ = false;
    Entry* reg = find(obj::error_register, 0);
    reg->value &= ~static_cast<std::uint32_t>(kCommunicationError);
    if (state_ != State::fault) {
      if ((reg->value & ~0x01u) == 0) reg->value = 0;
      find(obj::error_code, 0)->value = 0;
      emit_emcy(0x0000, out);
    }
  }
}

void Cia402DriveNode::check_consumer(Nanos now, FrameList& out) {
  if (!consumer_armed_) return;
  const std::uint32_t ms = find(obj::heartbeat_consumer, 1)->value & 0xFFFF;
  if (ms == 0) {
    consumer_armed_ = false;
    return;
  }
  if (now - last_consumed_ <= static_cast<Nanos>(ms) * 1'000'000) return;
  // Heartbeat event: report it, then the abort connection reaction.
  consumer_armed_ = false;
  heartbeat_error_ = true;
  ++heartbeat_events_;
  find(obj::error_register, 0)->value |= 0x01u | kCommunicationError;
  find(obj::error_code, 0)->value = kEmcyHeartbeat;
  emit_emcy(kEmcyHeartbeat, out);
  const auto option = static_cast<std::int16_t>(find(obj::abort_connection_option, 0)->value);
  const bool powered = state_ == State::operation_enabled || state_ == State::switched_on ||
                       state_ == State::ready_to_switch_on || state_ == State::quick_stop_active;
  if (option == 0 || !powered) return;
  if (option == static_cast<std::int16_t>(AbortConnection::quick_stop)) {
    if (state_ == State::operation_enabled) enter_state(State::quick_stop_active, now);
    // 605Ah 0-4 end the quick stop in Switch On Disabled, 5-8 stay in it.
    const auto qs = static_cast<std::int16_t>(find(obj::quick_stop_option, 0)->value);
    if (qs >= 0 && qs <= 4) enter_state(State::switch_on_disabled, now);
  } else if (option == static_cast<std::int16_t>(AbortConnection::disable_voltage)) {
    enter_state(State::switch_on_disabled, now);
  } else {
    // 1 (fault signal) and the manufacturer-specific codes.
    enter_state(State::fault_reaction_active, now);
    enter_state(State::fault, now);  // the reaction (stop) is immediate here
  }
}

// ---- frames ----------------------------------------------------------------

void Cia402DriveNode::handle_nmt(const can_frame& f, Nanos now, FrameList& out) {
  if (f.len != 2 || (f.data[1] != 0 && f.data[1] != node_)) return;
  switch (static_cast<canopen::NmtCommand>(f.data[0])) {
    case canopen::NmtCommand::start:
      nmt_ = NmtState::operational;
      break;
    case canopen::NmtCommand::stop:
      nmt_ = NmtState::stopped;
      break;
    case canopen::NmtCommand::enter_pre_operational:
      nmt_ = NmtState::pre_operational;
      break;
    case canopen::NmtCommand::reset_node:
      reset_application(now);
      boot(out);
      break;
    case canopen::NmtCommand::reset_communication:
      reset_communication();
      boot(out);
      break;
    default:
      break;  // unknown commands are ignored
  }
}

void Cia402DriveNode::handle_sdo(const can_frame& f, Nanos now, FrameList& out) {
  if (nmt_ == NmtState::stopped || f.len != 8) return;
  const canopen::Sdo s = canopen::parse_sdo(f);
  switch (s.kind) {
    case canopen::SdoKind::upload_request: {
      const Entry* e = find(s.index, s.subindex);
      std::uint32_t abort = 0;
      if (!e)
        abort = index_exists(s.index) ? ac::no_subindex : ac::no_object;
      else if (e->access == Access::wo)
        abort = ac::write_only;
      if (abort) {
        out.push_back(canopen::sdo_abort(node_, s.index, s.subindex, abort));
      } else {
        out.push_back(
            canopen::sdo_upload_response(node_, s.index, s.subindex, read_value(*e, now), e->size));
      }
      return;
    }
    case canopen::SdoKind::download_request: {
      if (!s.expedited) {
        out.push_back(canopen::sdo_abort(node_, s.index, s.subindex, ac::command_specifier));
        return;
      }
      const std::uint32_t abort = write(s.index, s.subindex, s.value, s.size, false, now, out);
      if (abort) {
        out.push_back(canopen::sdo_abort(node_, s.index, s.subindex, abort));
      } else {
        out.push_back(canopen::sdo_download_response(node_, s.index, s.subindex));
      }
      return;
    }
    case canopen::SdoKind::abort:
      return;  // the client gave up; nothing in flight here
    default:
      out.push_back(canopen::sdo_abort(node_, s.index, s.subindex, ac::command_specifier));
      return;
  }
}

void Cia402DriveNode::handle_rpdo(const can_frame& f, Nanos now, FrameList& out) {
  if (nmt_ != NmtState::operational) return;
  const std::uint32_t bytes =
      mapped_bits(kRpdo, static_cast<std::uint8_t>(find(kRpdo.map, 0)->value)) / 8;
  if (f.len < bytes) {
    emit_emcy(kEmcyRpdoLength, out);
    return;
  }
  std::copy(f.data, f.data + 8, rpdo_data_.begin());
  rpdo_pending_ = true;
  if (transmission_type(kRpdo) >= 254) apply_rpdo(now, out);
}

void Cia402DriveNode::apply_rpdo(Nanos now, FrameList& out) {
  if (!rpdo_pending_) return;
  rpdo_pending_ = false;
  const auto count = static_cast<std::uint8_t>(find(kRpdo.map, 0)->value);
  std::size_t offset = 0;
  // Target before controlword, so "enable operation" starts at the new target.
  for (int pass = 0; pass < 2; ++pass) {
    offset = 0;
    for (std::uint8_t s = 1; s <= count; ++s) {
      const std::uint32_t m = find(kRpdo.map, s)->value;
      const auto index = static_cast<std::uint16_t>(m >> 16);
      const int size = static_cast<int>((m & 0xFF) / 8);
      const bool is_cw = index == obj::controlword;
      if ((pass == 0) != is_cw) {
        write(index, static_cast<std::uint8_t>(m >> 8),
              canopen::get_le(rpdo_data_.data() + offset, size), 0, true, now, out);
      }
      offset += static_cast<std::size_t>(size);
    }
  }
}

void Cia402DriveNode::send_tpdo(const Pdo& pdo, Nanos now, FrameList& out) {
  can_frame f{};
  f.can_id = cob_id(pdo) & CAN_SFF_MASK;
  const auto count = static_cast<std::uint8_t>(find(pdo.map, 0)->value);
  std::size_t offset = 0;
  for (std::uint8_t s = 1; s <= count; ++s) {
    const std::uint32_t m = find(pdo.map, s)->value;
    const Entry* e = find(static_cast<std::uint16_t>(m >> 16), static_cast<std::uint8_t>(m >> 8));
    const int size = static_cast<int>((m & 0xFF) / 8);
    if (!e || offset + size > 8) return;
    canopen::put_le(f.data + offset, read_value(*e, now), size);
    offset += static_cast<std::size_t>(size);
  }
  f.len = static_cast<std::uint8_t>(offset);
  out.push_back(f);
}

void Cia402DriveNode::on_sync(Nanos now, FrameList& out) {
  if (nmt_ != NmtState::operational) return;
  const std::uint8_t rx_type = transmission_type(kRpdo);
  if (rx_type <= 240) apply_rpdo(now, out);
  ++sync_count_;
  advance_health(now, out);
  for (const Pdo& pdo : {kTpdo, kTpdo2}) {
    const std::uint8_t tx_type = transmission_type(pdo);
    if ((cob_id(pdo) & cia402::kPdoInvalid) == 0 && tx_type >= 1 && tx_type <= 240 &&
        sync_count_ % tx_type == 0) {
      send_tpdo(pdo, now, out);
    }
  }
}

void Cia402DriveNode::advance_health(Nanos now, FrameList& out) {
  const double speed = motor_.velocity(now) / binding_.ticks_per_rad;
  const bool was_blocked = health_.blocked();
  health_.advance(now, speed, state_ == State::operation_enabled);
  if (health_.blocked() && !was_blocked) motor_.hold(now);
  if (health_.injected_bits() != 0 && condition_ == 0) set_fault(health_.injected_bits(), now, out);
  check_trip(now, out);
}

void Cia402DriveNode::check_trip(Nanos now, FrameList& out) {
  const double t = health_.temperature_c();
  const double trip = settings_.health.trip_c;
  if (!overheated_ && condition_ == 0 && t > trip) {
    overheated_ = true;
    set_fault(kOverheating, now, out);  // EMCY 4310h; output off, so it cools
  } else if (overheated_ && t <= trip - kTripHysteresisC) {
    overheated_ = false;
    if (condition_ == kOverheating) condition_ = 0;  // a fault reset may clear it now
  }
}

void Cia402DriveNode::inject_health(const SimHealthInjection& change, Nanos now, FrameList& out) {
  advance_health(now, out);
  using Kind = SimHealthInjection::Kind;
  switch (change.kind) {
    case Kind::temperature:
      health_.set_temperature(change.value);
      break;
    case Kind::blocked:
      health_.set_blocked(change.value != 0.0);
      if (health_.blocked()) motor_.hold(now);
      break;
    case Kind::supply:
      health_.set_supply(change.value);
      break;
    case Kind::hardware_error:
      set_fault(static_cast<std::uint8_t>(change.value), now, out);
      break;
  }
  check_trip(now, out);
}

void Cia402DriveNode::handle(const can_frame& f, Nanos now, FrameList& out) {
  if (!responding()) return;
  if ((f.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0) return;
  poll(now, out);
  advance_search(now);
  const canid_t id = f.can_id & CAN_SFF_MASK;
  if (id == canopen::kNmtId) {
    handle_nmt(f, now, out);
  } else if (id == canopen::kSyncId) {
    on_sync(now, out);
  } else if (id == canopen::kRsdoBase + node_) {
    handle_sdo(f, now, out);
  } else if ((id & 0x780) == canopen::kHeartbeatBase) {
    consume_heartbeat(f, now, out);
  } else if ((cob_id(kRpdo) & cia402::kPdoInvalid) == 0 && id == (cob_id(kRpdo) & CAN_SFF_MASK)) {
    handle_rpdo(f, now, out);
  }
}

void Cia402DriveNode::poll(Nanos now, FrameList& out) {
  if (!responding()) return;
  if (boot_pending_) {
    boot(out);
    next_heartbeat_ = now;
  }
  check_consumer(now, out);
  const std::uint32_t period_ms = find(obj::heartbeat_time, 0)->value;
  if (period_ms == 0) return;
  const Nanos period = static_cast<Nanos>(period_ms) * 1'000'000;
  if (now < next_heartbeat_) return;
  out.push_back(canopen::heartbeat(node_, nmt_));
  next_heartbeat_ += period;
  if (next_heartbeat_ <= now) next_heartbeat_ = now + period;  // fell behind: no burst
}

}  // namespace animrt::sim
