// The simulated CiA 402 drive and MIT motor as firmware: NMT, SDO with abort
// codes, PDO mapping rules, SYNC, heartbeat, EMCY, the state machine, and
// MIT motor mode.

#include <gtest/gtest.h>

#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/mit_codec.hpp"
#include "animrt/sim/can/cia402_drive_node.hpp"
#include "animrt/sim/can/mit_motor_node.hpp"

namespace animrt::sim {
namespace {

using namespace canopen;
namespace obj = cia402::obj;

constexpr std::uint8_t kNode = 5;
constexpr Nanos kMs = 1'000'000;

struct Drive {
  ActuatorBinding binding;
  SimBusSettings settings;
  std::unique_ptr<Cia402DriveNode> node;
  FrameList out;
  Nanos now = 0;

  Drive() {
    binding.joint = "j";
    binding.device_id = kNode;
    binding.ticks_per_rad = 65536 / 6.283185307179586;
    binding.zero_ticks = 0;
    node = std::make_unique<Cia402DriveNode>(binding, settings, now);
    node->poll(now, out);  // boot-up
  }
  FrameList send(const can_frame& f) {
    out.clear();
    node->handle(f, now, out);
    return out;
  }
  Sdo sdo(const can_frame& f) {
    const FrameList r = send(f);
    EXPECT_EQ(r.size(), 1u);
    return r.empty() ? Sdo{} : parse_sdo(r[0]);
  }
  std::uint32_t write_abort(std::uint16_t index, std::uint8_t sub, std::uint32_t v,
                            std::uint8_t size) {
    const Sdo s = sdo(sdo_download(kNode, index, sub, v, size));
    return s.kind == SdoKind::abort ? s.value : 0;
  }
  std::uint32_t read(std::uint16_t index, std::uint8_t sub = 0) {
    return sdo(sdo_upload(kNode, index, sub)).value;
  }
  // The mapping the runtime writes at configure().
  void map_csp() {
    const std::uint32_t n = kNode;
    ASSERT_EQ(write_abort(0x1400, 1, 0x80000000 | (0x200 + n), 4), 0u);
    ASSERT_EQ(write_abort(0x1600, 0, 0, 1), 0u);
    ASSERT_EQ(write_abort(0x1600, 1, mapping(obj::controlword, 0, 16), 4), 0u);
    ASSERT_EQ(write_abort(0x1600, 2, mapping(obj::target_position, 0, 32), 4), 0u);
    ASSERT_EQ(write_abort(0x1600, 0, 2, 1), 0u);
    ASSERT_EQ(write_abort(0x1400, 2, 1, 1), 0u);
    ASSERT_EQ(write_abort(0x1400, 1, 0x200 + n, 4), 0u);
    ASSERT_EQ(write_abort(0x1800, 1, 0x80000000 | (0x180 + n), 4), 0u);
    ASSERT_EQ(write_abort(0x1A00, 0, 0, 1), 0u);
    ASSERT_EQ(write_abort(0x1A00, 1, mapping(obj::statusword, 0, 16), 4), 0u);
    ASSERT_EQ(write_abort(0x1A00, 2, mapping(obj::position_actual, 0, 32), 4), 0u);
    ASSERT_EQ(write_abort(0x1A00, 0, 2, 1), 0u);
    ASSERT_EQ(write_abort(0x1800, 2, 1, 1), 0u);
    ASSERT_EQ(write_abort(0x1800, 1, 0x180 + n, 4), 0u);
  }
  can_frame rpdo(std::uint16_t cw, std::int32_t target) {
    can_frame f{};
    f.can_id = 0x200 + kNode;
    f.len = 6;
    put_le(f.data, cw, 2);
    put_le(f.data + 2, static_cast<std::uint32_t>(target), 4);
    return f;
  }
};

TEST(Cia402Drive, BootsIntoPreOperationalAndAnswersTheDeviceType) {
  Drive d;
  ASSERT_EQ(d.out.size(), 1u);
  EXPECT_EQ(d.out[0].can_id, 0x705u);
  EXPECT_EQ(d.out[0].data[0], 0x00);  // boot-up
  EXPECT_EQ(d.node->nmt_state(), NmtState::pre_operational);
  EXPECT_EQ(d.read(obj::device_type), 0x00020192u);
  EXPECT_EQ(d.read(obj::identity, 0), 4u);
  EXPECT_EQ(d.node->state(), cia402::State::switch_on_disabled);
}

TEST(Cia402Drive, SdoAbortCodes) {
  Drive d;
  EXPECT_EQ(d.write_abort(0x2000, 0, 1, 1), abort_code::no_object);
  EXPECT_EQ(d.write_abort(obj::identity, 9, 1, 4), abort_code::no_subindex);
  EXPECT_EQ(d.write_abort(obj::statusword, 0, 1, 2), abort_code::read_only);
  EXPECT_EQ(d.write_abort(obj::heartbeat_time, 0, 10, 4), abort_code::length_mismatch);
  EXPECT_EQ(d.write_abort(obj::modes_of_operation, 0, 1, 1), abort_code::value_range);
  EXPECT_EQ(d.write_abort(0x1400, 2, 250, 1), abort_code::value_range);
  const Sdo s = d.sdo(sdo_upload(kNode, 0x2000, 0));
  EXPECT_EQ(s.kind, SdoKind::abort);
  EXPECT_EQ(s.value, abort_code::no_object);
  can_frame segmented = sdo_download(kNode, 0x1017, 0, 0, 4);
  segmented.data[0] = 0x21;
  EXPECT_EQ(d.sdo(segmented).value, abort_code::command_specifier);
}

TEST(Cia402Drive, PdoMappingRules) {
  Drive d;
  // Still valid: mapping cannot change.
  EXPECT_EQ(d.write_abort(0x1600, 0, 0, 1), abort_code::device_state);
  ASSERT_EQ(d.write_abort(0x1400, 1, 0x80000205, 4), 0u);
  // Sub-index 0 must be 0 before entries change.
  EXPECT_EQ(d.write_abort(0x1600, 1, mapping(obj::target_position, 0, 32), 4),
            abort_code::device_state);
  ASSERT_EQ(d.write_abort(0x1600, 0, 0, 1), 0u);
  EXPECT_EQ(d.write_abort(0x1600, 1, mapping(obj::statusword, 0, 16), 4), abort_code::not_mappable);
  EXPECT_EQ(d.write_abort(0x1600, 1, mapping(0x2222, 0, 16), 4), abort_code::no_object);
  EXPECT_EQ(d.write_abort(0x1600, 1, mapping(obj::target_position, 0, 16), 4),
            abort_code::length_mismatch);
  for (std::uint8_t s = 1; s <= 3; ++s) {
    ASSERT_EQ(d.write_abort(0x1600, s, mapping(obj::target_position, 0, 32), 4), 0u);
  }
  EXPECT_EQ(d.write_abort(0x1600, 0, 3, 1), abort_code::pdo_length);  // 96 bits
  EXPECT_EQ(d.write_abort(0x1600, 0, 2, 1), 0u);
}

TEST(Cia402Drive, SyncRpdoTpdoAndTheStateMachineToOperationEnabled) {
  Drive d;
  d.map_csp();
  const auto actual = static_cast<std::int32_t>(d.read(obj::position_actual));
  EXPECT_TRUE(d.send(nmt(NmtCommand::start, kNode)).empty());
  EXPECT_EQ(d.node->nmt_state(), NmtState::operational);
  const std::uint16_t steps[] = {cia402::cw::shutdown, cia402::cw::switch_on,
                                 cia402::cw::enable_operation};
  const cia402::State expected[] = {cia402::State::ready_to_switch_on, cia402::State::switched_on,
                                    cia402::State::operation_enabled};
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(d.send(d.rpdo(steps[i], actual)).empty());
    EXPECT_NE(d.node->state(), expected[i]);  // applied only at SYNC
    const FrameList tpdo = d.send(sync());
    ASSERT_EQ(tpdo.size(), 1u);
    EXPECT_EQ(tpdo[0].can_id, 0x185u);
    EXPECT_EQ(tpdo[0].len, 6);
    EXPECT_EQ(cia402::decode_statusword(static_cast<std::uint16_t>(get_le(tpdo[0].data, 2))),
              expected[i]);
    EXPECT_EQ(static_cast<std::int32_t>(get_le(tpdo[0].data + 2, 4)), actual);
  }
  // Moves toward a new target.
  d.send(d.rpdo(cia402::cw::enable_operation, actual + 5000));
  d.send(sync());
  d.now += 200 * kMs;
  const FrameList tpdo = d.send(sync());
  EXPECT_NEAR(static_cast<std::int32_t>(get_le(tpdo[0].data + 2, 4)), actual + 5000, 20);
  // Quick stop, then back via transition 16.
  d.send(d.rpdo(cia402::cw::quick_stop, actual + 5000));
  d.send(sync());
  EXPECT_EQ(d.node->state(), cia402::State::quick_stop_active);
  d.send(d.rpdo(cia402::cw::enable_operation, actual + 5000));
  d.send(sync());
  EXPECT_EQ(d.node->state(), cia402::State::operation_enabled);
}

// The drive's firmware through every transition of the CiA 402 state
// machine, each commanded by an RPDO and applied at the next SYNC, checked
// in the statusword of the TPDO that SYNC produces (transitions 0 and 1 are
// the boot into Switch On Disabled; 13 and 14 follow a fault).
TEST(Cia402Drive, EveryTransitionThroughRpdoAndSync) {
  using cia402::State;
  namespace cw = cia402::cw;
  Drive d;
  d.map_csp();
  EXPECT_EQ(d.node->state(), State::switch_on_disabled);  // 0 and 1 at boot
  const auto actual = static_cast<std::int32_t>(d.read(obj::position_actual));
  d.send(nmt(NmtCommand::start, kNode));
  std::uint16_t last = 0;
  // Sends one controlword, SYNCs, and returns the state the TPDO reports.
  auto step = [&](std::uint16_t controlword) {
    d.send(d.rpdo(controlword, actual));
    last = controlword;
    const FrameList r = d.send(sync());
    for (const can_frame& f : r) {
      if (f.can_id == 0x180u + kNode) {
        return cia402::decode_statusword(static_cast<std::uint16_t>(get_le(f.data, 2)));
      }
    }
    ADD_FAILURE() << "no TPDO after SYNC";
    return State::not_ready_to_switch_on;
  };
  struct Expect {
    std::uint16_t controlword;
    State state;
    const char* transition;
  };
  const Expect path[] = {
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::disable_voltage, State::switch_on_disabled, "7 (disable voltage)"},
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::quick_stop, State::switch_on_disabled, "7 (quick stop)"},
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::switch_on, State::switched_on, "3"},
      {cw::shutdown, State::ready_to_switch_on, "6"},
      {cw::switch_on, State::switched_on, "3"},
      {cw::disable_voltage, State::switch_on_disabled, "10 (disable voltage)"},
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::switch_on, State::switched_on, "3"},
      {cw::quick_stop, State::switch_on_disabled, "10 (quick stop)"},
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::switch_on, State::switched_on, "3"},
      {cw::enable_operation, State::operation_enabled, "4"},
      {cw::switch_on, State::switched_on, "5"},
      {cw::enable_operation, State::operation_enabled, "4"},
      {cw::shutdown, State::ready_to_switch_on, "8"},
      {cw::enable_operation, State::operation_enabled, "3+4 in one command"},
      {cw::disable_voltage, State::switch_on_disabled, "9"},
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::enable_operation, State::operation_enabled, "3+4 in one command"},
      {cw::quick_stop, State::quick_stop_active, "11"},
      {cw::enable_operation, State::operation_enabled, "16"},
      {cw::quick_stop, State::quick_stop_active, "11"},
      {cw::disable_voltage, State::switch_on_disabled, "12"},
      {cw::shutdown, State::ready_to_switch_on, "2"},
      {cw::enable_operation, State::operation_enabled, "3+4 in one command"},
  };
  for (const Expect& e : path) {
    EXPECT_EQ(step(e.controlword), e.state) << "transition " << e.transition;
  }
  // 13 and 14: a fault in Operation Enabled; the drive reports Fault.
  FrameList emcy_out;
  d.node->set_fault(0x04, d.now, emcy_out);
  EXPECT_EQ(step(last), State::fault) << "transitions 13, 14";
  // Commands other than fault reset leave Fault.
  EXPECT_EQ(step(cw::shutdown), State::fault);
  EXPECT_EQ(step(cw::enable_operation), State::fault);
  // 15: the cause gone, a rising edge of bit 7.
  d.node->set_fault(0, d.now, emcy_out);
  EXPECT_EQ(step(cw::fault_reset), State::switch_on_disabled) << "transition 15";
  // Bit 7 held high is no new reset and no other command: nothing changes.
  EXPECT_EQ(step(cw::fault_reset), State::switch_on_disabled);
  EXPECT_EQ(step(cw::shutdown), State::ready_to_switch_on);
}

TEST(Cia402Drive, HeartbeatProducer) {
  Drive d;
  ASSERT_EQ(d.write_abort(obj::heartbeat_time, 0, 20, 2), 0u);
  int beats = 0;
  for (int ms = 0; ms <= 100; ++ms) {
    d.out.clear();
    d.node->poll(ms * kMs, d.out);
    for (const can_frame& f : d.out) {
      EXPECT_EQ(f.can_id, 0x705u);
      EXPECT_EQ(f.data[0], 0x7F);
      ++beats;
    }
  }
  EXPECT_EQ(beats, 6);  // 0, 20, ..., 100 ms
}

TEST(Cia402Drive, FaultSendsEmcyAndFaultResetClearsIt) {
  Drive d;
  d.map_csp();
  d.send(nmt(NmtCommand::start, kNode));
  FrameList out;
  d.node->set_fault(0x20, d.now, out);  // overload
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].can_id, 0x85u);
  Emcy e;
  ASSERT_TRUE(parse_emcy(out[0], e));
  EXPECT_EQ(e.code, 0x2310);
  EXPECT_EQ(e.error_register, 0x03);  // generic + current
  EXPECT_EQ(d.node->state(), cia402::State::fault);
  EXPECT_EQ(d.read(obj::error_code), 0x2310u);
  // Fault reset while the cause persists: stays in fault.
  d.send(d.rpdo(cia402::cw::fault_reset, 0));
  d.send(sync());
  EXPECT_EQ(d.node->state(), cia402::State::fault);
  // Cause gone: bit 7 must rise again; EMCY error reset.
  d.node->set_fault(0, d.now, out);
  d.send(d.rpdo(0, 0));
  d.send(sync());
  d.send(d.rpdo(cia402::cw::fault_reset, 0));
  const FrameList r = d.send(sync());
  EXPECT_EQ(d.node->state(), cia402::State::switch_on_disabled);
  ASSERT_GE(r.size(), 1u);
  ASSERT_TRUE(parse_emcy(r[0], e));
  EXPECT_EQ(e.code, 0x0000);
}

TEST(Cia402Drive, NmtStopResetAndReboot) {
  Drive d;
  d.map_csp();
  d.send(nmt(NmtCommand::stop, 0));  // all nodes
  EXPECT_EQ(d.node->nmt_state(), NmtState::stopped);
  EXPECT_TRUE(d.send(sdo_upload(kNode, obj::device_type, 0)).empty());  // no SDO when stopped
  EXPECT_TRUE(d.send(sync()).empty());
  d.send(nmt(NmtCommand::enter_pre_operational, kNode));
  EXPECT_EQ(d.node->nmt_state(), NmtState::pre_operational);
  d.send(nmt(NmtCommand::start, 99));  // another node
  EXPECT_EQ(d.node->nmt_state(), NmtState::pre_operational);
  const FrameList boot = d.send(nmt(NmtCommand::reset_communication, kNode));
  ASSERT_EQ(boot.size(), 1u);
  EXPECT_EQ(boot[0].data[0], 0x00);
  EXPECT_EQ(d.read(0x1A00, 0), 1u);  // default mapping again: statusword only
  EXPECT_EQ(d.read(0x1800, 2), 255u);
  FrameList out;
  d.node->reboot(d.now, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].can_id, 0x705u);
  EXPECT_EQ(out[0].data[0], 0x00);
}

TEST(Cia402Drive, ShortRpdoGivesEmcy8210) {
  Drive d;
  d.map_csp();
  d.send(nmt(NmtCommand::start, kNode));
  can_frame f = d.rpdo(cia402::cw::shutdown, 0);
  f.len = 2;
  const FrameList r = d.send(f);
  ASSERT_EQ(r.size(), 1u);
  Emcy e;
  ASSERT_TRUE(parse_emcy(r[0], e));
  EXPECT_EQ(e.code, 0x8210);
}

TEST(MitMotor, MotorModeCommandsAndZero) {
  ActuatorBinding b;
  b.device_id = 3;
  MitMotorOptions m;
  m.ranges = *mit::find_model("ak80-9");
  b.options = m;
  SimBusSettings settings;
  MitMotorNode node(b, 0, settings, 0);
  FrameList out;
  const double start = node.motor_position(0);
  // A command outside motor mode is answered but not obeyed.
  node.handle(mit::pack_command(3, {start + 1.0, 0, 50, 1, 0}, m.ranges), 0, out);
  ASSERT_EQ(out.size(), 1u);
  mit::Reply r;
  ASSERT_TRUE(mit::unpack_reply(out[0], m.ranges, r));
  EXPECT_EQ(r.motor_id, 3);
  EXPECT_EQ(out[0].can_id, 0u);
  EXPECT_NEAR(node.motor_position(kMs * 500), start, 1e-9);
  node.handle(mit::special_frame(3, mit::Special::enter_motor_mode), 0, out);
  EXPECT_TRUE(node.motor_mode());
  node.handle(mit::pack_command(3, {start + 1.0, 0, 50, 1, 0}, m.ranges), 0, out);
  EXPECT_NEAR(node.motor_position(kMs * 1000), start + 1.0, 1e-3);
  node.handle(mit::special_frame(3, mit::Special::exit_motor_mode), kMs * 1000, out);
  EXPECT_FALSE(node.motor_mode());
  node.handle(mit::special_frame(3, mit::Special::set_zero), kMs * 1000, out);
  EXPECT_NEAR(node.motor_position(kMs * 1000), 0.0, 1e-9);
  // Frames for other ids and short frames are ignored.
  out.clear();
  node.handle(mit::special_frame(4, mit::Special::enter_motor_mode), 0, out);
  can_frame short_frame = mit::special_frame(3, mit::Special::enter_motor_mode);
  short_frame.len = 6;
  node.handle(short_frame, 0, out);
  EXPECT_TRUE(out.empty());
  // A fault leaves motor mode and shows in the reply.
  node.handle(mit::special_frame(3, mit::Special::enter_motor_mode), 0, out);
  node.set_fault(6, kMs * 1000, out);
  EXPECT_FALSE(node.motor_mode());
  out.clear();
  node.handle(mit::special_frame(3, mit::Special::enter_motor_mode), kMs * 1000, out);
  ASSERT_TRUE(mit::unpack_reply(out[0], m.ranges, r));
  EXPECT_EQ(r.error, 6);
  EXPECT_FALSE(node.motor_mode());
}

}  // namespace
}  // namespace animrt::sim
