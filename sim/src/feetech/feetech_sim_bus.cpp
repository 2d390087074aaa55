#include "animrt/sim/feetech/feetech_sim_bus.hpp"

#include <poll.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <stdexcept>

#include "animrt/core/error.hpp"

namespace animrt::sim {
namespace {

constexpr int kWriteStallMs = 200;  // a client that stops reading loses answers after this
constexpr int kBitsPerByte = 10;    // start + 8 data + stop
constexpr int kPacketSilenceMs = 5;

void sleep_until_monotonic(Nanos t) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(t % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

}  // namespace

FeetechSimBus::FeetechSimBus(const BusConfig& config, ft::Series series, const Clock& clock)
    : config_(config),
      clock_(clock),
      pty_("simulated bus '" + elide(config.name) + "'"),
      board_(config, series, clock.now()),
      lockstep_(dynamic_cast<const ManualClock*>(&clock) != nullptr),
      last_time_(clock.now()) {
  answers_.bytes.reserve((board_.size() + 1) * ft::kMaxPacket);
  answers_.list.reserve(board_.size() + 1);
}

FeetechSimBus::~FeetechSimBus() { stop(); }

std::string FeetechSimBus::describe() const { return "serial " + config_.name + " " + endpoint(); }

void FeetechSimBus::start() {
  if (thread_.joinable()) return;
  wake_.drain();
  stop_ = false;
  thread_ = std::thread([this] { serve(); });
}

void FeetechSimBus::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  wake_.wake();
  thread_.join();
}

void FeetechSimBus::serve() {
  std::array<std::uint8_t, 1024> buffer{};
  const MonotonicClock wall;
  Nanos last_byte = 0;
  while (!stop_.load()) {
    pollfd fds[2] = {{pty_.master(), POLLIN, 0}, {wake_.read_fd(), POLLIN, 0}};
    const int wait_ms = decoder_.buffered() > 0 ? kPacketSilenceMs : -1;
    const int ready = ::poll(fds, 2, wait_ms);
    if (ready < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (decoder_.buffered() > 0 &&
        (ready == 0 || wall.now() - last_byte > Nanos{kPacketSilenceMs} * 1'000'000)) {
      dropped_partial_ += decoder_.buffered();  // a servo's receive timeout
      decoder_.reset();
    }
    if (ready == 0) continue;
    if (fds[1].revents != 0) break;
    if (fds[0].revents & POLLIN) {
      const ssize_t n = ::read(pty_.master(), buffer.data(), buffer.size());
      if (n > 0) {
        last_byte = wall.now();
        process({buffer.data(), static_cast<std::size_t>(n)}, last_byte);
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    }
    ::poll(&fds[1], 1, 10);  // hangup or error: do not spin
  }
}

void FeetechSimBus::process(std::span<const std::uint8_t> bytes, Nanos arrival) {
  std::size_t fed = 0;
  while (fed < bytes.size()) {
    fed += decoder_.feed(bytes.subspan(fed));
    ft::Packet packet;
    for (;;) {
      const ft::DecodeResult r = decoder_.next(packet);
      if (r == ft::DecodeResult::need_more) break;
      if (r == ft::DecodeResult::bad_checksum) {
        ++bad_checksums_;  // a servo ignores a packet it cannot trust
      } else if (r == ft::DecodeResult::malformed) {
        ++malformed_;
      } else {
        handle(packet, arrival);
      }
    }
  }
}

void FeetechSimBus::handle(const ft::Packet& packet, Nanos arrival) {
  Nanos now = clock_.now();
  if (lockstep_ && !feetech_may_answer(packet)) now = last_time_;
  last_time_ = now;
  answers_.clear();
  {
    std::lock_guard lock(mutex_);
    board_.handle(packet, now, answers_);
  }
  ++packets_;
  if (!config_.sim.wire_time) {
    for (const FeetechAnswers::Answer& a : answers_.list) send(answers_.packet(a));
  } else {
    Nanos t = std::max(arrival, bus_free_) + wire_ns(packet.raw.size());
    for (const FeetechAnswers::Answer& a : answers_.list) {
      t += static_cast<Nanos>(a.return_delay_us) * 1000 + wire_ns(a.size);
      sleep_until_monotonic(t);
      send(answers_.packet(a));
    }
    bus_free_ = t;
  }
  answers_sent_ += answers_.list.size();
}

Nanos FeetechSimBus::wire_ns(std::size_t bytes) const {
  const int baud = std::max(config_.baud, 1);
  return static_cast<Nanos>(bytes) * kBitsPerByte * 1'000'000'000 / baud;
}

void FeetechSimBus::send(std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(pty_.master(), bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) {
      pollfd fds[2] = {{pty_.master(), POLLOUT, 0}, {wake_.read_fd(), POLLIN, 0}};
      if (::poll(fds, 2, kWriteStallMs) > 0 && fds[1].revents == 0 && (fds[0].revents & POLLOUT)) {
        continue;
      }
    }
    break;
  }
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

void FeetechSimBus::set_device_hardware_error(int device_id, std::uint8_t error_bits) {
  std::lock_guard lock(mutex_);
  servo(device_id).set_fault(error_bits, clock_.now());
}

double FeetechSimBus::device_position(int device_id) const {
  std::lock_guard lock(mutex_);
  return servo(device_id).position_rad(clock_.now());
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
  s.packets = packets_;
  s.answers = answers_sent_;
  s.bad_checksums = bad_checksums_;
  s.malformed = malformed_;
  s.partial_packet_bytes = dropped_partial_;
  return s;
}

}  // namespace animrt::sim
