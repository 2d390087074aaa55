#include "animrt/bridge/can/cia402_bus.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "animrt/core/error.hpp"

namespace animrt {
namespace {

using canopen::NmtState;
using cia402::State;

constexpr canid_t kExact = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
// CiA 301 EMCY "life guard error or heartbeat error".
constexpr std::uint16_t kHeartbeatErrorEmcy = 0x8130;

std::string hex(std::uint32_t v, int digits) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%0*X", digits, v);
  return buf;
}

std::string object_name(std::uint16_t index, std::uint8_t sub) {
  return hex(index, 4) + ":" + hex(sub, 2).substr(2);
}

}  // namespace

const char* to_string(AbortConnection action) {
  switch (action) {
    case AbortConnection::fault:
      return "a fault";
    case AbortConnection::disable_voltage:
      return "disable voltage";
    case AbortConnection::quick_stop:
      return "a quick stop";
  }
  return "unknown";
}

Cia402Bus::Cia402Bus(BusConfig config, std::unique_ptr<CanFrameTransport> transport)
    : config_(std::move(config)),
      options_(options_of<Cia402BusOptions>(config_.options)),
      transport_(std::move(transport)),
      timeout_(std::chrono::ceil<std::chrono::microseconds>(std::chrono::duration<double>(
          options_.sync_timeout_ms > 0 ? options_.sync_timeout_ms / 1000.0 : config_.timeout_s))),
      heartbeat_timeout_ns_(static_cast<Nanos>(options_.heartbeat_timeout_ms) * 1'000'000),
      host_heartbeat_ns_(static_cast<Nanos>(host_heartbeat_ms(options_.device_watchdog_ms)) *
                         1'000'000) {
  const std::string bus = "bus " + config_.name + ": ";
  if (!transport_) throw DeviceError(bus + "no transport");
  const std::size_t n = config_.actuators.size();
  slot_of_node_.assign(canopen::kMaxNodeId + 1, -1);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    const std::string who = "node " + std::to_string(b.device_id) + " (" + b.joint + ")";
    if (b.device_id < 1 || b.device_id > canopen::kMaxNodeId) {
      throw DeviceError(bus + who + " is outside 1..127");
    }
    if (slot_of_node_[b.device_id] >= 0) throw DeviceError(bus + who + " is used twice");
    if (!(b.ticks_per_rad > 0.0) || (b.direction != 1 && b.direction != -1)) {
      throw DeviceError(bus + who + ": bad scale or direction");
    }
    slot_of_node_[b.device_id] = static_cast<int>(i);
  }
  book_ = StatusBook(config_, transport_->interface(), "node");
  drive_.resize(n);
  actual_counts_.resize(n);
  target_counts_.resize(n);
  controlword_.resize(n);
  last_heartbeat_.resize(n);
  expect_.resize(n);
  hw_fault_.resize(n);
  min_rad_.resize(n);
  max_rad_.resize(n);
  rated_current_a_.assign(n, 0.0);
  joint_options_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    joint_options_[i] = options_of<Cia402JointOptions>(b.options);
    const double a = b.to_rad(std::numeric_limits<std::int32_t>::min() + 1);
    const double c = b.to_rad(std::numeric_limits<std::int32_t>::max() - 1);
    min_rad_[i] = std::min(a, c);
    max_rad_[i] = std::max(a, c);
  }
}

std::string Cia402Bus::fault_text(std::size_t device) const {
  const DriveReport& d = drive_[device];
  std::string out;
  if (d.last_emcy.code != 0) {
    out = "EMCY " + hex(d.last_emcy.code, 4) + " (" + canopen::emcy_class(d.last_emcy.code) +
          "), error register " + hex(d.last_emcy.error_register, 2);
  }
  if (d.reboots > 0)
    out += (out.empty() ? "" : "; ") + std::string("drive rebooted (boot-up message)");
  if (d.state == State::fault)
    out += (out.empty() ? "" : "; ") + std::string("statusword in fault");
  if (d.heartbeat_lost) out += (out.empty() ? "" : "; ") + std::string("heartbeat lost");
  if (d.last_emcy.code == kHeartbeatErrorEmcy) {
    out += "; the drive missed the host's heartbeat for more than " +
           std::to_string(options_.device_watchdog_ms) + " ms (device_watchdog_ms) and did " +
           to_string(options_.abort_connection);
  }
  return out;
}

int Cia402Bus::slot_of(canid_t cob, canid_t base) const {
  const canid_t node = cob - base;
  if (cob < base || node < 1 || node > static_cast<canid_t>(canopen::kMaxNodeId)) return -1;
  return slot_of_node_[node];
}

// ---- frames in -------------------------------------------------------------

void Cia402Bus::handle(const can_frame& f) {
  const canid_t cob = f.can_id & CAN_SFF_MASK;
  const canid_t function = cob & 0x780;
  int slot = -1;
  switch (function) {
    case canopen::kTpdo1Base: {
      slot = slot_of(cob, canopen::kTpdo1Base);
      if (slot < 0) return;
      const auto device = static_cast<std::size_t>(slot);
      if (f.len != (options_.health ? 8 : 6)) {
        book_.garbled(device);
        return;
      }
      if (options_.health) {
        HealthReading& h = book_[device].reading;
        h.error_bits = static_cast<std::uint32_t>(canopen::get_le(f.data + 6, 2));
        h.has_error_bits = true;
        h.read_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                        std::chrono::steady_clock::now().time_since_epoch())
                        .count();
        ++h.reads;
      }
      DriveReport& d = drive_[slot];
      d.statusword = static_cast<std::uint16_t>(canopen::get_le(f.data, 2));
      d.state = cia402::decode_statusword(d.statusword);
      actual_counts_[slot] = static_cast<std::int32_t>(canopen::get_le(f.data + 2, 4));
      if (expect_[slot]) {
        expect_[slot] = 0;
        book_.answered(device);
      }
      if (d.state == State::fault || d.state == State::fault_reaction_active ||
          (running_ && d.state != State::operation_enabled)) {
        hw_fault_[slot] = 1;
      }
      return;
    }
    case canopen::kTpdo2Base: {
      slot = slot_of(cob, canopen::kTpdo2Base);
      if (slot < 0 || !options_.health) return;
      const auto device = static_cast<std::size_t>(slot);
      const Cia402JointOptions& o = joint_options_[device];
      const int temperature_bytes = o.has_temperature ? o.temperature.bits / 8 : 0;
      if (f.len != 6 + temperature_bytes) {
        book_.garbled(device);
        return;
      }
      // Current actual: per mille of the motor's rated current (6075h, mA).
      HealthReading& h = book_[device].reading;
      const auto per_mille = static_cast<std::int16_t>(canopen::get_le(f.data, 2));
      h.current_a = rated_current_a_[device] > 0.0
                        ? std::abs(per_mille) / 1000.0 * rated_current_a_[device]
                        : HealthReading::kNone;
      h.voltage_v = canopen::get_le(f.data + 2, 4) / 1000.0;
      if (o.has_temperature) {
        h.temperature_c = o.temperature.decode(
            static_cast<std::uint32_t>(canopen::get_le(f.data + 6, temperature_bytes)));
      }
      return;
    }
    case canopen::kHeartbeatBase: {
      slot = slot_of(cob, canopen::kHeartbeatBase);
      if (slot < 0 || f.len != 1) return;
      DriveReport& d = drive_[slot];
      d.nmt = static_cast<NmtState>(f.data[0] & 0x7F);
      ++d.heartbeats;
      last_heartbeat_[slot] = transport_->now();
      d.heartbeat_lost = false;
      if (d.nmt == NmtState::boot_up && running_) {
        ++d.reboots;  // lost its state: the drive is de-energised, not following
        hw_fault_[slot] = 1;
      } else if (running_ && d.nmt != NmtState::operational) {
        hw_fault_[slot] = 1;
      }
      return;
    }
    case canopen::kTsdoBase: {
      slot = slot_of(cob, canopen::kTsdoBase);
      if (slot < 0 || slot != sdo_slot_) return;
      sdo_answer_ = canopen::parse_sdo(f);
      sdo_done_ = true;
      return;
    }
    default:
      break;
  }
  if (cob > canopen::kEmcyBase && cob <= canopen::kEmcyBase + canopen::kMaxNodeId) {
    slot = slot_of(cob, canopen::kEmcyBase);
    canopen::Emcy e;
    if (slot < 0 || !canopen::parse_emcy(f, e)) return;
    DriveReport& d = drive_[slot];
    DeviceStatus& st = book_[static_cast<std::size_t>(slot)];
    st.hardware_error_status = e.error_register;
    if (e.code == 0) return;  // error reset: the statusword says whether the fault is gone
    d.last_emcy = e;
    ++d.emcy_count;
    book_.fault_reported(static_cast<std::size_t>(slot));
    hw_fault_[slot] = 1;
  }
}

void Cia402Bus::supervise() {
  const Nanos now = transport_->now();
  for (std::size_t i = 0; i < book_.size(); ++i) {
    if (book_.faulted(i)) continue;
    if (expect_[i]) book_.timed_out(i);
    if (options_.heartbeat_ms > 0 && now - last_heartbeat_[i] > heartbeat_timeout_ns_) {
      // One timeout counted per heartbeat lost, the health says so while it is.
      if (!drive_[i].heartbeat_lost) {
        book_.timed_out(i);
      } else {
        book_[i].health = DeviceHealth::timeout;
      }
      drive_[i].heartbeat_lost = true;
    }
    if (hw_fault_[i]) book_[i].health = DeviceHealth::hardware_error;
  }
}

void Cia402Bus::produce_heartbeat() {
  if (!producing_) return;
  const Nanos now = transport_->now();
  if (now < next_host_heartbeat_) return;
  transport_->send(
      canopen::heartbeat(static_cast<std::uint8_t>(options_.host_node_id), NmtState::operational));
  next_host_heartbeat_ += host_heartbeat_ns_;
  if (next_host_heartbeat_ <= now) next_host_heartbeat_ = now + host_heartbeat_ns_;
}

void Cia402Bus::sync_cycle() {
  produce_heartbeat();
  std::size_t waiting = 0;
  for (std::size_t i = 0; i < book_.size(); ++i) {
    expect_[i] = book_[i].faulted ? 0 : 1;
    if (expect_[i]) {
      book_.asked(i);
      ++waiting;
    }
  }
  transport_->send(canopen::sync());
  const auto deadline = std::chrono::steady_clock::now() + timeout_;
  can_frame frame;
  // A node that floods the bus must not keep the cycle here: past the
  // deadline at most this many more frames are taken.
  std::size_t budget = frame_budget();
  while (waiting > 0) {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0 && budget-- == 0) break;
    if (!transport_->receive(frame, std::max(left, std::chrono::microseconds(0)))) break;
    handle(frame);
    waiting = static_cast<std::size_t>(std::count(expect_.begin(), expect_.end(), 1));
  }
  // Whatever else already arrived (heartbeats, EMCY) without waiting for more.
  budget = frame_budget();
  while (budget-- > 0 && transport_->receive(frame, std::chrono::microseconds(0))) handle(frame);
  supervise();
}

// ---- frames out ------------------------------------------------------------

void Cia402Bus::send_rpdo(std::size_t device, std::uint16_t controlword, std::int32_t target) {
  can_frame f{};
  f.can_id = canopen::kRpdo1Base + static_cast<canid_t>(config_.actuators[device].device_id);
  f.len = 6;
  canopen::put_le(f.data, controlword, 2);
  canopen::put_le(f.data + 2, static_cast<std::uint32_t>(target), 4);
  controlword_[device] = controlword;
  transport_->send(f);
}

void Cia402Bus::nmt(canopen::NmtCommand command, std::size_t device) {
  transport_->send(
      canopen::nmt(command, static_cast<std::uint8_t>(config_.actuators[device].device_id)));
}

std::uint32_t Cia402Bus::sdo_read(std::size_t device, std::uint16_t index, std::uint8_t sub) {
  const auto node = static_cast<std::uint8_t>(config_.actuators[device].device_id);
  return sdo_exchange(device, canopen::sdo_upload(node, index, sub), index, sub,
                      "SDO upload " + object_name(index, sub), canopen::SdoKind::upload_response);
}

void Cia402Bus::sdo_write(std::size_t device, std::uint16_t index, std::uint8_t sub,
                          std::uint32_t value, std::uint8_t size) {
  const auto node = static_cast<std::uint8_t>(config_.actuators[device].device_id);
  sdo_exchange(device, canopen::sdo_download(node, index, sub, value, size), index, sub,
               "SDO download " + object_name(index, sub) + " = " + hex(value, 2 * size),
               canopen::SdoKind::download_response);
}

std::uint32_t Cia402Bus::sdo_exchange(std::size_t device, const can_frame& request,
                                      std::uint16_t index, std::uint8_t sub,
                                      const std::string& what, canopen::SdoKind expected) {
  for (int t = 0; t < kTries; ++t) {
    sdo_slot_ = static_cast<int>(device);
    sdo_done_ = false;
    transport_->send(request);
    const auto deadline = std::chrono::steady_clock::now() + timeout_;
    can_frame frame;
    std::size_t budget = frame_budget();
    while (!sdo_done_) {
      const auto left = std::chrono::duration_cast<std::chrono::microseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0 && budget-- == 0) break;
      if (!transport_->receive(frame, std::max(left, std::chrono::microseconds(0)))) break;
      handle(frame);
      // The answer to an earlier SDO of this drive whose try timed out and
      // whose retry was answered first: it names another object, or another
      // kind of transfer. Not this one's answer (nor its refusal); waited on.
      const canopen::Sdo& a = sdo_answer_;
      if (sdo_done_ && (a.index != index || a.subindex != sub ||
                        (a.kind != canopen::SdoKind::abort && a.kind != expected))) {
        book_.stray(device);
        sdo_done_ = false;
      }
    }
    sdo_slot_ = -1;
    if (!sdo_done_) continue;
    const canopen::Sdo& a = sdo_answer_;
    if (a.kind == canopen::SdoKind::abort) {
      throw DeviceError(prefix() + describe(device) + ": " + what + " aborted: " + hex(a.value, 8) +
                        " (" + canopen::sdo_abort_text(a.value) + ")");
    }
    // Uploads are expedited only: a segmented answer is not understood.
    const bool expedited_if_upload = expected != canopen::SdoKind::upload_response || a.expedited;
    if (!expedited_if_upload) {
      book_.stray(device);
      throw DeviceError(prefix() + describe(device) + ": " + what + ": unexpected answer");
    }
    return a.value;
  }
  ++book_[device].timeouts;
  throw DeviceError(prefix() + describe(device) + ": no answer to " + what);
}

// ---- lifecycle -------------------------------------------------------------

void Cia402Bus::configure() {
  std::vector<can_filter> filters;
  for (const ActuatorBinding& b : config_.actuators) {
    const auto node = static_cast<canid_t>(b.device_id);
    for (canid_t base :
         {canopen::kTpdo1Base, canopen::kTsdoBase, canopen::kHeartbeatBase, canopen::kEmcyBase}) {
      filters.push_back({base + node, kExact});
    }
    if (options_.health) filters.push_back({canopen::kTpdo2Base + node, kExact});
  }
  transport_->set_filters(filters);
  running_ = false;
  const Nanos now = transport_->now();
  book_.reset();
  for (std::size_t i = 0; i < book_.size(); ++i) {
    drive_[i] = DriveReport{};
    hw_fault_[i] = 0;
    last_heartbeat_[i] = now;
  }

  std::string missing;
  for (std::size_t i = 0; i < book_.size(); ++i) {
    try {
      const std::uint32_t type = sdo_read(i, cia402::obj::device_type, 0);
      if ((type & 0xFFFF) != cia402::kDeviceProfile) {
        throw DeviceError(prefix() + describe(i) + ": device type " + hex(type, 8) +
                          " is not a CiA 402 drive");
      }
    } catch (const DeviceError& e) {
      if (std::string(e.what()).find("no answer") == std::string::npos) throw;
      missing += (missing.empty() ? "" : ", ") + describe(i);
    }
  }
  if (!missing.empty()) {
    std::string message =
        prefix() + "no answer to SDO upload 0x1000:00 (device type) from " + missing;
    if (transport_->bus_off()) message += " (the interface is bus-off)";
    throw DeviceError(message);
  }

  using namespace cia402::obj;
  for (std::size_t i = 0; i < book_.size(); ++i) {
    const auto node = static_cast<std::uint32_t>(config_.actuators[i].device_id);
    nmt(canopen::NmtCommand::enter_pre_operational, i);
    sdo_write(i, heartbeat_time, 0, static_cast<std::uint32_t>(options_.heartbeat_ms), 2);
    sdo_write(i, modes_of_operation, 0, static_cast<std::uint8_t>(cia402::kModeCsp), 1);
    // RPDO1: controlword + target position, applied at the next SYNC.
    sdo_write(i, rpdo1_comm, 1, cia402::kPdoInvalid | (canopen::kRpdo1Base + node), 4);
    sdo_write(i, rpdo1_map, 0, 0, 1);
    sdo_write(i, rpdo1_map, 1, canopen::mapping(controlword, 0, 16), 4);
    sdo_write(i, rpdo1_map, 2, canopen::mapping(target_position, 0, 32), 4);
    sdo_write(i, rpdo1_map, 0, 2, 1);
    sdo_write(i, rpdo1_comm, 2, 1, 1);
    sdo_write(i, rpdo1_comm, 1, canopen::kRpdo1Base + node, 4);
    // TPDO1: statusword + position actual, on every SYNC.
    sdo_write(i, tpdo1_comm, 1, cia402::kPdoInvalid | (canopen::kTpdo1Base + node), 4);
    sdo_write(i, tpdo1_map, 0, 0, 1);
    sdo_write(i, tpdo1_map, 1, canopen::mapping(statusword, 0, 16), 4);
    sdo_write(i, tpdo1_map, 2, canopen::mapping(position_actual, 0, 32), 4);
    if (options_.health) sdo_write(i, tpdo1_map, 3, canopen::mapping(error_code, 0, 16), 4);
    sdo_write(i, tpdo1_map, 0, options_.health ? 3 : 2, 1);
    sdo_write(i, tpdo1_comm, 2, 1, 1);
    sdo_write(i, tpdo1_comm, 1, canopen::kTpdo1Base + node, 4);
    if (options_.health) map_health_tpdo(i);

    actual_counts_[i] = static_cast<std::int32_t>(sdo_read(i, position_actual, 0));
    target_counts_[i] = actual_counts_[i];
    drive_[i].statusword = static_cast<std::uint16_t>(sdo_read(i, statusword, 0));
    drive_[i].state = cia402::decode_statusword(drive_[i].statusword);
    controlword_[i] = static_cast<std::uint16_t>(sdo_read(i, controlword, 0));
    nmt(canopen::NmtCommand::start, i);
  }
  for (std::size_t i = 0; i < book_.size(); ++i) last_heartbeat_[i] = transport_->now();
  fresh_ = true;
}

// TPDO2: current actual + DC link voltage (+ the temperature object the
// device's config names) on every SYNC, the current scaled by the motor's
// rated current read once here.
void Cia402Bus::map_health_tpdo(std::size_t i) {
  using namespace cia402::obj;
  const auto node = static_cast<std::uint32_t>(config_.actuators[i].device_id);
  rated_current_a_[i] = sdo_read(i, motor_rated_current, 0) / 1000.0;
  sdo_write(i, tpdo2_comm, 1, cia402::kPdoInvalid | (canopen::kTpdo2Base + node), 4);
  sdo_write(i, tpdo2_map, 0, 0, 1);
  sdo_write(i, tpdo2_map, 1, canopen::mapping(current_actual, 0, 16), 4);
  sdo_write(i, tpdo2_map, 2, canopen::mapping(dc_link_voltage, 0, 32), 4);
  const Cia402JointOptions& o = joint_options_[i];
  if (o.has_temperature) {
    const Cia402Temperature& t = o.temperature;
    sdo_write(i, tpdo2_map, 3,
              canopen::mapping(t.index, t.subindex, static_cast<std::uint8_t>(t.bits)), 4);
  }
  sdo_write(i, tpdo2_map, 0, o.has_temperature ? 3 : 2, 1);
  sdo_write(i, tpdo2_comm, 2, 1, 1);
  sdo_write(i, tpdo2_comm, 1, canopen::kTpdo2Base + node, 4);
}

std::string Cia402Bus::walk_to(State goal, std::size_t only) {
  for (int step = 0; step < kStateMachineSteps; ++step) {
    bool all_there = true;
    for (std::size_t i = 0; i < book_.size(); ++i) {
      if (book_[i].faulted || (only != kAllDrives && i != only)) continue;
      if (drive_[i].state == goal) continue;
      all_there = false;
      send_rpdo(i, cia402::controlword_toward(drive_[i].state, goal, controlword_[i]),
                actual_counts_[i]);
    }
    if (all_there) return "";
    sync_cycle();
  }
  std::string failed;
  for (std::size_t i = 0; i < book_.size(); ++i) {
    if (book_[i].faulted || drive_[i].state == goal || (only != kAllDrives && i != only)) continue;
    std::string why = fault_text(i);
    failed += (failed.empty() ? "" : ", ") + describe(i) + " stays in " +
              cia402::to_string(drive_[i].state) + (why.empty() ? "" : " (" + why + ")");
  }
  return failed;
}

void Cia402Bus::activate() {
  // Targets = where each drive is, so enabling cannot jump to a stale goal.
  for (std::size_t i = 0; i < book_.size(); ++i) {
    target_counts_[i] = actual_counts_[i];
    hw_fault_[i] = 0;
  }
  const std::string failed = walk_to(State::operation_enabled);
  if (!failed.empty()) {
    deactivate();
    throw DeviceError(prefix() + "cannot enable operation: " + failed);
  }
  for (std::size_t i = 0; i < book_.size(); ++i) {
    target_counts_[i] = actual_counts_[i];
    hw_fault_[i] = 0;
  }
  running_ = true;
}

void Cia402Bus::arm_device_guard() {
  try {
    arm_guard(kAllDrives);
  } catch (const DeviceError&) {
    deactivate();
    throw;
  }
}

void Cia402Bus::arm_guard(std::size_t only) {
  if (options_.device_watchdog_ms <= 0) return;
  // A drive starts watching at the first heartbeat after the consumer is
  // set, sent at once; from then on every read produces them.
  try {
    for (std::size_t i = 0; i < book_.size(); ++i) {
      if (book_[i].faulted || (only != kAllDrives && i != only)) continue;
      sdo_write(i, cia402::obj::abort_connection_option, 0,
                static_cast<std::uint16_t>(options_.abort_connection), 2);
      sdo_write(i, cia402::obj::heartbeat_consumer, 1,
                consumer_entry(options_.host_node_id, options_.device_watchdog_ms), 4);
    }
  } catch (const DeviceError& e) {
    throw DeviceError(std::string(e.what()) +
                      " (the drive's guard against a dead host; device_watchdog_ms: off "
                      "runs without it)");
  }
  producing_ = true;
  next_host_heartbeat_ = transport_->now();
  produce_heartbeat();
}

void Cia402Bus::deactivate() {
  running_ = false;
  try {
    walk_to(State::switch_on_disabled);
    clear_device_guard();
    for (std::size_t i = 0; i < book_.size(); ++i) {
      nmt(canopen::NmtCommand::enter_pre_operational, i);
    }
    const std::string errors = describe_errors(transport_->errors());
    if (!errors.empty())
      std::fprintf(stderr, "%sCAN errors: %s\n", prefix().c_str(), errors.c_str());
  } catch (...) {
    // deactivate never throws
  }
  producing_ = false;
}

void Cia402Bus::clear_device_guard(std::size_t only) {
  if (options_.device_watchdog_ms <= 0) return;
  for (std::size_t i = 0; i < book_.size(); ++i) {
    if (only != kAllDrives && i != only) continue;
    try {
      sdo_write(i, cia402::obj::heartbeat_consumer, 1, 0, 4);
    } catch (const DeviceError&) {
      // A drive that does not answer now has its guard still armed; it will
      // stop by itself, which is what the guard is for.
    }
  }
  producing_ = false;
}

// ---- cycle -------------------------------------------------------------------

void Cia402Bus::read(std::span<double> positions) {
  const std::size_t n = std::min(positions.size(), book_.size());
  if (!fresh_ && !running_) {
    read_limp();
  } else if (!fresh_) {
    sync_cycle();
  }
  fresh_ = false;
  for (std::size_t i = 0; i < n; ++i) {
    positions[i] = config_.actuators[i].to_rad(actual_counts_[i]);
  }
}

void Cia402Bus::read_limp() {
  // Disabled and pre-operational (commissioning: a joint moved by hand):
  // no PDOs, so the position actual by SDO, a device that fails counted.
  for (std::size_t i = 0; i < book_.size(); ++i) {
    if (book_[i].faulted) continue;
    book_.asked(i);
    try {
      actual_counts_[i] = static_cast<std::int32_t>(sdo_read(i, cia402::obj::position_actual, 0));
      book_.answered(i);
    } catch (const DeviceError&) {
      book_.timed_out(i);
    }
  }
}

void Cia402Bus::write(std::span<const double> positions) {
  for (std::size_t i = 0; i < book_.size(); ++i) {
    if (book_[i].faulted) continue;
    if (i < positions.size() && std::isfinite(positions[i])) {
      const double goal = config_.actuators[i].safe_goal(positions[i], positions[i]);
      target_counts_[i] = config_.actuators[i].to_ticks(std::clamp(goal, min_rad_[i], max_rad_[i]));
    }
    send_rpdo(i, cia402::cw::enable_operation, target_counts_[i]);
  }
}

}  // namespace animrt
