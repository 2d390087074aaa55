#include "animrt/sim/maestro/maestro_sim_bus.hpp"

#include <poll.h>
#include <unistd.h>

#include <any>
#include <array>
#include <cerrno>
#include <stdexcept>

#include "animrt/bridge/maestro/maestro_bus.hpp"
#include "animrt/core/error.hpp"

namespace animrt::sim {

MaestroSimBus::MaestroSimBus(const BusConfig& config, const Clock& clock)
    : config_(config),
      clock_(clock),
      pty_("simulated bus '" + elide(config.name) + "'"),
      lockstep_(dynamic_cast<const ManualClock*>(&clock) != nullptr),
      last_time_(clock.now()) {
  MaestroBusOptions options;
  if (const auto* o = std::any_cast<MaestroBusOptions>(&config_.options)) options = *o;
  std::map<int, std::vector<MaestroChannelSetup>> per_board;
  for (const ActuatorBinding& b : config_.actuators) {
    MaestroChannelOptions ch;
    if (const auto* o = std::any_cast<MaestroChannelOptions>(&b.options)) ch = *o;
    const int device = options.form == maestro::Form::compact ? maestro::kDefaultDevice : ch.device;
    per_board[device].push_back(MaestroChannelSetup{ch.channel, ch.min_us, ch.max_us});
  }
  boards_.reserve(per_board.size());
  for (const auto& [device, setup] : per_board) {
    boards_.emplace_back(device, options.channels, setup, clock.now());
    // The robot file says what the board's settings hold.
    boards_.back().set_serial_timeout(static_cast<Nanos>(options.serial_timeout_ms * 1e6));
  }
  answers_.reserve(4096);
  if (lockstep_) line_ = std::make_shared<LockstepLine>();
}

MaestroSimBus::~MaestroSimBus() { stop(); }

std::string MaestroSimBus::describe() const { return "serial " + config_.name + " " + endpoint(); }

void MaestroSimBus::start() {
  if (thread_.joinable()) return;
  wake_.drain();
  stop_ = false;
  if (line_) line_->device_serving(true);
  thread_ = std::thread([this] { serve(); });
}

void MaestroSimBus::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  wake_.wake();
  thread_.join();
  if (line_) line_->device_serving(false);
}

void MaestroSimBus::serve() {
  std::array<std::uint8_t, 1024> buffer{};
  while (!stop_.load()) {
    pollfd fds[2] = {{pty_.master(), POLLIN, 0}, {wake_.read_fd(), POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[1].revents != 0) break;
    if (fds[0].revents & POLLIN) {
      const ssize_t n = ::read(pty_.master(), buffer.data(), buffer.size());
      if (n > 0) {
        process(buffer.data(), static_cast<std::size_t>(n));
        if (line_) line_->device_took(static_cast<std::size_t>(n));
        continue;
      }
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    }
    ::poll(&fds[1], 1, 10);
  }
}

void MaestroSimBus::process(const std::uint8_t* bytes, std::size_t n) {
  answers_.clear();
  {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < n; ++i) {
      const maestro::ParseResult r = parser_.feed(bytes[i]);
      if (r == maestro::ParseResult::need_more) continue;
      if (r == maestro::ParseResult::protocol_error) {
        ++protocol_errors_;
        const Nanos now = lockstep_ ? last_time_ : clock_.now();
        for (MaestroBoard& b : boards_) {
          if (b.responding()) b.protocol_error(now);
        }
        continue;
      }
      const maestro::Command& c = parser_.command();
      const bool answered = c.command == maestro::cmd::get_position ||
                            c.command == maestro::cmd::get_errors ||
                            c.command == maestro::cmd::get_moving_state;
      Nanos now = clock_.now();
      if (lockstep_ && !answered) now = last_time_;
      last_time_ = now;
      for (MaestroBoard& b : boards_) {
        if (!b.responding()) continue;
        if (c.pololu_form && c.device != b.device_number()) continue;
        b.handle(c, now, answers_);
        ++commands_;
      }
    }
  }
  std::size_t done = 0;
  while (done < answers_.size()) {
    const ssize_t w = ::write(pty_.master(), answers_.data() + done, answers_.size() - done);
    if (w > 0) {
      done += static_cast<std::size_t>(w);
      if (line_) line_->device_wrote(static_cast<std::size_t>(w));
    } else if (w < 0 && errno == EAGAIN) {
      pollfd fd{pty_.master(), POLLOUT, 0};
      if (::poll(&fd, 1, 200) <= 0) break;  // the client stopped reading
    } else if (!(w < 0 && errno == EINTR)) {
      break;
    }
  }
}

MaestroSimBus::Where MaestroSimBus::find(int device_id) const {
  for (const ActuatorBinding& b : config_.actuators) {
    if (b.device_id != device_id) continue;
    const auto& ch = std::any_cast<const MaestroChannelOptions&>(b.options);
    const auto* options = std::any_cast<MaestroBusOptions>(&config_.options);
    const int device =
        options && options->form == maestro::Form::pololu ? ch.device : maestro::kDefaultDevice;
    for (const MaestroBoard& board : boards_) {
      if (board.device_number() == device) {
        return Where{const_cast<MaestroBoard*>(&board), ch.channel, &b};
      }
    }
  }
  throw std::out_of_range("no device " + std::to_string(device_id) + " on simulated bus '" +
                          elide(config_.name) + "'");
}

void MaestroSimBus::set_device_responding(int device_id, bool responding) {
  std::lock_guard lock(mutex_);
  find(device_id).board->set_responding(responding);
}

void MaestroSimBus::set_device_hardware_error(int device_id, std::uint8_t error_bits) {
  std::lock_guard lock(mutex_);
  find(device_id).board->raise_errors(error_bits, clock_.now());
}

std::uint16_t MaestroSimBus::pulse(int device_id) const {
  std::lock_guard lock(mutex_);
  const Where w = find(device_id);
  w.board->advance(clock_.now());
  return w.board->position(w.channel);
}

double MaestroSimBus::device_position(int device_id) const {
  const std::uint16_t q = pulse(device_id);
  std::lock_guard lock(mutex_);
  const Where w = find(device_id);
  return w.binding->to_rad(q == 0 ? w.binding->zero_ticks : q);
}

MaestroSimStats MaestroSimBus::stats() const {
  return MaestroSimStats{commands_.load(), protocol_errors_.load()};
}

}  // namespace animrt::sim
