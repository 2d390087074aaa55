#pragma once
// Master side of Modbus drives (RTU over serial or TCP, through libmodbus),
// each joint described by a register map.
//
// Per cycle: read() sends, per slave and register table, ONE Read Holding /
// Read Input Registers request covering every present and status register
// of that slave's joints; write() sends, per slave, one Write Multiple
// Registers per contiguous run of goal registers (one request when the goals
// are contiguous). Exceptions, CRC errors and timeouts are counted per
// device; a status register with fault bits set is a hardware error.
//
// Health (the bus's `health` key, for maps with a `health` section): with
// `packed` the current, temperature, voltage and fault code registers join
// the cycle's read requests (still one request per slave and table when
// they lie near the position); with `round_robin` the cycle reads positions
// as without health and then one slave's health registers in a request of
// its own, the next slave in the next cycle. A fault code other than 0 is
// the device's error bits; the runtime's health limits judge the values.
// A device switched off for its health gets its enable off in the next
// read().
//
// A TCP connection that drops is closed and reopened with exponential
// backoff (reconnect_min_s doubling to reconnect_max_s); in between, every
// device counts a timeout per cycle and nothing blocks, so the watchdog
// faults the devices only if the connection stays down.
//
// Bounded I/O: libmodbus retries nothing (error recovery off). A dead slave
// gets one request per cycle: the read; its write is skipped in that cycle.
// A dropped link is only marked down inside a request; the reconnect
// happens at the start of a later read() (on the bus's I/O thread, before
// any request of that cycle), and libmodbus bounds its connect by the
// response timeout (= the bus timeout). Goals are clamped into the joint
// limits; a NaN goal keeps the previous one.

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "animrt/bridge/actuator_bus.hpp"
#include "animrt/bridge/modbus/register_map.hpp"
#include "animrt/bridge/status_book.hpp"

struct _modbus;

namespace animrt {

namespace modbus_requests {
class LateAnswers;
struct Line;
}  // namespace modbus_requests

// BusConfig::options of a modbus-tcp or modbus-rtu bus.
struct ModbusBusOptions {
  bool tcp = true;
  char parity = 'N';  // RTU: N, E or O
  int stop_bits = 1;  // RTU
  enum class Health : std::uint8_t { off, packed, round_robin };
  Health health = Health::off;
  double reconnect_min_s = 0.1;
  double reconnect_max_s = 2.0;
  // device_watchdog_ms (0: off), written to each drive whose register map
  // names a watchdog register; where the key was given, if it was.
  double device_watchdog_ms = 0.0;
  bool device_watchdog_given = false;
  Location device_watchdog_where;
  std::string device_watchdog_path;
};

// ActuatorBinding::options of a Modbus joint:
//   map value (SI, map->unit) = zero + per_rad * joint position
// (the joint in rad, or in m for a prismatic joint; keys m_per_rad, zero_m).
struct ModbusJointOptions {
  int slave = 1;
  std::shared_ptr<const modbus::RegisterMap> map;
  // 1 for maps in rad and for a prismatic joint (the stroke is the joint);
  // metres per radian for a linear actuator on a lever.
  double per_rad = 1.0;
  double zero = 0.0;
  // The drive's communication timeout in counts of the map's watchdog unit
  // (0: the map names no watchdog register, or the guard is off).
  std::uint16_t watchdog_counts = 0;
};

class ModbusBus final : public ActuatorBus {
 public:
  // Plans the requests. Throws DeviceError for joints without a register
  // map, registers of one slave that overlap or span more than one request.
  explicit ModbusBus(BusConfig config);
  ~ModbusBus() override;
  ModbusBus(const ModbusBus&) = delete;
  ModbusBus& operator=(const ModbusBus&) = delete;

  const BusConfig& config() const override { return config_; }
  // Connects and reads every slave; throws DeviceError listing each slave
  // that did not answer (and why).
  void configure() override;
  // Goal = present, then the enable coil/register on; throws on failure.
  void activate() override;
  // Writes each drive's communication timeout (the map's watchdog register).
  void arm_device_guard() override;
  // Enable off, then the communication timeout cleared, best effort.
  void deactivate() override;
  void read(std::span<double> positions) override;
  void write(std::span<const double> positions) override;
  std::span<DeviceStatus> devices() override { return book_.devices(); }
  // Marks the device faulted; its enable goes off in the next read().
  void switch_off(std::size_t device) override;
  bool reads_health() const override { return options_.health != ModbusBusOptions::Health::off; }
  std::string error_words(std::size_t device, std::uint32_t code) const override {
    return joints_[device].map->health.code_name(code);
  }

  std::uint64_t reconnects() const { return reconnects_; }
  bool connected() const { return connected_; }
  // Requests sent so far (for tests that count them).
  std::uint64_t requests() const { return requests_; }

 private:
  // `urgent`: a switch-off, sent without waiting out a late answer.
  modbus_requests::Line line(bool urgent = false) const;
  struct Read {
    modbus::Table table;
    int begin = 0, count = 0;
    std::vector<std::uint16_t> words;
  };
  struct Write {
    int begin = 0, count = 0;
    std::vector<std::uint16_t> words;
  };
  struct Slave {
    int id = 0;
    std::vector<std::size_t> devices;
    std::vector<Read> reads;
    std::vector<Read> health_reads;  // round_robin: the health registers alone
    std::vector<Write> writes;
    // Did not answer this cycle's read: its write is skipped, so a dead
    // slave costs one timeout per cycle, not two.
    bool silent = false;
  };
  enum class Failure : std::uint8_t { none, timeout, exception, crc, protocol, connection };

  // The constructor's stages: which slave each joint is on, the slave's
  // requests (one read per table, one write per run of goal registers), the
  // libmodbus context. `bus` prefixes their errors.
  void group_slaves(const std::string& bus);
  void plan_reads(Slave& slave, const std::string& bus);
  void plan_writes(Slave& slave, const std::string& bus);
  // Requests covering, per table, every register `pick` gives of the slave's joints.
  template <class Pick>
  std::vector<Read> plan_table_reads(const Slave& slave, const std::string& bus, Pick&& pick);
  void open_context(const std::string& bus);
  bool ensure_connected(bool blocking);
  void disconnect();
  void flush_input();
  Failure classify(int error) const;
  // Counts a failed request against the slave's devices; returns the failure.
  Failure fail_slave(const Slave& slave, int error);
  bool read_slave(Slave& slave, bool count);
  static const std::uint16_t* words_of(const std::vector<Read>& reads, const modbus::Register& r);
  const std::uint16_t* words_of(const Slave& slave, const modbus::Register& r) const {
    return words_of(slave.reads, r);
  }
  void take_health(std::size_t device, const std::vector<Read>& reads);
  void read_health_round_robin();
  void switch_off_pending();
  bool write_slave(Slave& slave);
  bool set_enable(Slave& slave, bool on, int* error);
  bool set_watchdog(Slave& slave, bool on, int* error);
  std::string prefix() const { return book_.prefix(); }

  BusConfig config_;
  ModbusBusOptions options_;
  std::vector<ModbusJointOptions> joints_;
  std::vector<Slave> slaves_;
  StatusBook book_;
  std::vector<double> present_rad_;
  std::vector<double> goal_rad_;
  std::vector<std::uint8_t> answered_;
  std::vector<std::uint8_t> off_pending_;  // switch_off(): enable off in the next read()
  std::vector<DeviceHealth> kept_health_;  // round_robin: a lost health read keeps these
  std::size_t health_next_ = 0;            // round_robin: the slave read next
  _modbus* ctx_ = nullptr;
  std::unique_ptr<modbus_requests::LateAnswers> late_;
  bool connected_ = false;
  bool fresh_ = false;
  std::chrono::steady_clock::time_point next_attempt_{};
  double backoff_s_ = 0.0;
  std::uint64_t reconnects_ = 0;
  std::uint64_t requests_ = 0;
  std::string host_;
  int tcp_port_ = 0;
};

}  // namespace animrt
