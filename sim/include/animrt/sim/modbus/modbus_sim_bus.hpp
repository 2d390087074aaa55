#pragma once
// Simulated Modbus drives of one bus, served by libmodbus: on a loopback TCP
// port (modbus-tcp) or on a pty speaking RTU (modbus-rtu). Each slave id of
// the bus is one drive holding the registers of its joints' register maps
// (libmodbus answers exception 2 outside them, and 3 for a bad quantity);
// the drive itself answers exception 3 to a goal outside the map's range or
// an enable value that is neither on nor off. Motor per joint: first-order
// lag (SimBusSettings::time_constant_s) with a speed limit (max_speed), moving
// only while enabled (or always, when the map has no enable). The registers
// of a map's health section report each motor's current, temperature and
// supply from the servos' health model (sim.health, sim.inject: a thermal
// model driven by the current, a supply that sags with it, a joint that can
// be blocked); an injected hardware_error is the fault code, and a drive
// with a fault code stops its motors, as with status fault bits. Its firmware
// trips by itself above sim.health.trip_c: fault code 0x4310 and the output
// off (the motors coast where they are), latched until a fault reset (the
// enable written off, then on) once every motor is 5 deg C below the trip.
// Any standard Modbus master can talk to it (mbpoll, pymodbus).
//
// TCP: every connection has its own receive buffer, so a client that sends
// half a request stalls nobody else; it is closed after 1 s incomplete.
//
// RTU: frames are delimited by their function code's length, CRC-checked
// (a bad CRC is dropped unanswered and counted), and dispatched by slave id.
// SimBusSettings::return_delay_us delays every answer (real time), to model
// a slow drive or gateway.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/bus_config.hpp"
#include "animrt/bridge/modbus/modbus_bus.hpp"
#include "animrt/core/clock.hpp"
#include "animrt/core/thread_priority.hpp"
#include "animrt/sim/simulated_bus.hpp"

struct _modbus;
struct _modbus_mapping_t;

namespace animrt::sim {

class PtyPair;
class WakePipe;

struct ModbusSimStats {
  std::uint64_t requests = 0;     // answered or not, valid frames
  std::uint64_t exceptions = 0;   // exception 3 answers of the drive's own value checks
  std::uint64_t crc_errors = 0;   // RTU frames dropped for a bad CRC
  std::uint64_t dropped = 0;      // RTU bytes of unknown or cut frames
  std::uint64_t connections = 0;  // TCP connections accepted
};

class ModbusSimBus final : public SimulatedBus {
 public:
  ModbusSimBus(const BusConfig& config, const Clock& clock);
  ~ModbusSimBus() override;
  ModbusSimBus(const ModbusSimBus&) = delete;
  ModbusSimBus& operator=(const ModbusSimBus&) = delete;

  const std::string& endpoint() const override { return endpoint_; }
  std::string describe() const override;
  void start() override;
  void stop() override;
  std::string raise_priority(int priority) override { return set_fifo_priority(thread_, priority); }
  // device_id = slave id. A drive that is not responding ignores requests.
  void set_device_answer_delay(int device_id, Nanos delay_ns, int answers = -1) override;
  void set_device_responding(int device_id, bool responding) override;
  // Sets bits in the drive's status register (and disables its motors).
  void set_device_hardware_error(int device_id, std::uint8_t error_bits) override;
  // Its temperature, a blocked joint, its supply or its fault code (every
  // joint of the slave), at once.
  void inject_device_health(int device_id, const SimHealthInjection& change) override;
  double device_position(int device_id) const override;
  // RTU on a lockstep clock: the line the host's requests follow.
  std::shared_ptr<LockstepLine> lockstep_line() const override { return line_; }

  // TCP: closes every open client connection (the server keeps listening).
  void drop_connections();
  ModbusSimStats stats() const;

 private:
  void wrote(int bytes);  // an answer's bytes, for the lockstep line
  struct Joint;
  struct Drive;
  void serve_tcp();
  void serve_rtu();
  // Handles one request (ADU) at `offset` (header length); replies unless the
  // slave is absent or silent.
  void handle(const std::uint8_t* req, int length, int offset);
  Drive* drive(int slave);
  void advance(Drive& d, Nanos now);
  void publish(Drive& d);
  void publish_health(Drive& d, Joint& j);

  BusConfig config_;
  const Clock& clock_;
  bool tcp_;
  std::string endpoint_;
  int listen_fd_ = -1;
  std::unique_ptr<PtyPair> pty_;
  std::shared_ptr<LockstepLine> line_;  // RTU on a lockstep clock only
  std::unique_ptr<WakePipe> wake_;
  _modbus* ctx_ = nullptr;
  std::vector<std::unique_ptr<Drive>> drives_;
  mutable std::mutex mutex_;  // guards drives_ state
  std::vector<int> clients_;
  // Per TCP connection: bytes of a request not complete yet.
  static constexpr std::size_t kMbapLength = 7;
  static constexpr int kTcpStallMs = 1000;
  struct ClientRx {
    std::array<std::uint8_t, 260> buf{};  // MODBUS_TCP_MAX_ADU_LENGTH
    std::size_t have = 0;
    Nanos since = 0;  // when the pending bytes began
  };
  std::vector<ClientRx> client_rx_;
  void close_client(std::size_t i);
  std::atomic<bool> drop_{false};
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> requests_{0}, exceptions_{0}, crc_errors_{0}, dropped_{0},
      connections_{0};
};

}  // namespace animrt::sim
