#include "animrt/bridge/can/cia402.hpp"

namespace animrt::cia402 {

const char* to_string(State state) {
  switch (state) {
    case State::not_ready_to_switch_on:
      return "not ready to switch on";
    case State::switch_on_disabled:
      return "switch on disabled";
    case State::ready_to_switch_on:
      return "ready to switch on";
    case State::switched_on:
      return "switched on";
    case State::operation_enabled:
      return "operation enabled";
    case State::quick_stop_active:
      return "quick stop active";
    case State::fault_reaction_active:
      return "fault reaction active";
    case State::fault:
      return "fault";
  }
  return "unknown";
}

const char* to_string(Command command) {
  switch (command) {
    case Command::none:
      return "none";
    case Command::shutdown:
      return "shutdown";
    case Command::switch_on:
      return "switch on";
    case Command::enable_operation:
      return "enable operation";
    case Command::disable_voltage:
      return "disable voltage";
    case Command::quick_stop:
      return "quick stop";
    case Command::fault_reset:
      return "fault reset";
  }
  return "unknown";
}

std::uint16_t state_bits(State state) {
  switch (state) {
    case State::not_ready_to_switch_on:
      return 0x0000;
    case State::switch_on_disabled:
      return 0x0040;
    case State::ready_to_switch_on:
      return 0x0021;
    case State::switched_on:
      return 0x0023;
    case State::operation_enabled:
      return 0x0027;
    case State::quick_stop_active:
      return 0x0007;
    case State::fault_reaction_active:
      return 0x000F;
    case State::fault:
      return 0x0008;
  }
  return 0;
}

State decode_statusword(std::uint16_t sw) {
  // Bits 0-3 and 6 (mask 0x4F) or additionally bit 5 (mask 0x6F), per profile.
  switch (sw & 0x4F) {
    case 0x00:
      return State::not_ready_to_switch_on;
    case 0x40:
      return State::switch_on_disabled;
    case 0x0F:
      return State::fault_reaction_active;
    case 0x08:
      return State::fault;
    default:
      break;
  }
  switch (sw & 0x6F) {
    case 0x21:
      return State::ready_to_switch_on;
    case 0x23:
      return State::switched_on;
    case 0x27:
      return State::operation_enabled;
    case 0x07:
      return State::quick_stop_active;
    default:
      break;
  }
  // Not a defined combination: treat as not ready (the safe reading).
  return State::not_ready_to_switch_on;
}

Command decode_controlword(std::uint16_t c, std::uint16_t previous) {
  if ((c & 0x80) != 0) {
    return (previous & 0x80) == 0 ? Command::fault_reset : Command::none;
  }
  const bool b0 = c & 0x1, b1 = c & 0x2, b2 = c & 0x4, b3 = c & 0x8;
  if (!b1) return Command::disable_voltage;
  if (!b2) return Command::quick_stop;
  if (!b0) return Command::shutdown;
  return b3 ? Command::enable_operation : Command::switch_on;
}

State next_state(State s, Command c, int* transition) {
  auto go = [&](State to, int number) {
    if (transition) *transition = number;
    return to;
  };
  if (transition) *transition = 0;
  switch (s) {
    case State::switch_on_disabled:
      if (c == Command::shutdown) return go(State::ready_to_switch_on, 2);
      break;
    case State::ready_to_switch_on:
      if (c == Command::switch_on) return go(State::switched_on, 3);
      // "Switch on + enable operation" passes through switched on (3, then 4).
      if (c == Command::enable_operation) return go(State::operation_enabled, 4);
      if (c == Command::disable_voltage || c == Command::quick_stop) {
        return go(State::switch_on_disabled, 7);
      }
      break;
    case State::switched_on:
      if (c == Command::enable_operation) return go(State::operation_enabled, 4);
      if (c == Command::shutdown) return go(State::ready_to_switch_on, 6);
      if (c == Command::disable_voltage || c == Command::quick_stop) {
        return go(State::switch_on_disabled, 10);
      }
      break;
    case State::operation_enabled:
      if (c == Command::switch_on) return go(State::switched_on, 5);
      if (c == Command::shutdown) return go(State::ready_to_switch_on, 8);
      if (c == Command::disable_voltage) return go(State::switch_on_disabled, 9);
      if (c == Command::quick_stop) return go(State::quick_stop_active, 11);
      break;
    case State::quick_stop_active:
      if (c == Command::disable_voltage) return go(State::switch_on_disabled, 12);
      if (c == Command::enable_operation) return go(State::operation_enabled, 16);
      break;
    case State::fault:
      if (c == Command::fault_reset) return go(State::switch_on_disabled, 15);
      break;
    case State::not_ready_to_switch_on:
    case State::fault_reaction_active:
      break;  // automatic transitions only
  }
  return s;
}

std::uint16_t controlword_toward(State s, State goal, std::uint16_t previous) {
  if (goal == State::operation_enabled) {
    switch (s) {
      case State::fault:
        // Bit 7 must rise: send it low first if it was high.
        return (previous & 0x80) ? cw::disable_voltage : cw::fault_reset;
      case State::switch_on_disabled:
      case State::not_ready_to_switch_on:
      case State::fault_reaction_active:
        return cw::shutdown;
      case State::ready_to_switch_on:
        return cw::switch_on;
      case State::switched_on:
      case State::operation_enabled:
        return cw::enable_operation;
      case State::quick_stop_active:
        return cw::disable_voltage;  // through switch on disabled, never straight back
    }
  }
  switch (s) {
    case State::operation_enabled:
      return cw::switch_on;  // disable operation (5)
    case State::switched_on:
      return cw::shutdown;  // (6)
    default:
      return cw::disable_voltage;  // (7), (12) or stay
  }
}

}  // namespace animrt::cia402
