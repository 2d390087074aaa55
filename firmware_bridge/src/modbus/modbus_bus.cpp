#include "animrt/bridge/modbus/modbus_bus.hpp"

#include <modbus.h>
#include <sys/socket.h>

#include <algorithm>
#include <any>
#include <cerrno>
#include <cmath>
#include <utility>

#include "animrt/core/error.hpp"
#include "modbus_requests.hpp"

namespace animrt {
namespace {

using std::chrono::steady_clock;
constexpr int kMaxReadWords = 125;   // Read (Holding|Input) Registers
constexpr int kMaxWriteWords = 123;  // Write Multiple Registers
constexpr int kTries = 3;            // lifecycle requests only
constexpr int kMaxFlushReads = 16;   // bounded input flush before a cycle's requests

std::string exception_name(int code) {
  switch (code) {
    case MODBUS_EXCEPTION_ILLEGAL_FUNCTION:
      return "illegal function";
    case MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS:
      return "illegal data address";
    case MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE:
      return "illegal data value";
    case MODBUS_EXCEPTION_SLAVE_OR_SERVER_FAILURE:
      return "slave device failure";
    case MODBUS_EXCEPTION_SLAVE_OR_SERVER_BUSY:
      return "slave device busy";
    case MODBUS_EXCEPTION_GATEWAY_TARGET:
      return "gateway target failed to respond";
    default:
      return "exception " + std::to_string(code);
  }
}

}  // namespace

// Simulated RTU drives on a lockstep clock say when they have answered all
// they will; on a real RTU line late answers are waited out
// (modbus_requests.hpp).
modbus_requests::Line ModbusBus::line(bool urgent) const {
  if (options_.tcp) return {};  // the transaction id tells answers apart
  return {config_.lockstep_line.get(), config_.lockstep_line ? nullptr : late_.get(), urgent};
}

ModbusBus::ModbusBus(BusConfig config)
    : config_(std::move(config)), late_(std::make_unique<modbus_requests::LateAnswers>()) {
  const std::string bus = "bus " + config_.name + ": ";
  if (const auto* o = std::any_cast<ModbusBusOptions>(&config_.options)) options_ = *o;
  const std::size_t n = config_.actuators.size();
  joints_.resize(n);
  book_ = StatusBook(config_, config_.port, "slave");
  present_rad_.assign(n, 0.0);
  goal_rad_.assign(n, 0.0);
  answered_.assign(n, 0);
  off_pending_.assign(n, 0);
  kept_health_.assign(n, DeviceHealth::ok);
  group_slaves(bus);
  // Requests per slave: one read per table over every present/status
  // register, one write per contiguous run of goal registers.
  for (Slave& s : slaves_) {
    plan_reads(s, bus);
    plan_writes(s, bus);
  }
  open_context(bus);
}

void ModbusBus::group_slaves(const std::string& bus) {
  const std::size_t n = config_.actuators.size();
  for (std::size_t i = 0; i < n; ++i) {
    const ActuatorBinding& b = config_.actuators[i];
    const auto* j = std::any_cast<ModbusJointOptions>(&b.options);
    if (j == nullptr || !j->map) throw DeviceError(bus + b.joint + " has no register map");
    joints_[i] = *j;
    auto slave = std::find_if(slaves_.begin(), slaves_.end(),
                              [&](const Slave& s) { return s.id == j->slave; });
    if (slave == slaves_.end()) {
      slaves_.push_back(Slave{});
      slaves_.back().id = j->slave;
      slave = slaves_.end() - 1;
    }
    slave->devices.push_back(i);
  }
}

template <class Pick>
std::vector<ModbusBus::Read> ModbusBus::plan_table_reads(const Slave& s, const std::string& bus,
                                                         Pick&& pick) {
  std::vector<Read> reads;
  for (modbus::Table table : {modbus::Table::holding, modbus::Table::input}) {
    int lo = 1 << 20, hi = -1;
    for (std::size_t d : s.devices) {
      pick(*joints_[d].map, [&](const modbus::Register& r) {
        if (r.table != table) return;
        lo = std::min(lo, r.address);
        hi = std::max(hi, r.end());
      });
    }
    if (hi < 0) continue;
    if (hi - lo > kMaxReadWords) {
      throw DeviceError(bus + "the " + std::string(modbus::to_string(table)) +
                        " registers read from slave " + std::to_string(s.id) + " span " +
                        std::to_string(hi - lo) + " registers, more than one request can read (" +
                        std::to_string(kMaxReadWords) + ")" +
                        (options_.health == ModbusBusOptions::Health::packed
                             ? " (with health: packed; round_robin reads health apart)"
                             : ""));
    }
    Read r;
    r.table = table;
    r.begin = lo;
    r.count = hi - lo;
    r.words.assign(static_cast<std::size_t>(r.count), 0);
    reads.push_back(std::move(r));
  }
  return reads;
}

void ModbusBus::plan_reads(Slave& s, const std::string& bus) {
  using Health = ModbusBusOptions::Health;
  const Health health = options_.health;
  const auto health_registers = [](const modbus::RegisterMap& m, const auto& cover) {
    for (const modbus::Register* r : m.health.list()) cover(*r);
  };
  s.reads = plan_table_reads(s, bus, [&](const modbus::RegisterMap& m, const auto& cover) {
    cover(m.present);
    if (m.has_status) cover(m.status);
    if (health == Health::packed) health_registers(m, cover);
  });
  if (health == Health::round_robin) s.health_reads = plan_table_reads(s, bus, health_registers);
}

void ModbusBus::plan_writes(Slave& s, const std::string& bus) {
  std::vector<std::pair<int, int>> goals;
  for (std::size_t d : s.devices)
    goals.push_back({joints_[d].map->goal.address, joints_[d].map->goal.end()});
  std::sort(goals.begin(), goals.end());
  for (std::size_t k = 0; k < goals.size(); ++k) {
    if (k > 0 && goals[k].first < goals[k - 1].second) {
      throw DeviceError(bus + "two joints on slave " + std::to_string(s.id) +
                        " write the same goal register " + std::to_string(goals[k].first));
    }
    if (!s.writes.empty() && s.writes.back().begin + s.writes.back().count == goals[k].first &&
        s.writes.back().count + (goals[k].second - goals[k].first) <= kMaxWriteWords) {
      s.writes.back().count += goals[k].second - goals[k].first;
    } else {
      Write w;
      w.begin = goals[k].first;
      w.count = goals[k].second - goals[k].first;
      s.writes.push_back(std::move(w));
    }
  }
  for (Write& w : s.writes) w.words.assign(static_cast<std::size_t>(w.count), 0);
}

void ModbusBus::open_context(const std::string& bus) {
  if (options_.tcp) {
    const auto colon = config_.port.rfind(':');
    if (colon == std::string::npos)
      throw DeviceError(bus + "expected HOST:PORT, found " + quote(config_.port));
    host_ = config_.port.substr(0, colon);
    try {
      tcp_port_ = std::stoi(config_.port.substr(colon + 1));
    } catch (...) {
      throw DeviceError(bus + "expected HOST:PORT, found " + quote(config_.port));
    }
    ctx_ = modbus_new_tcp(host_.c_str(), tcp_port_);
  } else {
    ctx_ =
        modbus_new_rtu(config_.port.c_str(), config_.baud, options_.parity, 8, options_.stop_bits);
  }
  if (ctx_ == nullptr) throw DeviceError(bus + "libmodbus: " + modbus_strerror(errno));
  // We reconnect ourselves, with backoff; libmodbus's own recovery sleeps.
  modbus_set_error_recovery(ctx_, MODBUS_ERROR_RECOVERY_NONE);
  const auto us = static_cast<std::uint32_t>(std::ceil(config_.timeout_s * 1e6));
  modbus_set_response_timeout(ctx_, us / 1'000'000, us % 1'000'000);
  modbus_set_byte_timeout(ctx_, us / 1'000'000, us % 1'000'000);
}

ModbusBus::~ModbusBus() {
  if (ctx_ != nullptr) {
    modbus_close(ctx_);
    modbus_free(ctx_);
  }
}

void ModbusBus::disconnect() {
  if (connected_) modbus_close(ctx_);
  connected_ = false;
}

bool ModbusBus::ensure_connected(bool blocking) {
  if (connected_) return true;
  const auto now = steady_clock::now();
  if (!blocking && now < next_attempt_) return false;
  if (modbus_connect(ctx_) == 0) {
    connected_ = true;
    backoff_s_ = 0.0;
    ++reconnects_;
    return true;
  }
  modbus_close(ctx_);
  backoff_s_ = backoff_s_ == 0.0 ? options_.reconnect_min_s
                                 : std::min(2 * backoff_s_, options_.reconnect_max_s);
  next_attempt_ = now + std::chrono::duration_cast<steady_clock::duration>(
                            std::chrono::duration<double>(backoff_s_));
  return false;
}

void ModbusBus::flush_input() {
  if (!options_.tcp) {
    modbus_flush(ctx_);  // RTU: tcflush, bounded
    return;
  }
  // TCP: what is queued now, at most a few ADUs; a peer that keeps sending
  // must not keep the cycle here (libmodbus's flush reads while data comes).
  const int fd = modbus_get_socket(ctx_);
  if (fd < 0) return;
  std::uint8_t sink[MODBUS_TCP_MAX_ADU_LENGTH];
  for (int k = 0; k < kMaxFlushReads; ++k) {
    const ssize_t n = ::recv(fd, sink, sizeof sink, MSG_DONTWAIT);
    if (n <= 0) return;
  }
}

ModbusBus::Failure ModbusBus::classify(int error) const {
  if (error > MODBUS_ENOBASE && error <= EMBXGTAR) return Failure::exception;
  if (error == EMBBADCRC) return Failure::crc;
  if (error == ETIMEDOUT) return Failure::timeout;
  if (error == EMBBADDATA || error == EMBBADEXC || error == EMBUNKEXC || error == EMBMDATA ||
      error == EMBBADSLAVE) {
    return Failure::protocol;
  }
  return Failure::connection;  // ECONNRESET, EPIPE, EBADF, ...: the link is gone
}

ModbusBus::Failure ModbusBus::fail_slave(const Slave& slave, int error) {
  const Failure f = classify(error);
  for (std::size_t d : slave.devices) {
    if (book_.faulted(d)) continue;
    switch (f) {
      case Failure::exception:
        book_.exception(d, static_cast<std::uint8_t>(error - MODBUS_ENOBASE));
        break;
      case Failure::crc:
      case Failure::protocol:
        book_.garbled(d, f == Failure::crc);
        break;
      case Failure::timeout:
      case Failure::connection:
      case Failure::none:
        book_.timed_out(d);
        break;
    }
  }
  if (f == Failure::connection && options_.tcp) {
    disconnect();
    next_attempt_ =
        steady_clock::now() + std::chrono::duration_cast<steady_clock::duration>(
                                  std::chrono::duration<double>(options_.reconnect_min_s));
    backoff_s_ = options_.reconnect_min_s;
  }
  return f;
}

const std::uint16_t* ModbusBus::words_of(const std::vector<Read>& reads,
                                         const modbus::Register& r) {
  for (const Read& rd : reads) {
    if (rd.table == r.table && r.address >= rd.begin && r.end() <= rd.begin + rd.count) {
      return rd.words.data() + (r.address - rd.begin);
    }
  }
  return nullptr;
}

bool ModbusBus::read_slave(Slave& slave, bool count) {
  bool any = false;
  for (std::size_t d : slave.devices) {
    answered_[d] = 0;
    if (book_[d].faulted) continue;
    any = true;
    if (count) book_.asked(d);
  }
  if (!any) return true;
  for (Read& r : slave.reads) {
    if (!connected_) return false;
    modbus_set_slave(ctx_, slave.id);
    ++requests_;
    const int rc = modbus_requests::read_registers(
        ctx_, line(), slave.id, r.table == modbus::Table::input, r.begin, r.count, r.words.data());
    if (rc != r.count) {
      const int error = rc < 0 ? errno : EMBMDATA;
      if (count) {
        fail_slave(slave, error);
      } else if (classify(error) == Failure::connection && options_.tcp) {
        disconnect();
      }
      if (!count)
        book_[slave.devices[0]].last_error_byte =
            classify(error) == Failure::exception
                ? static_cast<std::uint8_t>(error - MODBUS_ENOBASE)
                : 0;
      return false;
    }
  }
  for (std::size_t d : slave.devices) {
    if (book_[d].faulted) continue;
    const modbus::RegisterMap& m = *joints_[d].map;
    const ModbusJointOptions& j = joints_[d];
    present_rad_[d] = (m.present.decode(words_of(slave, m.present)) - j.zero) / j.per_rad;
    answered_[d] = 1;
    std::uint16_t faults = 0;
    if (m.has_status) {
      faults = *words_of(slave, m.status) & m.fault_mask;
      book_[d].hardware_error_status = static_cast<std::uint8_t>(faults & 0xFF);
      if (faults != 0 && count) book_.fault_reported(d);
    }
    book_.answered(d, faults != 0);
    if (options_.health == ModbusBusOptions::Health::packed) take_health(d, slave.reads);
  }
  return true;
}

void ModbusBus::take_health(std::size_t d, const std::vector<Read>& reads) {
  const modbus::HealthRegisters& regs = joints_[d].map->health;
  if (!regs.any()) return;
  HealthReading& h = book_[d].reading;
  const auto value = [&](const std::optional<modbus::Register>& r) {
    const std::uint16_t* w = r ? words_of(reads, *r) : nullptr;
    return w ? r->decode(w) : HealthReading::kNone;
  };
  h.current_a = std::abs(value(regs.current));
  h.temperature_c = value(regs.temperature);
  h.voltage_v = value(regs.voltage);
  if (regs.fault_code) {
    const std::uint16_t* w = words_of(reads, *regs.fault_code);
    h.has_error_bits = w != nullptr;
    h.error_bits = w ? *w : 0u;
  }
  h.read_ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(steady_clock::now().time_since_epoch())
          .count();
  ++h.reads;
}

// One slave's health registers in requests of their own; a lost health
// read is counted, but the cycle's verdict on the device is its position's.
void ModbusBus::read_health_round_robin() {
  for (std::size_t k = 0; k < slaves_.size(); ++k) {
    Slave& s = slaves_[(health_next_ + k) % slaves_.size()];
    if (s.silent || s.health_reads.empty()) continue;
    bool live = false;
    for (std::size_t d : s.devices) live = live || !book_[d].faulted;
    if (!live) continue;
    health_next_ = (health_next_ + k + 1) % slaves_.size();
    for (std::size_t d : s.devices) {
      if (!book_[d].faulted) book_.asked(d);
    }
    for (Read& r : s.health_reads) {
      if (!connected_) return;
      modbus_set_slave(ctx_, s.id);
      ++requests_;
      const int rc = modbus_requests::read_registers(
          ctx_, line(), s.id, r.table == modbus::Table::input, r.begin, r.count, r.words.data());
      if (rc != r.count) {
        for (std::size_t d : s.devices) kept_health_[d] = book_[d].health;
        fail_slave(s, rc < 0 ? errno : EMBMDATA);
        for (std::size_t d : s.devices) book_[d].health = kept_health_[d];
        return;
      }
    }
    for (std::size_t d : s.devices) {
      if (!book_[d].faulted) take_health(d, s.health_reads);
    }
    return;
  }
}

bool ModbusBus::write_slave(Slave& slave) {
  for (std::size_t d : slave.devices) {
    if (book_[d].faulted) return true;  // a faulted drive is left alone
  }
  for (std::size_t d : slave.devices) {
    const modbus::RegisterMap& m = *joints_[d].map;
    const ModbusJointOptions& j = joints_[d];
    for (Write& w : slave.writes) {
      if (m.goal.address >= w.begin && m.goal.end() <= w.begin + w.count) {
        m.goal.encode(j.zero + j.per_rad * goal_rad_[d],
                      w.words.data() + (m.goal.address - w.begin));
      }
    }
  }
  for (Write& w : slave.writes) {
    if (!connected_) return false;
    modbus_set_slave(ctx_, slave.id);
    ++requests_;
    if (modbus_requests::write_registers(ctx_, line(), slave.id, w.begin, w.count,
                                         w.words.data()) != w.count) {
      fail_slave(slave, errno);
      return false;
    }
  }
  return true;
}

bool ModbusBus::set_enable(Slave& slave, bool on, int* error) {
  for (std::size_t d : slave.devices) {
    const modbus::Enable& e = joints_[d].map->enable;
    if (!e.configured) continue;
    modbus_set_slave(ctx_, slave.id);
    const std::uint16_t value = on ? e.on : e.off;
    const int rc =
        modbus_requests::write_single(ctx_, line(!on), slave.id, e.coil, e.address, value);
    if (rc != 1) {
      *error = errno;
      return false;
    }
  }
  return true;
}

bool ModbusBus::set_watchdog(Slave& slave, bool on, int* error) {
  for (std::size_t d : slave.devices) {
    const modbus::Watchdog& w = joints_[d].map->watchdog;
    if (!w.configured || joints_[d].watchdog_counts == 0) continue;
    modbus_set_slave(ctx_, slave.id);
    const auto counts = static_cast<std::uint16_t>(on ? joints_[d].watchdog_counts : 0);
    if (modbus_requests::write_single(ctx_, line(), slave.id, false, w.address, counts) != 1) {
      *error = errno;
      return false;
    }
  }
  return true;
}

// ---- lifecycle --------------------------------------------------------------

void ModbusBus::configure() {
  book_.reset();
  for (std::size_t i = 0; i < book_.size(); ++i) book_.set_device_id(i, joints_[i].slave);
  if (!ensure_connected(true)) {
    throw DeviceError(prefix() + "cannot connect: " + modbus_strerror(errno));
  }
  std::string failed;
  for (Slave& s : slaves_) {
    bool ok = false;
    int tries = 0;
    for (; tries < kTries && !ok; ++tries) {
      if (!connected_) ensure_connected(true);
      ok = read_slave(s, false);
    }
    if (ok) continue;
    const std::uint8_t code = book_[s.devices[0]].last_error_byte;
    std::string joints;
    for (std::size_t d : s.devices)
      joints += (joints.empty() ? "" : ", ") + config_.actuators[d].joint;
    failed += (failed.empty() ? "" : "; ") + std::string("slave ") + std::to_string(s.id) + " (" +
              joints + "): " +
              (code ? "exception " + std::to_string(code) + " (" + exception_name(code) + ")"
                    : std::string("no answer"));
  }
  if (!failed.empty()) throw DeviceError(prefix() + "cannot read " + failed);
  for (Slave& s : slaves_) {
    for (std::size_t d : s.devices) {
      if (book_[d].health == DeviceHealth::hardware_error) {
        const auto& m = *joints_[d].map;
        throw DeviceError(prefix() + "slave " + std::to_string(s.id) + " (" +
                          config_.actuators[d].joint +
                          ") reports faults: " + m.fault_text(book_[d].hardware_error_status));
      }
    }
  }
  goal_rad_ = present_rad_;
  for (Slave& s : slaves_) s.silent = false;
  fresh_ = true;
}

void ModbusBus::activate() {
  for (Slave& s : slaves_) {
    bool ok = false;
    int error = 0;
    for (int t = 0; t < kTries && !ok; ++t) {
      if (!connected_) ensure_connected(true);
      ok = write_slave(s);  // goal = present: enabling cannot make it jump
      if (ok) ok = set_enable(s, true, &error);
      if (!ok && error == 0) error = errno;
    }
    if (!ok) {
      const std::string why = classify(error) == Failure::exception
                                  ? exception_name(error - MODBUS_ENOBASE)
                                  : std::string(modbus_strerror(error));
      deactivate();
      throw DeviceError(prefix() + "cannot enable slave " + std::to_string(s.id) + ": " + why);
    }
  }
}

void ModbusBus::arm_device_guard() {
  for (Slave& s : slaves_) {
    bool ok = false;
    int error = 0;
    for (int t = 0; t < kTries && !ok; ++t) {
      if (!connected_) ensure_connected(true);
      ok = set_watchdog(s, true, &error);
      if (!ok && error == 0) error = errno;
    }
    if (!ok) {
      const std::string why = classify(error) == Failure::exception
                                  ? exception_name(error - MODBUS_ENOBASE)
                                  : std::string(modbus_strerror(error));
      throw DeviceError(prefix() + "cannot set the communication timeout of slave " +
                        std::to_string(s.id) + " (device_watchdog_ms): " + why);
    }
  }
}

void ModbusBus::deactivate() {
  if (!connected_ && !ensure_connected(true)) return;
  for (Slave& s : slaves_) {
    int error = 0;
    if (!set_enable(s, false, &error) && classify(error) == Failure::connection) return;
  }
  for (Slave& s : slaves_) {
    int error = 0;
    if (!set_watchdog(s, false, &error) && classify(error) == Failure::connection) return;
  }
}

// ---- cycle ----------------------------------------------------------------

void ModbusBus::switch_off(std::size_t device) {
  mark_faulted(device);
  off_pending_[device] = 1;
}

// The enable of each device switched off since the last read(), one
// request each, best effort (the drive's fault or watchdog is the backstop).
void ModbusBus::switch_off_pending() {
  for (Slave& s : slaves_) {
    for (std::size_t d : s.devices) {
      if (!off_pending_[d]) continue;
      off_pending_[d] = 0;
      const modbus::Enable& e = joints_[d].map->enable;
      if (!e.configured || !connected_) continue;
      modbus_set_slave(ctx_, s.id);
      ++requests_;
      const int rc =
          modbus_requests::write_single(ctx_, line(true), s.id, e.coil, e.address, e.off);
      if (rc != 1 && classify(errno) == Failure::connection && options_.tcp) disconnect();
    }
  }
}

void ModbusBus::read(std::span<double> positions) {
  const std::size_t n = std::min(positions.size(), book_.size());
  if (fresh_) {
    for (std::size_t i = 0; i < n; ++i) positions[i] = present_rad_[i];
    fresh_ = false;
  }
  if (!ensure_connected(false)) {
    // Down and waiting for the next attempt: no answer this cycle.
    for (Slave& s : slaves_) s.silent = true;
    for (std::size_t d = 0; d < book_.size(); ++d) {
      if (book_.faulted(d)) continue;
      book_.asked(d);
      book_.timed_out(d);
    }
    return;
  }
  flush_input();  // late answers of timed-out requests must not pass for these
  switch_off_pending();
  for (Slave& s : slaves_) {
    if (!connected_) {
      s.silent = true;
      for (std::size_t d : s.devices) {
        if (book_.faulted(d)) continue;
        book_.asked(d);
        book_.timed_out(d);
      }
      continue;
    }
    s.silent = !read_slave(s, true);
  }
  if (options_.health == ModbusBusOptions::Health::round_robin) read_health_round_robin();
  for (std::size_t i = 0; i < n; ++i) {
    if (answered_[i]) positions[i] = present_rad_[i];
  }
}

void ModbusBus::write(std::span<const double> positions) {
  for (std::size_t i = 0; i < std::min(positions.size(), goal_rad_.size()); ++i) {
    goal_rad_[i] = config_.actuators[i].safe_goal(positions[i], goal_rad_[i]);
  }
  if (!connected_) return;  // read() reconnects; nothing to say to a dead link
  for (Slave& s : slaves_) {
    if (!s.silent) write_slave(s);
  }
}

}  // namespace animrt
