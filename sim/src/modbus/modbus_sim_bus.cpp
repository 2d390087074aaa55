#include "animrt/sim/modbus/modbus_sim_bus.hpp"

#include <arpa/inet.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <any>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "animrt/core/error.hpp"
#include "animrt/sim/dynamixel_servo.hpp"
#include "animrt/sim/maestro/pty_pair.hpp"
#include "animrt/sim/modbus/modbus_frame.hpp"
#include "animrt/sim/servo_health_model.hpp"

namespace animrt::sim {
namespace {

constexpr Nanos kStep = 1'000'000;  // motor integration step: 1 ms
// The fault code of the drive's own overtemperature trip: the CiA 402 code
// for excess drive temperature, which many Modbus drives report too.
constexpr std::uint16_t kOvertemperatureCode = 0x4310;
// A trip is cleared by a fault reset only this far below the trip.
constexpr double kTripHysteresisC = 5.0;

void sleep_us(int us) {
  if (us <= 0) return;
  timespec ts{us / 1'000'000, static_cast<long>(us % 1'000'000) * 1000};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

}  // namespace

struct ModbusSimBus::Joint {
  const ActuatorBinding* binding = nullptr;
  ModbusJointOptions options;
  double position = 0.0;  // joint rad
  double goal = 0.0;
  ServoHealthModel health;  // its motor's current, temperature, supply
};

struct ModbusSimBus::Drive {
  int slave = 0;
  std::vector<Joint> joints;
  modbus_mapping_t* mapping = nullptr;
  bool responding = true;
  // Its next `late_answers` answers (-1: all) leave `late_us` later than
  // the return delay, as from a drive busy with other work.
  int late_answers = 0;
  int late_us = 0;
  std::uint16_t faults = 0;
  std::uint16_t fault_code = 0;  // the health section's fault code (injected)
  // The firmware's own overtemperature trip: output off, latched until a
  // fault reset (the enable written off, then on) once the drive cooled.
  bool tripped = false;
  bool enabled = false;
  bool commanded = false;  // the enable as last written
  Nanos time = 0;
  // The communication timeout: the register (if a map names one), the time
  // it allows (0: off) and when the drive last heard a request.
  const modbus::Watchdog* watchdog = nullptr;
  Nanos guard = 0;
  Nanos last_request = 0;
  ~Drive() {
    if (mapping) modbus_mapping_free(mapping);
  }
};

ModbusSimBus::ModbusSimBus(const BusConfig& config, const Clock& clock)
    : config_(config), clock_(clock), wake_(std::make_unique<WakePipe>()) {
  const auto* bus_options = std::any_cast<ModbusBusOptions>(&config_.options);
  tcp_ = bus_options == nullptr || bus_options->tcp;
  const Nanos now = clock.now();
  for (const ActuatorBinding& b : config_.actuators) {
    const auto& o = std::any_cast<const ModbusJointOptions&>(b.options);
    Drive* d = drive(o.slave);
    if (d == nullptr) {
      drives_.push_back(std::make_unique<Drive>());
      d = drives_.back().get();
      d->slave = o.slave;
      d->time = now;
    }
    if (o.map->watchdog.configured && d->watchdog == nullptr) d->watchdog = &o.map->watchdog;
    Joint j;
    j.binding = &b;
    j.options = o;
    j.position = j.goal = initial_offset_rad(o.slave + static_cast<int>(d->joints.size()));
    j.health = ServoHealthModel(config_.sim.health, o.slave, now);
    d->joints.push_back(j);
  }
  for (auto& dp : drives_) {
    Drive& d = *dp;
    int hold_lo = 1 << 20, hold_hi = 0, in_lo = 1 << 20, in_hi = 0, coil_lo = 1 << 20, coil_hi = 0;
    bool any_enable = false;
    for (const Joint& j : d.joints) {
      for (const auto& [table, span] : j.options.map->spans()) {
        int& lo = table == modbus::Table::holding ? hold_lo : in_lo;
        int& hi = table == modbus::Table::holding ? hold_hi : in_hi;
        lo = std::min(lo, span.first);
        hi = std::max(hi, span.second);
      }
      const modbus::Enable& e = j.options.map->enable;
      if (e.configured) any_enable = true;
      if (e.configured && e.coil) {
        coil_lo = std::min(coil_lo, e.address);
        coil_hi = std::max(coil_hi, e.address + 1);
      }
    }
    d.enabled = !any_enable;
    const auto n = [](int lo, int hi) { return hi > lo ? hi - lo : 0; };
    d.mapping = modbus_mapping_new_start_address(
        static_cast<unsigned>(n(coil_lo, coil_hi) ? coil_lo : 0),
        static_cast<unsigned>(n(coil_lo, coil_hi)), 0, 0,
        static_cast<unsigned>(n(hold_lo, hold_hi) ? hold_lo : 0),
        static_cast<unsigned>(n(hold_lo, hold_hi)),
        static_cast<unsigned>(n(in_lo, in_hi) ? in_lo : 0), static_cast<unsigned>(n(in_lo, in_hi)));
    if (d.mapping == nullptr)
      throw DeviceError("simulated bus '" + elide(config_.name) + "': modbus mapping");
    for (Joint& j : d.joints) {
      const modbus::RegisterMap& m = *j.options.map;
      j.options.map->goal.encode(
          j.options.zero + j.options.per_rad * j.goal,
          d.mapping->tab_registers + (m.goal.address - d.mapping->start_registers));
      if (m.enable.configured) {
        if (m.enable.coil) {
          d.mapping->tab_bits[m.enable.address - d.mapping->start_bits] =
              static_cast<std::uint8_t>(m.enable.off);
        } else {
          d.mapping->tab_registers[m.enable.address - d.mapping->start_registers] = m.enable.off;
        }
      }
    }
    publish(d);
  }

  if (tcp_) {
    ctx_ = modbus_new_tcp("127.0.0.1", 0);
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int yes = 1;
    ::setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = 0;
    socklen_t len = sizeof addr;
    if (listen_fd_ < 0 ||
        ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(listen_fd_, 8) != 0 ||
        ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len) != 0) {
      const int error = errno;
      if (listen_fd_ >= 0) ::close(listen_fd_);
      if (ctx_) modbus_free(ctx_);
      throw DeviceError("simulated bus '" + elide(config_.name) +
                        "': cannot listen on 127.0.0.1: " + std::strerror(error));
    }
    endpoint_ = "127.0.0.1:" + std::to_string(ntohs(addr.sin_port));
  } else {
    pty_ = std::make_unique<PtyPair>("simulated bus '" + elide(config_.name) + "'");
    endpoint_ = pty_->path();
    ctx_ = modbus_new_rtu("/dev/null", std::max(config_.baud, 300), 'N', 8, 1);
    if (ctx_) modbus_set_socket(ctx_, pty_->master());
    if (dynamic_cast<const ManualClock*>(&clock_) != nullptr)
      line_ = std::make_shared<LockstepLine>();
  }
  if (ctx_ == nullptr)
    throw DeviceError("simulated bus '" + elide(config_.name) + "': libmodbus context");
}

ModbusSimBus::~ModbusSimBus() {
  stop();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  if (ctx_) {
    if (tcp_) modbus_set_socket(ctx_, -1);
    modbus_free(ctx_);  // the pty's fd belongs to PtyPair; free does not close it
  }
}

std::string ModbusSimBus::describe() const {
  return std::string(tcp_ ? "modbus-tcp " : "modbus-rtu ") + config_.name + " " + endpoint_;
}

void ModbusSimBus::start() {
  if (thread_.joinable()) return;
  wake_->drain();
  stop_ = false;
  if (line_) line_->device_serving(true);
  thread_ = std::thread([this] { tcp_ ? serve_tcp() : serve_rtu(); });
}

void ModbusSimBus::stop() {
  if (!thread_.joinable()) return;
  stop_ = true;
  wake_->wake();
  thread_.join();
  if (line_) line_->device_serving(false);
  for (int fd : clients_) ::close(fd);
  clients_.clear();
  client_rx_.clear();
}

ModbusSimBus::Drive* ModbusSimBus::drive(int slave) {
  for (auto& d : drives_) {
    if (d->slave == slave) return d.get();
  }
  return nullptr;
}

void ModbusSimBus::advance(Drive& d, Nanos now) {
  const double tau = config_.sim.time_constant_s;
  const double vmax = config_.sim.max_speed_rad_s;
  const auto integrate = [&](Nanos until) {
    for (; d.time + kStep <= until; d.time += kStep) {
      const bool on = d.enabled && !d.faults && !d.fault_code && !d.tripped;
      const double dt = to_seconds(kStep);
      for (Joint& j : d.joints) {
        // A blocked joint stays where it is and draws its stall current.
        const double v = on && !j.health.blocked()
                             ? std::clamp((j.goal - j.position) / std::max(tau, dt), -vmax, vmax)
                             : 0.0;
        j.position += v * dt;
        j.health.advance(d.time + kStep, v, on);
        d.fault_code = static_cast<std::uint16_t>(d.fault_code | j.health.injected_bits());
        if (j.health.temperature_c() > config_.sim.health.trip_c) d.tripped = true;
      }
    }
  };
  // The communication timeout ran out: the drive disables its output from
  // that moment (the enable reads off until the host switches it on again).
  if (d.guard > 0 && d.enabled && now - d.last_request > d.guard) {
    integrate(d.last_request + d.guard);
    d.enabled = false;
    d.commanded = false;
    for (const Joint& j : d.joints) {
      const modbus::Enable& e = j.options.map->enable;
      if (!e.configured) continue;
      if (e.coil) {
        d.mapping->tab_bits[e.address - d.mapping->start_bits] = static_cast<std::uint8_t>(e.off);
      } else {
        d.mapping->tab_registers[e.address - d.mapping->start_registers] = e.off;
      }
    }
  }
  integrate(now);
}

void ModbusSimBus::publish(Drive& d) {
  for (Joint& j : d.joints) {
    const modbus::RegisterMap& m = *j.options.map;
    std::uint16_t* tab =
        m.present.table == modbus::Table::holding
            ? d.mapping->tab_registers + (m.present.address - d.mapping->start_registers)
            : d.mapping->tab_input_registers +
                  (m.present.address - d.mapping->start_input_registers);
    m.present.encode(j.options.zero + j.options.per_rad * j.position, tab);
    if (m.has_status) {
      std::uint16_t* st =
          m.status.table == modbus::Table::holding
              ? d.mapping->tab_registers + (m.status.address - d.mapping->start_registers)
              : d.mapping->tab_input_registers +
                    (m.status.address - d.mapping->start_input_registers);
      *st = d.faults;
    }
    publish_health(d, j);
  }
}

void ModbusSimBus::publish_health(Drive& d, Joint& j) {
  const modbus::HealthRegisters& h = j.options.map->health;
  const auto put = [&](const std::optional<modbus::Register>& r, double value) {
    if (!r) return;
    std::uint16_t* tab =
        r->table == modbus::Table::holding
            ? d.mapping->tab_registers + (r->address - d.mapping->start_registers)
            : d.mapping->tab_input_registers + (r->address - d.mapping->start_input_registers);
    r->encode(value, tab);
  };
  put(h.current, j.health.current_a());
  put(h.temperature, j.health.temperature_c());
  put(h.voltage, j.health.voltage_v());
  put(h.fault_code, d.fault_code ? d.fault_code : d.tripped ? kOvertemperatureCode : 0);
}

void ModbusSimBus::handle(const std::uint8_t* req, int length, int offset) {
  ++requests_;
  std::lock_guard lock(mutex_);
  Drive* d = drive(req[offset - 1]);
  if (d == nullptr || !d->responding) return;  // nobody home: the master times out
  const Nanos now = clock_.now();
  advance(*d, now);
  publish(*d);
  d->last_request = now;

  // The drive's own checks of written values, before libmodbus stores them.
  // A write that declares more values than it carries is left to libmodbus,
  // which answers it with an exception.
  const std::size_t pdu_length =
      static_cast<std::size_t>(std::max(0, length - offset - (tcp_ ? 0 : 2)));
  modbus_frame::Write w;
  bool bad_value = false;
  if (modbus_frame::parse_write(req + offset, pdu_length, w)) {
    for (const Joint& j : d->joints) {
      const modbus::RegisterMap& m = *j.options.map;
      const int g0 = m.goal.address, g1 = m.goal.end();
      if (w.address < g1 && g0 < w.address + w.count) {
        std::uint16_t words[2] = {0, 0};
        for (int a = g0; a < g1; ++a) {
          const int rel = a - d->mapping->start_registers;
          words[a - g0] =
              (a >= w.address && a < w.address + w.count)
                  ? w.value(a - w.address)
                  : (rel >= 0 && rel < d->mapping->nb_registers ? d->mapping->tab_registers[rel]
                                                                : 0);
        }
        const double si = m.goal.decode(words);
        if (!std::isfinite(si) || (m.has_range && (si < m.range_min || si > m.range_max)))
          bad_value = true;
      }
      if (m.enable.configured && !m.enable.coil && m.enable.address >= w.address &&
          m.enable.address < w.address + w.count) {
        const std::uint16_t v = w.value(m.enable.address - w.address);
        if (v != m.enable.on && v != m.enable.off) bad_value = true;
      }
    }
  }
  int delay = config_.sim.return_delay_us;
  if (d->late_answers != 0) {
    delay += d->late_us;
    if (d->late_answers > 0) --d->late_answers;
  }
  if (bad_value) {
    sleep_us(delay);
    wrote(modbus_reply_exception(ctx_, req, MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE));
    ++exceptions_;
    return;
  }
  if (!tcp_) modbus_set_slave(ctx_, d->slave);
  sleep_us(delay);
  // libmodbus answers exceptions 2 (illegal address) and 3 (bad quantity) itself.
  wrote(modbus_reply(ctx_, req, length, d->mapping));
  // Read back what was written: goals and enables.
  bool enabled = true, any_enable = false;
  for (Joint& j : d->joints) {
    const modbus::RegisterMap& m = *j.options.map;
    const std::uint16_t* g =
        d->mapping->tab_registers + (m.goal.address - d->mapping->start_registers);
    j.goal = (m.goal.decode(g) - j.options.zero) / j.options.per_rad;
    if (m.enable.configured) {
      any_enable = true;
      const std::uint16_t v =
          m.enable.coil ? d->mapping->tab_bits[m.enable.address - d->mapping->start_bits]
                        : d->mapping->tab_registers[m.enable.address - d->mapping->start_registers];
      enabled = enabled && v == m.enable.on;
    }
  }
  // A fault reset: the enable switched on again, once every motor cooled.
  if (any_enable && enabled && !d->commanded && d->tripped) {
    bool cool = true;
    for (const Joint& j : d->joints)
      cool = cool && j.health.temperature_c() <= config_.sim.health.trip_c - kTripHysteresisC;
    if (cool) d->tripped = false;
  }
  d->commanded = any_enable && enabled;
  d->enabled = !any_enable || enabled;
  if (d->watchdog != nullptr) {
    const std::uint16_t counts =
        d->mapping->tab_registers[d->watchdog->address - d->mapping->start_registers];
    d->guard = static_cast<Nanos>(std::llround(counts * d->watchdog->unit_ms * 1e6));
  }
}

void ModbusSimBus::close_client(std::size_t i) {
  ::close(clients_[i]);
  clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(i));
  client_rx_.erase(client_rx_.begin() + static_cast<std::ptrdiff_t>(i));
}

// Each connection has its own receive buffer: a request is handled once its
// whole ADU (MBAP length) arrived, so a client that sends half a header
// holds up nobody else; one that stays incomplete for kTcpStallMs is closed.
void ModbusSimBus::serve_tcp() {
  std::vector<pollfd> fds;
  const MonotonicClock wall;
  while (!stop_.load()) {
    if (drop_.exchange(false)) {
      while (!clients_.empty()) close_client(clients_.size() - 1);
    }
    fds.clear();
    fds.push_back({wake_->read_fd(), POLLIN, 0});
    fds.push_back({listen_fd_, POLLIN, 0});
    bool partial = false;
    for (std::size_t i = 0; i < clients_.size(); ++i) {
      fds.push_back({clients_[i], POLLIN, 0});
      partial = partial || client_rx_[i].have > 0;
    }
    if (::poll(fds.data(), fds.size(), partial ? kTcpStallMs : -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[0].revents != 0) {
      wake_->drain();
      continue;  // stop or drop: checked at the top
    }
    const Nanos now = wall.now();
    if (fds[1].revents & POLLIN) {
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd >= 0) {
        clients_.push_back(fd);
        client_rx_.emplace_back();
        fds.push_back({fd, 0, 0});  // nothing to read from it in this round
        ++connections_;
      }
    }
    // Clients that keep a request half sent for too long are dropped.
    for (std::size_t i = clients_.size(); i-- > 0;) {
      if (client_rx_[i].have > 0 && fds[i + 2].revents == 0 &&
          now - client_rx_[i].since > Nanos{kTcpStallMs} * 1'000'000) {
        ++dropped_;
        close_client(i);
        fds.erase(fds.begin() + static_cast<std::ptrdiff_t>(i + 2));
      }
    }
    for (std::size_t i = clients_.size(); i-- > 0;) {
      if (fds[i + 2].revents == 0) continue;
      ClientRx& rx = client_rx_[i];
      const ssize_t n =
          ::recv(clients_[i], rx.buf.data() + rx.have, rx.buf.size() - rx.have, MSG_DONTWAIT);
      if (n == 0 || (n < 0 && errno != EAGAIN && errno != EINTR)) {
        close_client(i);
        continue;
      }
      if (n < 0) continue;
      if (rx.have == 0) rx.since = now;
      rx.have += static_cast<std::size_t>(n);
      bool bad = false;
      while (rx.have >= kMbapLength) {
        // MBAP length (big endian): unit id + PDU
        const std::size_t length = static_cast<std::size_t>((rx.buf[4] << 8) | rx.buf[5]);
        const std::size_t total = 6 + length;
        if (length < 2 || total > rx.buf.size()) {
          bad = true;
          break;
        }
        if (rx.have < total) break;
        modbus_set_socket(ctx_, clients_[i]);
        handle(rx.buf.data(), static_cast<int>(total), static_cast<int>(kMbapLength));
        std::memmove(rx.buf.data(), rx.buf.data() + total, rx.have - total);
        rx.have -= total;
        rx.since = now;
      }
      if (bad) {
        ++dropped_;
        close_client(i);
      }
    }
  }
  modbus_set_socket(ctx_, -1);
}

void ModbusSimBus::serve_rtu() {
  std::array<std::uint8_t, 512> buf{};
  std::size_t have = 0;
  const int master = pty_->master();
  // Silence that ends a cut frame: 3.5 characters, at least a few ms here.
  const int gap_ms = 5;
  const MonotonicClock wall;
  Nanos last_byte = 0;
  while (!stop_.load()) {
    pollfd fds[2] = {{master, POLLIN, 0}, {wake_->read_fd(), POLLIN, 0}};
    const int r = ::poll(fds, 2, have > 0 ? gap_ms : -1);
    if (r < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[1].revents != 0) break;
    // Silence inside a frame drops it; so does one this thread slept
    // through (the bytes that came after it start a new frame).
    if (have > 0 && (r == 0 || wall.now() - last_byte > Nanos{gap_ms} * 1'000'000)) {
      dropped_ += have;
      have = 0;
    }
    if (r == 0) continue;
    if (!(fds[0].revents & POLLIN)) {
      ::poll(&fds[1], 1, 10);
      continue;
    }
    const ssize_t n = ::read(master, buf.data() + have, buf.size() - have);
    if (n <= 0) continue;
    last_byte = wall.now();
    have += static_cast<std::size_t>(n);
    for (;;) {
      const int want = modbus_frame::rtu_length(buf.data(), have);
      if (want == 0 || (want > 0 && have < static_cast<std::size_t>(want))) break;
      if (want < 0) {  // unknown function: wait for the silence after it
        break;
      }
      const std::size_t len = static_cast<std::size_t>(want);
      const std::uint16_t crc = modbus_frame::crc16(buf.data(), len - 2);
      if ((buf[len - 2] | (buf[len - 1] << 8)) != crc) {
        ++crc_errors_;  // a drive ignores a frame it cannot trust
      } else {
        handle(buf.data(), static_cast<int>(len), 1);
      }
      std::memmove(buf.data(), buf.data() + len, have - len);
      have -= len;
    }
    if (have == buf.size()) {
      dropped_ += have;
      have = 0;
    }
    // Every byte read is handled: answered, or kept for the rest of its frame.
    if (line_) line_->device_took(static_cast<std::size_t>(n));
  }
}

void ModbusSimBus::wrote(int bytes) {
  if (line_ && bytes > 0) line_->device_wrote(static_cast<std::size_t>(bytes));
}

void ModbusSimBus::set_device_answer_delay(int device_id, Nanos delay_ns, int answers) {
  std::lock_guard lock(mutex_);
  Drive* d = drive(device_id);
  if (!d)
    throw std::out_of_range("no slave " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config_.name) + "'");
  d->late_us = static_cast<int>(delay_ns / 1000);
  d->late_answers = delay_ns > 0 ? answers : 0;
}

void ModbusSimBus::set_device_responding(int device_id, bool responding) {
  std::lock_guard lock(mutex_);
  Drive* d = drive(device_id);
  if (!d)
    throw std::out_of_range("no slave " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config_.name) + "'");
  d->responding = responding;
}

void ModbusSimBus::set_device_hardware_error(int device_id, std::uint8_t error_bits) {
  std::lock_guard lock(mutex_);
  Drive* d = drive(device_id);
  if (!d)
    throw std::out_of_range("no slave " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config_.name) + "'");
  advance(*d, clock_.now());
  d->faults = static_cast<std::uint16_t>(d->faults | error_bits);
  publish(*d);
}

void ModbusSimBus::inject_device_health(int device_id, const SimHealthInjection& change) {
  std::lock_guard lock(mutex_);
  Drive* d = drive(device_id);
  if (!d)
    throw std::out_of_range("no slave " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config_.name) + "'");
  advance(*d, clock_.now());
  using Kind = SimHealthInjection::Kind;
  for (Joint& j : d->joints) {
    switch (change.kind) {
      case Kind::temperature:
        j.health.set_temperature(change.value);
        break;
      case Kind::blocked:
        j.health.set_blocked(change.value != 0.0);
        break;
      case Kind::supply:
        j.health.set_supply(change.value);
        break;
      case Kind::hardware_error:
        d->fault_code = static_cast<std::uint16_t>(change.value);
        break;
    }
  }
  publish(*d);
}

double ModbusSimBus::device_position(int device_id) const {
  std::lock_guard lock(mutex_);
  auto* self = const_cast<ModbusSimBus*>(this);
  Drive* d = self->drive(device_id);
  if (!d)
    throw std::out_of_range("no slave " + std::to_string(device_id) + " on simulated bus '" +
                            elide(config_.name) + "'");
  self->advance(*d, clock_.now());
  return d->joints.front().position;
}

void ModbusSimBus::drop_connections() {
  drop_ = true;
  wake_->wake();
}

ModbusSimStats ModbusSimBus::stats() const {
  return ModbusSimStats{requests_.load(), exceptions_.load(), crc_errors_.load(), dropped_.load(),
                        connections_.load()};
}

}  // namespace animrt::sim
