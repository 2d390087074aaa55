// The CAN devices' guards against a dead host, as firmware: the simulated
// CiA 402 drive's heartbeat consumer (1016h) and abort connection option
// code (6007h), and the simulated MIT motor's CAN timeout. All on explicit
// times, so "within the consumer time, and not before" is exact.

#include <gtest/gtest.h>

#include <memory>

#include "animrt/bridge/can/canopen.hpp"
#include "animrt/bridge/can/cia402.hpp"
#include "animrt/bridge/can/mit_codec.hpp"
#include "animrt/sim/can/cia402_drive_node.hpp"
#include "animrt/sim/can/mit_motor_node.hpp"

namespace animrt::sim::guard_test {
using namespace animrt::sim;
namespace {

using namespace canopen;
using cia402::State;
namespace obj = cia402::obj;

constexpr std::uint8_t kNode = 5;
constexpr std::uint8_t kHost = 127;
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
  FrameList poll_at(Nanos t) {
    now = t;
    out.clear();
    node->poll(now, out);
    return out;
  }
  std::uint32_t write_abort(std::uint16_t index, std::uint8_t sub, std::uint32_t v,
                            std::uint8_t size) {
    const FrameList r = send(sdo_download(kNode, index, sub, v, size));
    EXPECT_EQ(r.size(), 1u);
    const Sdo s = r.empty() ? Sdo{} : parse_sdo(r[0]);
    return s.kind == SdoKind::abort ? s.value : 0;
  }
  std::uint32_t read(std::uint16_t index, std::uint8_t sub = 0) {
    const FrameList r = send(sdo_upload(kNode, index, sub));
    EXPECT_EQ(r.size(), 1u);
    return r.empty() ? 0 : parse_sdo(r[0]).value;
  }
  State state_on_the_wire() {
    return cia402::decode_statusword(static_cast<std::uint16_t>(read(obj::statusword)));
  }
  can_frame rpdo(std::uint16_t cw, std::int32_t target) {
    can_frame f{};
    f.can_id = 0x200 + kNode;
    f.len = 6;
    put_le(f.data, cw, 2);
    put_le(f.data + 2, static_cast<std::uint32_t>(target), 4);
    return f;
  }
  // The mapping Cia402Bus writes, NMT start, then the state machine up.
  void enable() {
    const std::uint32_t n = kNode;
    ASSERT_EQ(write_abort(0x1400, 1, 0x80000000 | (0x200 + n), 4), 0u);
    ASSERT_EQ(write_abort(0x1600, 0, 0, 1), 0u);
    ASSERT_EQ(write_abort(0x1600, 1, mapping(obj::controlword, 0, 16), 4), 0u);
    ASSERT_EQ(write_abort(0x1600, 2, mapping(obj::target_position, 0, 32), 4), 0u);
    ASSERT_EQ(write_abort(0x1600, 0, 2, 1), 0u);
    ASSERT_EQ(write_abort(0x1400, 2, 1, 1), 0u);
    ASSERT_EQ(write_abort(0x1400, 1, 0x200 + n, 4), 0u);
    send(nmt(NmtCommand::start, kNode));
    const auto actual = static_cast<std::int32_t>(read(obj::position_actual));
    for (std::uint16_t cw :
         {cia402::cw::shutdown, cia402::cw::switch_on, cia402::cw::enable_operation}) {
      send(rpdo(cw, actual));
      send(sync());
    }
    ASSERT_EQ(node->state(), State::operation_enabled);
  }
  // 6007h and 1016h:01 as Cia402Bus writes them at activate.
  void arm(std::int16_t option, int ms, std::uint8_t producer = kHost) {
    ASSERT_EQ(write_abort(obj::abort_connection_option, 0, static_cast<std::uint16_t>(option), 2),
              0u);
    ASSERT_EQ(
        write_abort(obj::heartbeat_consumer, 1,
                    (static_cast<std::uint32_t>(producer) << 16) | static_cast<unsigned>(ms), 4),
        0u);
  }
  void heartbeat_at(Nanos t, std::uint8_t from = kHost) {
    now = t;
    send(heartbeat(from, NmtState::operational));
  }
};

const Emcy* find_emcy(const FrameList& frames, Emcy& e) {
  for (const can_frame& f : frames) {
    if (f.can_id == 0x080u + kNode && parse_emcy(f, e)) return &e;
  }
  return nullptr;
}

TEST(Cia402DriveGuard, ConsumerAndAbortConnectionObjects) {
  Drive d;
  EXPECT_EQ(d.read(obj::heartbeat_consumer, 0), 1u);  // one consumer entry
  EXPECT_EQ(d.read(obj::heartbeat_consumer, 1), 0u);  // off at power-on
  EXPECT_EQ(d.read(obj::abort_connection_option), 1u);
  EXPECT_EQ(d.write_abort(obj::heartbeat_consumer, 1, 0x007F0032, 4), 0u);
  EXPECT_EQ(d.read(obj::heartbeat_consumer, 1), 0x007F0032u);
  EXPECT_EQ(d.write_abort(obj::heartbeat_consumer, 1, 0x017F0032, 4), abort_code::value_range);
  EXPECT_EQ(d.write_abort(obj::heartbeat_consumer, 1, 0x0032, 2), abort_code::length_mismatch);
  EXPECT_EQ(d.write_abort(obj::heartbeat_consumer, 0, 2, 1), abort_code::read_only);
  EXPECT_EQ(d.write_abort(obj::abort_connection_option, 0, 3, 2), 0u);
  EXPECT_EQ(d.read(obj::abort_connection_option), 3u);
  EXPECT_EQ(d.write_abort(obj::abort_connection_option, 0, 4, 2), abort_code::value_range);
}

TEST(Cia402DriveGuard, StaysEnabledWhileHeartbeatsComeAndQuickStopsAfterTheConsumerTime) {
  Drive d;
  d.enable();
  d.arm(3, 50);
  // Not watching before the first heartbeat.
  EXPECT_TRUE(d.poll_at(400 * kMs).empty());
  EXPECT_EQ(d.node->state(), State::operation_enabled);
  // Heartbeats every 12 ms for a second, polled every millisecond.
  Nanos last = 0;
  for (Nanos t = 500 * kMs; t <= 1500 * kMs; t += kMs) {
    if ((t - 500 * kMs) % (12 * kMs) == 0) {
      d.heartbeat_at(t);
      last = t;
    }
    d.poll_at(t);
    ASSERT_EQ(d.node->state(), State::operation_enabled) << "at " << t / kMs << " ms";
  }
  // Silence: still enabled at exactly the consumer time ...
  EXPECT_TRUE(d.poll_at(last + 50 * kMs).empty());
  EXPECT_EQ(d.node->state(), State::operation_enabled);
  EXPECT_FALSE(d.node->guard_fired());
  // ... and out of Operation Enabled a millisecond later, with EMCY 8130h.
  const FrameList out = d.poll_at(last + 51 * kMs);
  Emcy e;
  ASSERT_NE(find_emcy(out, e), nullptr);
  EXPECT_EQ(e.code, 0x8130);
  EXPECT_EQ(e.error_register, 0x11);                     // generic + communication
  EXPECT_EQ(d.node->state(), State::quick_stop_active);  // 605Ah = 6: stays in quick stop
  EXPECT_EQ(d.state_on_the_wire(), State::quick_stop_active);
  EXPECT_EQ(d.read(obj::error_code), 0x8130u);
  EXPECT_EQ(d.read(obj::error_register), 0x11u);
  EXPECT_TRUE(d.node->guard_fired());
  EXPECT_EQ(d.node->heartbeat_events(), 1u);
  // One event per silence, not one per poll.
  EXPECT_TRUE(d.poll_at(last + 500 * kMs).empty());
}

TEST(Cia402DriveGuard, AbortConnectionOptionChoosesTheReaction) {
  const struct {
    std::int16_t option;
    State after;
  } cases[] = {{1, State::fault}, {2, State::switch_on_disabled}, {3, State::quick_stop_active}};
  for (const auto& c : cases) {
    Drive d;
    d.enable();
    d.arm(c.option, 20);
    d.heartbeat_at(100 * kMs);
    d.poll_at(120 * kMs);
    EXPECT_EQ(d.node->state(), State::operation_enabled) << c.option;
    d.poll_at(121 * kMs);
    EXPECT_EQ(d.node->state(), c.after) << c.option;
  }
  // 605Ah 2 (quick stop ramp, then Switch On Disabled) ends the quick stop.
  Drive d;
  d.enable();
  ASSERT_EQ(d.write_abort(obj::quick_stop_option, 0, 2, 2), 0u);
  d.arm(3, 20);
  d.heartbeat_at(100 * kMs);
  d.poll_at(121 * kMs);
  EXPECT_EQ(d.node->state(), State::switch_on_disabled);
  // 0: reported, no action.
  Drive none;
  none.enable();
  none.arm(0, 20);
  none.heartbeat_at(100 * kMs);
  Emcy e;
  EXPECT_NE(find_emcy(none.poll_at(121 * kMs), e), nullptr);
  EXPECT_EQ(none.node->state(), State::operation_enabled);
}

TEST(Cia402DriveGuard, OnlyTheConfiguredProducerFeedsIt) {
  Drive d;
  d.enable();
  d.arm(3, 50);
  d.heartbeat_at(0);
  for (Nanos t = 10 * kMs; t <= 200 * kMs; t += 10 * kMs) d.heartbeat_at(t, 126);
  d.poll_at(51 * kMs);
  EXPECT_EQ(d.node->state(), State::quick_stop_active);
}

TEST(Cia402DriveGuard, ConsumerTimeZeroDisarms) {
  Drive d;
  d.enable();
  d.arm(3, 50);
  d.heartbeat_at(0);
  ASSERT_EQ(d.write_abort(obj::heartbeat_consumer, 1, 0, 4), 0u);  // a clean deactivate
  d.poll_at(10'000 * kMs);
  EXPECT_EQ(d.node->state(), State::operation_enabled);
  EXPECT_FALSE(d.node->guard_fired());
}

TEST(Cia402DriveGuard, FaultIsResetAtTheNextBringUpAndHeartbeatsClearTheError) {
  Drive d;
  d.enable();
  d.arm(1, 50);
  d.heartbeat_at(0);
  d.poll_at(51 * kMs);
  ASSERT_EQ(d.node->state(), State::fault);
  // The host comes back: fault reset (rising edge of bit 7), error reset EMCY.
  d.heartbeat_at(60 * kMs);
  d.send(d.rpdo(0, 0));
  d.send(sync());
  d.send(d.rpdo(cia402::cw::fault_reset, 0));
  const FrameList out = d.send(sync());
  Emcy e;
  ASSERT_NE(find_emcy(out, e), nullptr);
  EXPECT_EQ(e.code, 0x0000);
  EXPECT_EQ(d.node->state(), State::switch_on_disabled);
  EXPECT_EQ(d.read(obj::error_register), 0u);
  EXPECT_FALSE(d.node->guard_fired());
  const auto actual = static_cast<std::int32_t>(d.read(obj::position_actual));
  for (std::uint16_t cw :
       {cia402::cw::shutdown, cia402::cw::switch_on, cia402::cw::enable_operation}) {
    d.send(d.rpdo(cw, actual));
    d.send(sync());
  }
  EXPECT_EQ(d.node->state(), State::operation_enabled);

  // After a quick stop the error clears when heartbeats resume.
  Drive q;
  q.enable();
  q.arm(3, 50);
  q.heartbeat_at(0);
  q.poll_at(51 * kMs);
  ASSERT_TRUE(q.node->guard_fired());
  q.heartbeat_at(70 * kMs);
  ASSERT_NE(find_emcy(q.out, e), nullptr);
  EXPECT_EQ(e.code, 0x0000);
  EXPECT_EQ(q.read(obj::error_register), 0u);
  EXPECT_FALSE(q.node->guard_fired());
}

// ---- MIT motor -------------------------------------------------------------

struct Motor {
  ActuatorBinding binding;
  MitMotorOptions options;
  std::unique_ptr<MitMotorNode> node;
  FrameList out;

  explicit Motor(int timeout_ms) {
    binding.device_id = 3;
    options.ranges = *mit::find_model("ak80-9");
    binding.options = options;
    node = std::make_unique<MitMotorNode>(binding, 0, SimBusSettings{}, 0, timeout_ms);
  }
  void command(double position, Nanos t) {
    node->handle(mit::pack_command(3, {position, 0, 50, 1, 0}, options.ranges), t, out);
  }
};

TEST(MitMotorGuard, GoesLimpAfterTheCanTimeoutAndNotBefore) {
  Motor m(50);
  const double start = m.node->motor_position(0);
  m.node->handle(mit::special_frame(3, mit::Special::enter_motor_mode), 0, m.out);
  // Commands every 5 ms toward a goal far away, polled every millisecond.
  Nanos last = 0;
  for (Nanos t = 0; t <= 300 * kMs; t += kMs) {
    if (t % (5 * kMs) == 0) {
      m.command(start + 4.0, t);
      last = t;
    }
    m.node->poll(t, m.out);
    ASSERT_FALSE(m.node->timed_out()) << t / kMs << " ms";
  }
  m.node->poll(last + 50 * kMs, m.out);
  EXPECT_FALSE(m.node->timed_out());
  EXPECT_GT(m.node->command().kp, 0.0);
  m.node->poll(last + 51 * kMs, m.out);
  EXPECT_TRUE(m.node->timed_out());
  EXPECT_TRUE(m.node->guard_fired());
  EXPECT_EQ(m.node->command().kp, 0.0);
  EXPECT_EQ(m.node->command().kd, 0.0);
  EXPECT_EQ(m.node->command().torque, 0.0);
  EXPECT_TRUE(m.node->motor_mode());  // limp, still in motor mode
  // It was still on its way to the goal; limp, it no longer drives there.
  const double at_timeout = m.node->motor_position(last + 51 * kMs);
  EXPECT_LT(at_timeout, start + 3.5);
  EXPECT_NEAR(m.node->motor_position(last + 1000 * kMs), at_timeout, 1e-9);
  EXPECT_EQ(m.node->timeouts(), 1u);
  // The next command drives it again.
  m.command(start + 4.0, last + 1000 * kMs);
  EXPECT_FALSE(m.node->timed_out());
  EXPECT_NEAR(m.node->motor_position(last + 3000 * kMs), start + 4.0, 1e-3);
}

TEST(MitMotorGuard, NoTimeoutSetNoLimp) {
  Motor m(0);
  const double start = m.node->motor_position(0);
  m.node->handle(mit::special_frame(3, mit::Special::enter_motor_mode), 0, m.out);
  m.command(start + 1.0, 0);
  m.node->poll(10'000 * kMs, m.out);
  EXPECT_FALSE(m.node->timed_out());
  EXPECT_NEAR(m.node->motor_position(10'000 * kMs), start + 1.0, 1e-3);
}

TEST(MitMotorGuard, OutsideMotorModeThereIsNothingToStop) {
  Motor m(50);
  m.node->poll(10'000 * kMs, m.out);
  EXPECT_FALSE(m.node->timed_out());
}

}  // namespace
}  // namespace animrt::sim::guard_test
