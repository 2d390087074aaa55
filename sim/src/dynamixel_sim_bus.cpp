#include "animrt/sim/dynamixel_sim_bus.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/prctl.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include "animrt/bridge/dynamixel/link_codec.hpp"
#include "animrt/core/error.hpp"

namespace animrt::sim {
namespace {

[[noreturn]] void fail(const BusConfig& config, const char* what, int error) {
  throw DeviceError("simulated bus '" + elide(config.name) + "': " + what + ": " +
                    std::strerror(error));
}

// Bytes the packet took on the wire, stuffing included.
std::size_t wire_size(const dxl::Packet& packet) {
  std::size_t stuffed = 0;
  int ff_run = packet.instruction == 0xFF ? 1 : 0;
  for (std::uint8_t b : packet.params) {
    if (b == 0xFD && ff_run >= 2) {
      ++stuffed;
      ff_run = 0;
    } else {
      ff_run = b == 0xFF ? ff_run + 1 : 0;
    }
  }
  return 10 + packet.params.size() + stuffed;  // header, id, len, inst, params, crc
}

// By the id of the BusConfig; the ids a test or the CLI knows.
template <typename Firmware>
auto& servo_or_throw(Firmware& firmware, const BusConfig& config, int device_id) {
  auto* servo = firmware.find_configured(device_id);
  if (servo == nullptr) {
    throw std::out_of_range("no device " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config.name) + "'");
  }
  return *servo;
}

}  // namespace

DynamixelSimBus::DynamixelSimBus(const BusConfig& config, const Clock& clock, JointPhysics* physics,
                                 const ServoStartup& startup)
    : config_(config),
      clock_(clock),
      firmware_(config, clock.now(), physics),
      keeper_(startup, config.name),
      physics_(physics),
      any_baud_(startup.any_baud),
      lockstep_(dynamic_cast<const ManualClock*>(&clock) != nullptr),
      last_time_(clock.now()) {
  try {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0) fail(config_, "posix_openpt", errno);
    if (::grantpt(master_) != 0) fail(config_, "grantpt", errno);
    if (::unlockpt(master_) != 0) fail(config_, "unlockpt", errno);
    char name[128];
    if (const int error = ::ptsname_r(master_, name, sizeof(name)); error != 0) {
      fail(config_, "ptsname", error);
    }
    endpoint_ = name;
    slave_ = ::open(endpoint_.c_str(), O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (slave_ < 0) fail(config_, "open pty slave", errno);
    // Raw 8N1 on the line, so no byte is translated or echoed whichever side
    // configures it first.
    termios tio{};
    if (::tcgetattr(slave_, &tio) != 0) fail(config_, "tcgetattr", errno);
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    if (::tcsetattr(slave_, TCSANOW, &tio) != 0) fail(config_, "tcsetattr", errno);
    // At the bus's baud until a host sets its own.
    line::set_line_baud(slave_, config_.baud);
    if (::fcntl(master_, F_SETFL, O_NONBLOCK) != 0) fail(config_, "fcntl", errno);
    if (::pipe2(wake_.data(), O_CLOEXEC | O_NONBLOCK) != 0) fail(config_, "pipe", errno);
  } catch (...) {
    close_fds();
    throw;
  }
  keeper_.start(firmware_, clock.now(),
                [&](DynamixelServo& s) { s.factory_reset(0xFF, clock.now()); });
  const std::size_t most = (firmware_.size() + 1) * dxl::kMaxPacket;
  answers_.bytes.reserve(most);
  answers_.list.reserve(firmware_.size() + 1);
  due_.reserve(firmware_.size() + 1);
  if (lockstep_) line_ = std::make_shared<LockstepLine>();
  // Joined last: a bus whose pty could not be opened never holds the others up.
  if (lockstep_ && physics_ != nullptr) party_ = physics_->join_lockstep();
}

DynamixelSimBus::~DynamixelSimBus() {
  stop();
  close_fds();
  keeper_.save(firmware_, true);
}

void DynamixelSimBus::close_fds() {
  for (int* fd : {&master_, &slave_, &wake_[0], &wake_[1]}) {
    if (*fd >= 0) ::close(*fd);
    *fd = -1;
  }
}

std::string DynamixelSimBus::describe() const { return "serial " + config_.name + " " + endpoint_; }

void DynamixelSimBus::start() {
  if (thread_.joinable()) return;
  std::uint8_t drain[16];
  while (::read(wake_[0], drain, sizeof(drain)) > 0) {
  }
  stop_ = false;
  if (line_) line_->device_serving(true);
  thread_ = std::thread([this] { serve(); });
}

void DynamixelSimBus::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  if (party_ >= 0) physics_->leave_lockstep(party_);
  const std::uint8_t wake = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &wake, 1);
  thread_.join();
  if (line_) line_->device_serving(false);
}

void DynamixelSimBus::serve() {
  // Answers are timed to the microsecond: no timer slack (50 us by default)
  // on this thread's sleeps.
  ::prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
  std::array<std::uint8_t, 4096> buffer{};
  line::serve(master_, wake_[0], stop_, buffer,
              {[this](std::span<const std::uint8_t> bytes, Nanos arrival) {
                 line::feed(dxl::LinkCodec{}, decoder_, bytes, decode_counts_,
                            [&](const dxl::Packet& packet) { handle(packet, arrival); });
                 stray_bytes_ = decoder_.stray_bytes();
                 received_bytes_ += bytes.size();
               },
               [this] { return decoder_.buffered() > 0; },
               [this] {
                 // A packet only partly received: dropped, as a servo's
                 // receive timeout does.
                 dropped_partial_ += decoder_.buffered();
                 decoder_.reset();
               }},
              line_.get());
}

void DynamixelSimBus::handle(const dxl::Packet& packet, Nanos arrival) {
  const std::size_t instruction_bytes = wire_size(packet);
  Nanos now = clock_.now();
  if (lockstep_ && !may_answer(packet)) now = last_time_;
  last_time_ = now;
  if (party_ >= 0) physics_->reach(party_, now);
  answers_.clear();
  {
    std::lock_guard lock(mutex_);
    firmware_.handle(packet, now, answers_, any_baud_ ? 0 : line::line_baud(master_));
    keeper_.save(firmware_);
    if (!hand_paths_.empty()) follow_hand_paths(now);
  }

  if (!config_.sim.wire_time) {
    for (const Answers::Answer& a : answers_.list) {
      if (a.late_ns > 0) line::sleep_until_monotonic(MonotonicClock().now() + a.late_ns);
      send(answers_.packet(a));
    }
  } else {
    // One line: the instruction, then each servo's delay and answer in turn.
    Nanos t = std::max(arrival, bus_free_) + wire_ns(instruction_bytes);
    due_.clear();
    for (const Answers::Answer& a : answers_.list) {
      t += static_cast<Nanos>(a.return_delay_us) * 1000 + a.late_ns + wire_ns(a.size);
      due_.push_back(t);
    }
    bus_free_ = t;
    send_paced();
  }
  answers_sent_ += answers_.list.size();
  // Counted once answered: a client that sees the count sees the answers too.
  if (packet.instruction != dxl::inst::status) ++packets_;
}

void DynamixelSimBus::send_paced() {
  // Each answer leaves when its last byte would have arrived (due_), never
  // sooner. Every wake-up costs the machine far more than a few bytes' wire
  // time, so whatever is due by the time the thread runs goes out in one
  // write, and the thread sleeps again only until the next answer's time.
  const MonotonicClock wall;
  const std::vector<Answers::Answer>& list = answers_.list;
  std::size_t k = 0;
  while (k < list.size()) {
    const Nanos now = wall.now();
    std::size_t end = k;
    while (end < list.size() && due_[end] <= now &&
           (end == k || list[end].offset == list[end - 1].offset + list[end - 1].size)) {
      ++end;
    }
    if (end == k) {
      line::sleep_until_monotonic(due_[k]);
      continue;
    }
    const std::size_t first = list[k].offset;
    send({answers_.bytes.data() + first, list[end - 1].offset + list[end - 1].size - first});
    k = end;
  }
}

Nanos DynamixelSimBus::wire_ns(std::size_t bytes) const {
  return line::wire_ns(bytes, config_.baud);
}

void DynamixelSimBus::send(std::span<const std::uint8_t> bytes) {
  const std::size_t written = line::write_all(master_, wake_[0], bytes);
  if (line_) line_->device_wrote(written);
  dropped_bytes_ += bytes.size() - written;
}

void DynamixelSimBus::set_device_responding(int device_id, bool responding) {
  std::lock_guard lock(mutex_);
  servo_or_throw(firmware_, config_, device_id).set_responding(responding);
}

void DynamixelSimBus::set_device_hardware_error(int device_id, std::uint8_t error_bits) {
  std::lock_guard lock(mutex_);
  servo_or_throw(firmware_, config_, device_id).set_hardware_error(error_bits, clock_.now());
}

void DynamixelSimBus::inject_device_health(int device_id, const SimHealthInjection& change) {
  std::lock_guard lock(mutex_);
  DynamixelServo& servo = servo_or_throw(firmware_, config_, device_id);
  const Nanos now = clock_.now();
  servo.advance(now);
  using Kind = SimHealthInjection::Kind;
  switch (change.kind) {
    case Kind::temperature:
      servo.health().set_temperature(change.value);
      break;
    case Kind::blocked:
      servo.health().set_blocked(change.value != 0.0);
      break;
    case Kind::supply:
      servo.health().set_supply(change.value);
      break;
    case Kind::hardware_error:
      servo.set_hardware_error(static_cast<std::uint8_t>(change.value), now);
      return;
  }
  servo.advance(now);
}

void DynamixelSimBus::set_device_answer_delay(int device_id, Nanos delay_ns, int answers) {
  std::lock_guard lock(mutex_);
  servo_or_throw(firmware_, config_, device_id).set_answer_delay(delay_ns, answers);
}

void DynamixelSimBus::hand_move(int device_id, std::int32_t ticks) {
  hand_path(device_id, {ticks}, 1);
}

void DynamixelSimBus::hand_path(int device_id, const std::vector<std::int32_t>& ticks,
                                int reads_per_step) {
  if (ticks.empty()) throw std::invalid_argument("a hand path needs at least one position");
  if (reads_per_step < 1) throw std::invalid_argument("a hand path needs 1 or more reads a step");
  std::lock_guard lock(mutex_);
  DynamixelServo& s = servo_or_throw(firmware_, config_, device_id);
  if (!s.yields_to_hand()) throw std::logic_error("torque is on");
  if (!s.hand_move(ticks.front(), clock_.now())) {
    throw std::logic_error("the physics model moves this joint");
  }
  // The hand is elsewhere now: a path it was following ends.
  std::erase_if(hand_paths_, [&](const HandPath& p) { return p.device_id == device_id; });
  if (ticks.size() > 1) {
    hand_paths_.push_back({device_id, ticks, 1, reads_per_step, s.position_reads()});
  }
}

void DynamixelSimBus::follow_hand_paths(Nanos now) {
  for (HandPath& p : hand_paths_) {
    DynamixelServo& s = *firmware_.find_configured(p.device_id);
    if (s.position_reads() - p.reads_at_step < static_cast<std::uint64_t>(p.reads_per_step)) {
      continue;
    }
    // Against a torque too strong for a hand the hand lets go: the path ends.
    if (!s.yields_to_hand() || !s.hand_move(p.ticks[p.next], now)) {
      p.next = p.ticks.size();
      continue;
    }
    ++p.next;
    p.reads_at_step = s.position_reads();
  }
  std::erase_if(hand_paths_, [](const HandPath& p) { return p.next >= p.ticks.size(); });
}

SimulatedBus::ServoReadout DynamixelSimBus::servo_readout(int device_id) const {
  std::lock_guard lock(mutex_);
  const DynamixelServo& s = servo_or_throw(firmware_, config_, device_id);
  return {s.present_ticks(clock_.now()), s.torque_on(), s.id(), s.baud()};
}

void DynamixelSimBus::set_device_plugged(std::size_t index, bool plugged) {
  std::lock_guard lock(mutex_);
  if (index >= firmware_.size()) {
    throw std::out_of_range("no device #" + std::to_string(index) + " on simulated bus '" +
                            elide(config_.name) + "' (it has " + std::to_string(firmware_.size()) +
                            ")");
  }
  firmware_.at(index).set_plugged(plugged, clock_.now());
}

std::vector<GoalRecord> DynamixelSimBus::device_goal_log(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo_or_throw(firmware_, config_, device_id).goal_log();
}

std::uint64_t DynamixelSimBus::device_goals_received(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo_or_throw(firmware_, config_, device_id).goals_received();
}

double DynamixelSimBus::device_position(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo_or_throw(firmware_, config_, device_id).position_rad(clock_.now());
}

DynamixelSimStats DynamixelSimBus::stats() const {
  DynamixelSimStats s;
  s.received_bytes = received_bytes_;
  s.packets = packets_;
  s.answers = answers_sent_;
  s.crc_errors = decode_counts_.bad_checks;
  s.malformed = decode_counts_.malformed;
  s.stray_bytes = stray_bytes_;
  s.dropped_bytes = dropped_bytes_;
  s.partial_packet_bytes = dropped_partial_;
  return s;
}

}  // namespace animrt::sim
