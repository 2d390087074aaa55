#pragma once
// The servos of one simulated Dynamixel bus answering decoded Protocol 2.0
// instruction packets, as the firmware of each servo would. No I/O: the
// status packets go to an Answers list in the order they appear on the wire.
//
// Instructions: Ping (broadcast: every servo answers, in id order), Read,
// Write, Reg Write, Action, Reboot, Factory Reset, Sync Read, Sync Write, Bulk Read, Bulk
// Write, Fast Sync Read, Fast Bulk Read. Clear and unknown instructions answer
// Instruction Error. Reboot keeps EEPROM and clears RAM; Factory Reset
// (option 0xFF, 0x01 or 0x02) restores the EEPROM's factory settings first. A broadcast Read is
// ignored; broadcast Write/Reg Write/Action/Reboot act without answering. Status Return Level is
// respected (Ping always answers; a write that changes the level is answered per the level it
// arrived under). Sync and Bulk instructions are obeyed only with the broadcast id. A servo that is
// not responding ignores every packet. A write to ID takes effect at once (its status packet
// already carries the new ID).
//
// Fast Sync Read and Fast Bulk Read (servos whose model and firmware support
// them; see dxl::supports_fast_read) answer with one combined status packet:
// the first servo that answers sends the header, whose LEN counts every
// servo asked, and each servo appends its slice (error, id, data, CRC of the
// packet so far). A servo with an error number still sends a full-length
// slice, its data zero.
//
// Simplification: on a real bus each servo of a Sync/Bulk Read waits for the
// previous one's status packet; here a servo that does not respond is simply
// skipped and the next one answers at once. For a fast read that means the
// packet comes out shorter than its LEN by the silent servo's slice, and the
// later slices' CRCs cover what was actually sent. (The manual does not say
// what real servos do then; a master must not rely on either outcome, and
// ours reads what arrived slice by slice.)

#include <cstdint>
#include <span>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/sim/dynamixel_servo.hpp"
#include "animrt/sim/servo_answers.hpp"

namespace animrt::sim {

// Whether the protocol lets any servo answer this packet: broadcast packets
// other than Ping, Sync Read and Bulk Read never get an answer.
bool may_answer(const dxl::Packet& packet);

class DynamixelFirmware {
 public:
  // One servo per actuator of `config`. Throws InputError for a device id
  // outside 0..252 or used twice. With `physics`, every servo takes its
  // motor state from it (see DynamixelServo).
  DynamixelFirmware(const BusConfig& config, Nanos now, JointPhysics* physics = nullptr);

  // Handles one instruction packet at time `now` and appends the answers.
  // Only servos whose baud rate is `line_baud` (the host's; 0: every servo)
  // hear it: to the others it is noise. Servos sharing an ID all act, and
  // their answers collide (collide()); a Fast Sync/Bulk Read takes the
  // first of them only.
  void handle(const dxl::Packet& packet, Nanos now, Answers& out, int line_baud = 0);

  // By the id configured in the BusConfig (not the ID register, which a
  // client may change); nullptr if there is none.
  DynamixelServo* find_configured(int device_id);
  const DynamixelServo* find_configured(int device_id) const;

  std::size_t size() const { return servos_.size(); }
  // The index-th servo of the BusConfig; std::out_of_range past the end.
  DynamixelServo& at(std::size_t index) { return servos_.at(index); }

 private:
  DynamixelServo* target(std::uint8_t id);  // first responding servo with this ID register
  // Each responding servo with this ID acts (and may answer); their answers
  // collide.
  template <class Act>
  void for_id(std::uint8_t id, Answers& out, Act&& act);
  void answer(const DynamixelServo& servo, dxl::StatusError error,
              std::span<const std::uint8_t> data, Answers& out) const;
  void answer_read(const DynamixelServo& servo, std::uint16_t address, std::uint16_t length,
                   Answers& out) const;
  void answer_fast(std::span<const dxl::BulkReadEntry> entries, Answers& out);
  void ping(const dxl::Packet& packet, Answers& out);
  void factory_reset(const dxl::Packet& packet, Nanos now, Answers& out);

  std::vector<DynamixelServo> servos_;
  std::vector<DynamixelServo*> by_id_;  // scratch for broadcast ping
  std::vector<dxl::BulkReadEntry> fast_entries_;
};

}  // namespace animrt::sim
