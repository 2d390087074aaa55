#pragma once
// A simulated CANopen CiA 402 servo drive: the device side of the protocol
// the runtime's Cia402Bus speaks.
//
// - NMT: start, stop, enter pre-operational, reset node (object dictionary
//   back to defaults), reset communication (1000h-1FFFh back to defaults);
//   a boot-up message after power-on and after either reset.
// - Object dictionary subset: 1000h device type (0x00020192), 1001h error
//   register, 1017h heartbeat producer time, 1018h identity, RPDO1 (1400h,
//   1600h) and TPDO1 (1800h, 1A00h) communication and mapping, 603Fh error
//   code, 6040h controlword, 6041h statusword, 6060h/6061h modes of
//   operation (8, cyclic synchronous position, and 6, homing), 6064h
//   position actual, 606Ch velocity actual, 607Ah target position, 607Ch
//   home offset, 6098h homing method (35 and 37, homing on the current
//   position; 17-30, on switches), 6099h homing speeds, 609Ah homing
//   acceleration.
// - Homing mode (6): in Operation Enabled a rising controlword bit 4 starts
//   it; methods 35/37 make the position actual read the home offset where
//   the motor is, without moving, and set statusword bits 12 (homing
//   attained) and 10 (target reached). Methods 17-30 first search the
//   switches of sim.switches (HomingSearch: statusword bits 10, 12, 13
//   clear while it moves), then the edge found reads the home offset;
//   a limit switch the method does not use sets bit 13 (homing error) and
//   the drive stops there. Bit 4 falling interrupts a search (bit 10 alone).
//   The offset is the drive's own (absolute encoder): kept across NMT
//   resets and reboots.
// - Expedited SDO upload and download with the CiA 301 abort codes (object
//   or sub-index missing, read-only, write-only, length mismatch, value
//   range, mapping rules); segmented transfers are answered with an abort.
// - PDOs: mapping as configured through 1600h/1A00h (rules: disable the PDO
//   by COB-ID bit 31 and set sub-index 0 to 0 before changing entries; only
//   mappable objects; at most 64 bits). Transmission types 1-240 act on
//   SYNC (an RPDO received is applied at the next SYNC; a TPDO goes out
//   every n-th SYNC), 254/255 immediately (RPDO) / never on SYNC (TPDO).
// - The controlword / statusword state machine of CiA 402, with fault
//   reaction, fault reset and quick stop.
// - EMCY on a fault (error code per injected condition, error register),
//   and "error reset" (code 0) when a fault reset clears it; EMCY 8210h when
//   an RPDO is shorter than its mapping.
// - Heartbeat producer at the 1017h period.
// - Heartbeat consumer (1016h:01, one entry: producer node id and time in
//   ms): it watches from the first heartbeat of that node after the entry
//   is written; when the time passes without one it sends EMCY 8130h
//   (heartbeat error), sets the communication bit of the error register and
//   603Fh, and reacts as 6007h (abort connection option code) says: 1 fault
//   (the default), 2 disable voltage, 3 quick stop (then 605Ah), 0 none. A
//   heartbeat that comes back clears the communication error (EMCY 0000h
//   unless in Fault, which needs a fault reset).
// - Motor: in Operation Enabled the position follows the target (LagMotor,
//   in counts); otherwise it holds. A blocked joint (sim.inject) holds too.
// - Health: 6075h motor rated current (mA), 6078h current actual (per mille
//   of 6075h) and 6079h DC link circuit voltage (mV), from the servos'
//   health model (current driven by the motion or a stall, a supply that
//   sags with it), mappable into TPDO2 (1801h, 1A01h; COB-ID 280h + node,
//   invalid by default). The profile has no temperature object, so none is
//   reported; an injected hardware error is a fault with its EMCY. Above
//   sim.health.trip_c the drive trips by itself, as drive firmware does:
//   Fault, EMCY 4310h (excess temperature, drive), output off; a fault
//   reset clears it only once it has cooled 5 deg C below the trip.

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/can/can_options.hpp"
#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/sim/can/can_node.hpp"
#include "animrt/sim/can/homing_search.hpp"
#include "animrt/sim/can/motor_model.hpp"
#include "animrt/sim/servo_health_model.hpp"

namespace animrt::sim {

inline constexpr std::uint32_t kDriveDeviceType = 0x00020192;  // servo drive, profile 402
inline constexpr std::uint32_t kDriveVendorId = 0x000000A5;
inline constexpr std::uint32_t kDriveProductCode = 0x00000402;

class Cia402DriveNode final : public CanNode {
 public:
  Cia402DriveNode(const ActuatorBinding& binding, const SimBusSettings& settings, Nanos now);

  int device_id() const override { return binding_.device_id; }
  std::vector<canid_t> listens_to() const override;
  void handle(const can_frame& frame, Nanos now, FrameList& out) override;
  void poll(Nanos now, FrameList& out) override;
  double joint_position(Nanos now) const override;
  void set_fault(std::uint8_t bits, Nanos now, FrameList& out) override;
  void reboot(Nanos now, FrameList& out) override;
  void inject_health(const SimHealthInjection& change, Nanos now, FrameList& out) override;

  cia402::State state() const { return state_; }
  canopen::NmtState nmt_state() const { return nmt_; }
  std::uint16_t statusword(Nanos now) const;
  // Times the heartbeat consumer fired since power-on.
  std::uint64_t heartbeat_events() const { return heartbeat_events_; }
  bool guard_fired() const override { return heartbeat_error_; }
  // The EMCY error code an injected fault condition produces.
  static std::uint16_t emcy_code_for(std::uint8_t bits);

 private:
  enum class Access : std::uint8_t { ro, rw, wo };
  struct Entry {
    std::uint16_t index;
    std::uint8_t sub;
    std::uint8_t size;  // bytes
    Access access;
    bool rx_mappable;  // may be mapped into an RPDO
    bool tx_mappable;  // may be mapped into a TPDO
    std::uint32_t value;
  };
  struct Pdo {
    std::uint16_t comm;  // 1400h / 1800h
    std::uint16_t map;   // 1600h / 1A00h
    bool receive;
  };

  void reset_application(Nanos now);
  void reset_communication();
  void boot(FrameList& out);
  Entry* find(std::uint16_t index, std::uint8_t sub);
  bool index_exists(std::uint16_t index) const;
  std::uint32_t read_value(const Entry& e, Nanos now) const;
  // A manufacturer object: the temperature object the config names, served
  // from the health model; any other keeps its stored value.
  std::uint32_t manufacturer_value(const Entry& e) const;
  // Checks and performs a write (SDO or PDO); returns an abort code or 0.
  std::uint32_t write(std::uint16_t index, std::uint8_t sub, std::uint32_t value, std::uint8_t size,
                      bool from_pdo, Nanos now, FrameList& out);
  std::uint32_t check_mapping(const Pdo& pdo, std::uint8_t sub, std::uint32_t value) const;
  std::uint32_t mapped_bits(const Pdo& pdo, std::uint8_t count) const;
  void handle_sdo(const can_frame& frame, Nanos now, FrameList& out);
  void handle_nmt(const can_frame& frame, Nanos now, FrameList& out);
  void handle_rpdo(const can_frame& frame, Nanos now, FrameList& out);
  void apply_rpdo(Nanos now, FrameList& out);
  void on_sync(Nanos now, FrameList& out);
  void send_tpdo(const Pdo& pdo, Nanos now, FrameList& out);
  // The health model on to `now`; an injected fault condition faults the drive.
  void advance_health(Nanos now, FrameList& out);
  // The drive's own trip above sim.health.trip_c, and its end once cooled.
  void check_trip(Nanos now, FrameList& out);
  void controlword(std::uint16_t value, Nanos now, FrameList& out);
  void enter_state(cia402::State state, Nanos now);
  void emit_emcy(std::uint16_t code, FrameList& out);
  void consume_heartbeat(const can_frame& frame, Nanos now, FrameList& out);
  void check_consumer(Nanos now, FrameList& out);
  std::uint32_t cob_id(const Pdo& pdo) const;
  std::uint8_t transmission_type(const Pdo& pdo) const;

  ActuatorBinding binding_;
  SimBusSettings settings_;
  std::uint8_t node_;
  std::vector<Entry> od_;
  canopen::NmtState nmt_ = canopen::NmtState::pre_operational;
  cia402::State state_ = cia402::State::switch_on_disabled;
  std::uint16_t last_controlword_ = 0;
  LagMotor motor_;  // counts
  // What homing added: position actual = motor + position_offset_.
  std::int32_t position_offset_ = 0;
  bool homing_attained_ = false;
  std::int32_t counts(Nanos now) const;
  bool homing_mode() const {
    return static_cast<std::int8_t>(const_cast<Cia402DriveNode*>(this)
                                        ->find(cia402::obj::modes_of_operation, 0)
                                        ->value) == cia402::kModeHoming;
  }
  void start_homing(Nanos now);
  // A switch search on to `now`: the motor where it has got to, the home
  // offset taken at the edge found.
  void advance_search(Nanos now);
  void stop_search(Nanos now);
  HomingSearch::Switches switches() const;
  std::optional<HomingSearch> search_;
  bool homing_error_ = false;
  ServoHealthModel health_;
  std::uint8_t condition_ = 0;  // injected fault condition (0: none)
  bool overheated_ = false;     // tripped on its own temperature, not yet cooled
  bool boot_pending_ = true;
  Nanos next_heartbeat_ = 0;
  // Heartbeat consumer: watching since the first heartbeat, and its time.
  bool consumer_armed_ = false;
  Nanos last_consumed_ = 0;
  bool heartbeat_error_ = false;
  std::uint64_t heartbeat_events_ = 0;
  // RPDO received, waiting for SYNC.
  std::array<std::uint8_t, 8> rpdo_data_{};
  bool rpdo_pending_ = false;
  std::uint32_t sync_count_ = 0;
  static constexpr Pdo kRpdo{0x1400, 0x1600, true};
  static constexpr Pdo kTpdo{0x1800, 0x1A00, false};
  static constexpr Pdo kTpdo2{0x1801, 0x1A01, false};
  static constexpr std::uint32_t kRatedCurrentMa = 2000;
};

}  // namespace animrt::sim
