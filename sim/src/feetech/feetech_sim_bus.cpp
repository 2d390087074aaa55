#include "animrt/sim/feetech/feetech_sim_bus.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <stdexcept>

#include "animrt/bridge/feetech/link_codec.hpp"
#include "animrt/core/error.hpp"

namespace animrt::sim {

FeetechSimBus::FeetechSimBus(const BusConfig& config, ft::Series series, const Clock& clock,
                             const ServoStartup& startup)
    : config_(config),
      clock_(clock),
      pty_("simulated bus '" + elide(config.name) + "'"),
      board_(config, series, clock.now()),
      keeper_(startup, config.name),
      any_baud_(startup.any_baud),
      lockstep_(dynamic_cast<const ManualClock*>(&clock) != nullptr),
      last_time_(clock.now()) {
  keeper_.start(board_, clock.now(), [&](FeetechServo& s) { s.factory_reset(clock.now()); });
  line::set_line_baud(pty_.master(), config_.baud);  // until a host sets its own
  answers_.bytes.reserve((board_.size() + 1) * ft::kMaxPacket);
  answers_.list.reserve(board_.size() + 1);
  if (lockstep_) line_ = std::make_shared<LockstepLine>();
}

FeetechSimBus::~FeetechSimBus() {
  stop();
  keeper_.save(board_, true);
}

std::string FeetechSimBus::describe() const { return "serial " + config_.name + " " + endpoint(); }

void FeetechSimBus::start() {
  if (thread_.joinable()) return;
  wake_.drain();
  stop_ = false;
  if (line_) line_->device_serving(true);
  thread_ = std::thread([this] { serve(); });
}

void FeetechSimBus::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  wake_.wake();
  thread_.join();
  if (line_) line_->device_serving(false);
}

void FeetechSimBus::serve() {
  std::array<std::uint8_t, 1024> buffer{};
  line::serve(pty_.master(), wake_.read_fd(), stop_, buffer,
              {[this](std::span<const std::uint8_t> bytes, Nanos arrival) {
                 line::feed(ft::LinkCodec{}, decoder_, bytes, decode_counts_,
                            [&](const ft::Packet& packet) { handle(packet, arrival); });
                 received_bytes_ += bytes.size();
               },
               [this] { return decoder_.buffered() > 0; },
               [this] {
                 dropped_partial_ += decoder_.buffered();  // a servo's receive timeout
                 decoder_.reset();
               }},
              line_.get());
}

void FeetechSimBus::handle(const ft::Packet& packet, Nanos arrival) {
  Nanos now = clock_.now();
  if (lockstep_ && !feetech_may_answer(packet)) now = last_time_;
  last_time_ = now;
  answers_.clear();
  {
    std::lock_guard lock(mutex_);
    board_.handle(packet, now, answers_, any_baud_ ? 0 : line::line_baud(pty_.master()));
    keeper_.save(board_);
  }
  if (!config_.sim.wire_time) {
    for (const FeetechAnswers::Answer& a : answers_.list) send(answers_.packet(a));
  } else {
    Nanos t = std::max(arrival, bus_free_) + wire_ns(packet.raw.size());
    for (const FeetechAnswers::Answer& a : answers_.list) {
      t += static_cast<Nanos>(a.return_delay_us) * 1000 + wire_ns(a.size);
      line::sleep_until_monotonic(t);
      send(answers_.packet(a));
    }
    bus_free_ = t;
  }
  answers_sent_ += answers_.list.size();
  ++packets_;  // once answered: a client that sees the count sees the answers too
}

Nanos FeetechSimBus::wire_ns(std::size_t bytes) const { return line::wire_ns(bytes, config_.baud); }

void FeetechSimBus::send(std::span<const std::uint8_t> bytes) {
  const std::size_t written = line::write_all(pty_.master(), wake_.read_fd(), bytes);
  if (line_) line_->device_wrote(written);
}

FeetechServo& FeetechSimBus::servo(int device_id) {
  FeetechServo* s = board_.find_configured(device_id);
  if (s == nullptr) {
    throw std::out_of_range("no device " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config_.name) + "'");
  }
  return *s;
}

const FeetechServo& FeetechSimBus::servo(int device_id) const {
  return const_cast<FeetechSimBus*>(this)->servo(device_id);
}

void FeetechSimBus::set_device_responding(int device_id, bool responding) {
  std::lock_guard lock(mutex_);
  servo(device_id).set_responding(responding);
}

void FeetechSimBus::inject_device_health(int device_id, const SimHealthInjection& change) {
  std::lock_guard lock(mutex_);
  FeetechServo& s = servo(device_id);
  const Nanos now = clock_.now();
  s.advance(now);
  using Kind = SimHealthInjection::Kind;
  switch (change.kind) {
    case Kind::temperature:
      s.health().set_temperature(change.value);
      break;
    case Kind::blocked:
      s.health().set_blocked(change.value != 0.0);
      break;
    case Kind::supply:
      s.health().set_supply(change.value);
      break;
    case Kind::hardware_error:
      s.set_fault(static_cast<std::uint8_t>(change.value), now);
      return;
  }
  s.advance(now + 1);
}

void FeetechSimBus::set_device_hardware_error(int device_id, std::uint8_t error_bits) {
  std::lock_guard lock(mutex_);
  servo(device_id).set_fault(error_bits, clock_.now());
}

double FeetechSimBus::device_position(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo(device_id).position_rad(clock_.now());
}

void FeetechSimBus::hand_move(int device_id, std::int32_t ticks) {
  std::lock_guard lock(mutex_);
  if (!servo(device_id).hand_move(ticks, clock_.now())) throw std::logic_error("torque is on");
}

SimulatedBus::ServoReadout FeetechSimBus::servo_readout(int device_id) const {
  std::lock_guard lock(mutex_);
  const FeetechServo& s = servo(device_id);
  return {s.present_steps(clock_.now()), s.torque_on(), s.id(), s.baud()};
}

void FeetechSimBus::set_device_plugged(std::size_t index, bool plugged) {
  std::lock_guard lock(mutex_);
  if (index >= board_.size()) {
    throw std::out_of_range("no device #" + std::to_string(index) + " on simulated bus '" +
                            elide(config_.name) + "' (it has " + std::to_string(board_.size()) +
                            ")");
  }
  board_.at(index).set_plugged(plugged, clock_.now());
}

std::uint64_t FeetechSimBus::device_goals_received(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo(device_id).goals_received();
}

std::int32_t FeetechSimBus::device_last_goal(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo(device_id).last_goal();
}

FeetechSimStats FeetechSimBus::stats() const {
  FeetechSimStats s;
  s.received_bytes = received_bytes_;
  s.packets = packets_;
  s.answers = answers_sent_;
  s.bad_checksums = decode_counts_.bad_checks;
  s.malformed = decode_counts_.malformed;
  s.partial_packet_bytes = dropped_partial_;
  return s;
}

}  // namespace animrt::sim
