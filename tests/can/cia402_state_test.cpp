// The CiA 402 controlword / statusword state machine through every
// transition, including fault and quick stop, and the master's path to
// Operation Enabled and back from every state.

#include <gtest/gtest.h>

#include "animrt/bridge/can/cia402.hpp"

namespace animrt::cia402 {
namespace {

struct Step {
  State from;
  std::uint16_t controlword;
  State to;
  int transition;
};

TEST(Cia402, StatuswordDecoding) {
  EXPECT_EQ(decode_statusword(0x0000), State::not_ready_to_switch_on);
  EXPECT_EQ(decode_statusword(0x0250), State::switch_on_disabled);  // + remote, voltage
  EXPECT_EQ(decode_statusword(0x0231), State::ready_to_switch_on);
  EXPECT_EQ(decode_statusword(0x0233), State::switched_on);
  EXPECT_EQ(decode_statusword(0x1637), State::operation_enabled);
  EXPECT_EQ(decode_statusword(0x0217), State::quick_stop_active);
  EXPECT_EQ(decode_statusword(0x021F), State::fault_reaction_active);
  EXPECT_EQ(decode_statusword(0x0218), State::fault);
  for (State s : {State::not_ready_to_switch_on, State::switch_on_disabled,
                  State::ready_to_switch_on, State::switched_on, State::operation_enabled,
                  State::quick_stop_active, State::fault_reaction_active, State::fault}) {
    EXPECT_EQ(decode_statusword(state_bits(s) | 0x0210), s) << to_string(s);
  }
}

TEST(Cia402, ControlwordCommands) {
  EXPECT_EQ(decode_controlword(0x06, 0), Command::shutdown);
  EXPECT_EQ(decode_controlword(0x07, 0), Command::switch_on);
  EXPECT_EQ(decode_controlword(0x0F, 0), Command::enable_operation);
  EXPECT_EQ(decode_controlword(0x00, 0), Command::disable_voltage);
  EXPECT_EQ(decode_controlword(0x0D, 0), Command::disable_voltage);  // bit 1 low
  EXPECT_EQ(decode_controlword(0x02, 0), Command::quick_stop);
  EXPECT_EQ(decode_controlword(0x0B, 0), Command::quick_stop);
  EXPECT_EQ(decode_controlword(0x80, 0x00), Command::fault_reset);  // rising edge
  EXPECT_EQ(decode_controlword(0x80, 0x80), Command::none);         // held high: nothing
}

TEST(Cia402, EveryTransition) {
  const Step steps[] = {
      {State::switch_on_disabled, cw::shutdown, State::ready_to_switch_on, 2},
      {State::ready_to_switch_on, cw::switch_on, State::switched_on, 3},
      {State::switched_on, cw::enable_operation, State::operation_enabled, 4},
      {State::operation_enabled, cw::switch_on, State::switched_on, 5},
      {State::switched_on, cw::shutdown, State::ready_to_switch_on, 6},
      {State::ready_to_switch_on, cw::disable_voltage, State::switch_on_disabled, 7},
      {State::ready_to_switch_on, cw::quick_stop, State::switch_on_disabled, 7},
      {State::operation_enabled, cw::shutdown, State::ready_to_switch_on, 8},
      {State::operation_enabled, cw::disable_voltage, State::switch_on_disabled, 9},
      {State::switched_on, cw::disable_voltage, State::switch_on_disabled, 10},
      {State::switched_on, cw::quick_stop, State::switch_on_disabled, 10},
      {State::operation_enabled, cw::quick_stop, State::quick_stop_active, 11},
      {State::quick_stop_active, cw::disable_voltage, State::switch_on_disabled, 12},
      {State::fault, cw::fault_reset, State::switch_on_disabled, 15},
      {State::quick_stop_active, cw::enable_operation, State::operation_enabled, 16},
  };
  for (const Step& s : steps) {
    int transition = -1;
    const State to = next_state(s.from, decode_controlword(s.controlword, 0), &transition);
    EXPECT_EQ(to, s.to) << to_string(s.from) << " + " << s.controlword;
    EXPECT_EQ(transition, s.transition) << to_string(s.from) << " + " << s.controlword;
  }
}

TEST(Cia402, CommandsThatDoNotApplyLeaveTheState) {
  int transition = -1;
  EXPECT_EQ(next_state(State::switch_on_disabled, Command::enable_operation, &transition),
            State::switch_on_disabled);
  EXPECT_EQ(transition, 0);
  EXPECT_EQ(next_state(State::fault, Command::enable_operation), State::fault);
  EXPECT_EQ(next_state(State::fault, Command::shutdown), State::fault);
  EXPECT_EQ(next_state(State::fault_reaction_active, Command::fault_reset),
            State::fault_reaction_active);
  EXPECT_EQ(next_state(State::quick_stop_active, Command::shutdown), State::quick_stop_active);
}

// The master's controlword choices reach the goal from every state within a
// few steps, one transition per SYNC, with the fault reset edge respected.
TEST(Cia402, MasterReachesOperationEnabledAndBackFromEveryState) {
  for (State start : {State::switch_on_disabled, State::ready_to_switch_on, State::switched_on,
                      State::operation_enabled, State::quick_stop_active, State::fault}) {
    for (std::uint16_t previous : {std::uint16_t{0x00}, std::uint16_t{0x80}}) {
      State s = start;
      std::uint16_t last = previous;
      int steps = 0;
      while (s != State::operation_enabled && steps < 8) {
        const std::uint16_t c = controlword_toward(s, State::operation_enabled, last);
        s = next_state(s, decode_controlword(c, last));
        last = c;
        ++steps;
      }
      EXPECT_EQ(s, State::operation_enabled) << "from " << to_string(start);
      EXPECT_LE(steps, 5);
      while (s != State::switch_on_disabled && steps < 16) {
        const std::uint16_t c = controlword_toward(s, State::switch_on_disabled, last);
        s = next_state(s, decode_controlword(c, last));
        last = c;
        ++steps;
      }
      EXPECT_EQ(s, State::switch_on_disabled);
    }
  }
}

}  // namespace
}  // namespace animrt::cia402
