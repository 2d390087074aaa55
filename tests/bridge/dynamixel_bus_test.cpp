// DynamixelBus against a scripted fake device on the far side of a real
// pseudo-terminal: the fake decodes instructions with the codec's Decoder and
// answers with encode_status, or with deliberately broken bytes.

#include "animrt/bridge/dynamixel/dynamixel_bus.hpp"

#include <gtest/gtest.h>
#include <poll.h>
#include <pty.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "animrt/bridge/byte_transport.hpp"
#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "animrt/core/error.hpp"
#include "animrt/core/joint.hpp"
#include "support/alloc_counter.hpp"

namespace animrt {
namespace {

using namespace std::chrono_literals;

// How a fake servo spoils its answers.
enum class Fault {
  none,
  silent,
  bad_crc,
  stray_prefix,
  junk_header,
  truncate,
  wrong_id,
  error_number
};

struct FakeServo {
  std::int32_t present = 2048;
  std::int32_t goal = 0;
  std::uint8_t torque = 0;
  std::uint32_t max_limit = 0, min_limit = 0;  // registers 48 and 52
  std::uint8_t hardware_error = 0;             // register 70; nonzero sets the alert bit
  std::uint8_t mode = 3;                       // register 11, Operating Mode: position
  Fault fault = Fault::none;
  int booting_pings = 0;  // pings it ignores before it answers (still booting)
};

// One instruction as the fake received it.
struct Received {
  std::uint8_t id = 0;
  std::uint8_t instruction = 0;
  std::vector<std::uint8_t> params;
  std::uint16_t address() const { return dxl::get_u16(params.data()); }
};

class FakeDevices {
 public:
  explicit FakeDevices(std::map<std::uint8_t, FakeServo> servos) : servos_(std::move(servos)) {
    char name[128];
    if (openpty(&master_, &slave_, name, nullptr, nullptr) != 0)
      throw std::runtime_error("openpty");
    port_ = name;
    thread_ = std::thread([this] { serve(); });
  }
  ~FakeDevices() {
    unplug();
    ::close(slave_);
  }
  // The adapter is pulled: the device side closes, the bus sees EIO.
  void unplug() {
    if (master_ < 0) return;
    stop_ = true;
    thread_.join();
    ::close(master_);
    master_ = -1;
  }

  const std::string& port() const { return port_; }

  void edit(const std::function<void(std::map<std::uint8_t, FakeServo>&)>& change) {
    std::lock_guard lock(mutex_);
    change(servos_);
  }
  FakeServo servo(std::uint8_t id) {
    std::lock_guard lock(mutex_);
    return servos_.at(id);
  }
  std::vector<Received> log() {
    std::lock_guard lock(mutex_);
    return log_;
  }
  void clear_log() {
    std::lock_guard lock(mutex_);
    log_.clear();
  }
  std::vector<Received> log_of(std::uint8_t instruction) {
    std::vector<Received> out;
    for (auto& r : log()) {
      if (r.instruction == instruction) out.push_back(r);
    }
    return out;
  }

 private:
  void serve() {
    dxl::Decoder decoder;
    std::uint8_t buf[512];
    while (!stop_) {
      pollfd p{master_, POLLIN, 0};
      if (::poll(&p, 1, 10) <= 0) continue;
      const ssize_t n = ::read(master_, buf, sizeof buf);
      if (n <= 0) continue;
      std::size_t fed = 0;
      while (fed < static_cast<std::size_t>(n)) {
        fed += decoder.feed({buf + fed, static_cast<std::size_t>(n) - fed});
        dxl::Packet packet;
        for (;;) {
          const dxl::DecodeResult r = decoder.next(packet);
          if (r == dxl::DecodeResult::need_more) break;
          if (r == dxl::DecodeResult::packet) handle(packet);
        }
      }
    }
  }

  void handle(const dxl::Packet& packet) {
    std::lock_guard lock(mutex_);
    log_.push_back({packet.id, packet.instruction, {packet.params.begin(), packet.params.end()}});
    const auto& p = packet.params;
    switch (packet.instruction) {
      case dxl::inst::ping:
        if (servos_.count(packet.id) != 0 && servos_[packet.id].booting_pings-- <= 0) {
          answer(packet.id, {0x60, 0x04, 0x2E});  // XL430
        }
        break;
      case dxl::inst::read:
        if (servos_.count(packet.id) != 0) {
          answer(packet.id, table(servos_[packet.id], dxl::get_u16(&p[0]), dxl::get_u16(&p[2])));
        }
        break;
      case dxl::inst::write:
        if (servos_.count(packet.id) != 0) {
          FakeServo& s = servos_[packet.id];
          const std::uint16_t address = dxl::get_u16(&p[0]);
          if (address == dxl::xreg::goal_position)
            s.goal = static_cast<std::int32_t>(dxl::get_u32(&p[2]));
          if (address == dxl::xreg::torque_enable) s.torque = p[2];
          if (address == dxl::xreg::max_position_limit) s.max_limit = dxl::get_u32(&p[2]);
          if (address == dxl::xreg::min_position_limit) s.min_limit = dxl::get_u32(&p[2]);
          if (address == dxl::xreg::operating_mode) s.mode = p[2];
          answer(packet.id, {});
        }
        break;
      case dxl::inst::sync_read: {
        const std::uint16_t address = dxl::get_u16(&p[0]);
        const std::uint16_t length = dxl::get_u16(&p[2]);
        for (std::size_t i = 4; i < p.size(); ++i) {
          if (servos_.count(p[i]) != 0) answer(p[i], table(servos_[p[i]], address, length));
        }
        break;
      }
      case dxl::inst::sync_write: {
        const std::uint16_t length = dxl::get_u16(&p[2]);
        for (std::size_t i = 4; i + length < p.size() + 1; i += 1 + length) {
          if (servos_.count(p[i]) != 0) {
            servos_[p[i]].goal = static_cast<std::int32_t>(dxl::get_u32(&p[i + 1]));
          }
        }
        break;
      }
      default:
        break;
    }
  }

  static std::vector<std::uint8_t> table(const FakeServo& s, std::uint16_t address,
                                         std::uint16_t length) {
    std::vector<std::uint8_t> data(length, 0);
    if (address == dxl::xreg::present_position && length == 4) {
      dxl::put_u32(data.data(), static_cast<std::uint32_t>(s.present));
    }
    if (address == dxl::xreg::hardware_error_status && length == 1) data[0] = s.hardware_error;
    if (address == dxl::xreg::torque_enable && length == 1) data[0] = s.torque;
    if (address == dxl::xreg::operating_mode && length == 1) data[0] = s.mode;
    if (address == dxl::xreg::max_position_limit && length == 4)
      dxl::put_u32(data.data(), s.max_limit);
    if (address == dxl::xreg::min_position_limit && length == 4)
      dxl::put_u32(data.data(), s.min_limit);
    return data;
  }

  void answer(std::uint8_t id, const std::vector<std::uint8_t>& data) {
    const FakeServo& s = servos_[id];
    std::uint8_t error = s.hardware_error != 0 ? dxl::kAlertBit : 0;
    std::uint8_t out[dxl::kMaxPacket];
    std::size_t n = 0;
    switch (s.fault) {
      case Fault::silent:
        return;
      case Fault::error_number:
        error |= static_cast<std::uint8_t>(dxl::StatusError::data_range);
        n = dxl::encode_status(id, error, {}, out);
        break;
      case Fault::wrong_id:
        n = dxl::encode_status(static_cast<std::uint8_t>(id + 100), error, data, out);
        break;
      default:
        n = dxl::encode_status(id, error, data, out);
        break;
    }
    if (s.fault == Fault::bad_crc) out[n - 1] ^= 0x5A;
    if (s.fault == Fault::truncate) n -= 3;
    if (s.fault == Fault::stray_prefix) send({0x00, 0x13, 0xFF, 0x42, 0xFF, 0xFF});
    // A header with an impossible length (LEN 0xFFFF) right before the answer.
    if (s.fault == Fault::junk_header) send({0xFF, 0xFF, 0xFD, 0x00, 0x01, 0xFF, 0xFF});
    send({out, out + n});
  }

  void send(const std::vector<std::uint8_t>& bytes) {
    ASSERT_EQ(::write(master_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
  }

  int master_ = -1;
  int slave_ = -1;  // kept open so the master never sees a hangup
  std::string port_;
  std::mutex mutex_;
  std::map<std::uint8_t, FakeServo> servos_;
  std::vector<Received> log_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

constexpr double kTicksPerRad = 4096.0 / (2.0 * 3.14159265358979323846);

BusConfig make_config(const std::string& port) {
  BusConfig c;
  c.name = "legs";
  c.protocol = "dynamixel2";
  c.port = port;
  // Generous: a loaded machine may hold the fake servos' thread off the CPU
  // for tens of milliseconds, and a cycle's read is not retried.
  c.timeout_s = 0.2;
  // These devices speak plain Sync Read only (Fast Sync Read: tests/sim).
  dxl::BusOptions options;
  options.fast_read = dxl::FastRead::off;
  c.options = options;
  const char* joints[] = {"lf_hip", "lf_knee", "lf_ankle"};
  for (int i = 0; i < 3; ++i) {
    ActuatorBinding b;
    b.joint = joints[i];
    b.joint_index = i;
    b.device_id = i + 1;
    c.actuators.push_back(b);
  }
  // The third joint is mounted mirrored, with its own zero.
  c.actuators[2].direction = -1;
  c.actuators[2].zero_ticks = 1000;
  return c;
}

std::map<std::uint8_t, FakeServo> three_servos() {
  std::map<std::uint8_t, FakeServo> m;
  m[1].present = 2048;
  m[2].present = 3072;
  m[3].present = 1500;
  return m;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const DeviceError& e) {
    return e.what();
  }
  return "no error";
}

class DynamixelBusTest : public ::testing::Test {
 protected:
  DynamixelBusTest()
      : fake_(three_servos()),
        bus_(make_config(fake_.port()), open_serial(fake_.port(), 1'000'000)) {}

  // Configured, with the log cleared and the lifecycle's transactions noted.
  void configured() {
    bus_.configure();
    fake_.clear_log();
    for (std::size_t i = 0; i < 3; ++i) base_transactions_[i] = status(i).transactions;
  }
  std::uint64_t cycles(std::size_t i) { return status(i).transactions - base_transactions_[i]; }
  const DeviceStatus& status(std::size_t i) { return bus_.devices()[i]; }
  double rad(std::size_t i, std::int32_t ticks) { return bus_.config().actuators[i].to_rad(ticks); }
  void set_fault(std::uint8_t id, Fault fault) {
    fake_.edit([&](auto& s) { s[id].fault = fault; });
  }
  void set_present(std::uint8_t id, std::int32_t ticks) {
    fake_.edit([&](auto& s) { s[id].present = ticks; });
  }
  void expect_ok(std::size_t i) {
    EXPECT_EQ(status(i).health, DeviceHealth::ok) << "device " << i;
    EXPECT_EQ(status(i).timeouts + status(i).crc_errors + status(i).protocol_errors, 0u)
        << "device " << i;
  }

  FakeDevices fake_;
  DynamixelBus bus_;
  std::uint64_t base_transactions_[3] = {};
};

TEST_F(DynamixelBusTest, ConfigurePingsAndReadsEveryDevice) {
  bus_.configure();
  const auto log = fake_.log();
  ASSERT_EQ(log.size(), 12u);
  for (std::uint8_t id = 1; id <= 3; ++id) {
    EXPECT_EQ(log[id - 1].instruction, dxl::inst::ping);
    EXPECT_EQ(log[id - 1].id, id);
    // Operating Mode: read, and (position mode already) left alone.
    EXPECT_EQ(log[id + 2].instruction, dxl::inst::read);
    EXPECT_EQ(log[id + 2].id, id);
    EXPECT_EQ(log[id + 2].params, (std::vector<std::uint8_t>{11, 0, 1, 0}));
    EXPECT_EQ(log[id + 5].instruction, dxl::inst::read);
    EXPECT_EQ(log[id + 5].id, id);
    EXPECT_EQ(log[id + 5].params, (std::vector<std::uint8_t>{132, 0, 4, 0}));
    // Bus Watchdog: read, and (reading 0 here) left alone.
    EXPECT_EQ(log[id + 8].instruction, dxl::inst::read);
    EXPECT_EQ(log[id + 8].id, id);
    EXPECT_EQ(log[id + 8].params, (std::vector<std::uint8_t>{98, 0, 1, 0}));
  }
  for (std::size_t i = 0; i < 3; ++i) {
    expect_ok(i);
    EXPECT_EQ(status(i).device_id, static_cast<int>(i) + 1);
    EXPECT_EQ(status(i).transactions, 4u);  // the lifecycle's transactions count too
  }
  EXPECT_EQ(bus_.mode_warning(), "");
}

// A process killed while it held a joint compliantly leaves its servo in
// current-based position mode (EEPROM): configure writes position mode
// back, torque off first, before it reads any position, and says so; a
// multi_turn joint's servo goes to extended position mode and gets no
// position limits (that mode does not use them).
TEST_F(DynamixelBusTest, ConfigurePutsEachServoInTheModeItsJointNeeds) {
  auto config = make_config(fake_.port());
  config.actuators[0].min_position = -0.5;
  config.actuators[0].max_position = 0.25;
  config.actuators[2].min_position = -0.5;
  config.actuators[2].max_position = 0.25;
  dxl::DeviceOptions multi;
  multi.multi_turn = true;
  config.actuators[2].options = multi;
  DynamixelBus bus(config, open_serial(fake_.port(), 1'000'000));
  fake_.edit([](auto& s) {
    s[1].mode = 5;
    s[1].torque = 1;
  });
  bus.configure();
  EXPECT_EQ(fake_.servo(1).mode, 3);
  EXPECT_EQ(fake_.servo(2).mode, 3);
  EXPECT_EQ(fake_.servo(3).mode, 4);
  const auto log = fake_.log();
  std::vector<std::uint16_t> to_1, to_3;
  for (const auto& r : log) {
    if (r.instruction == dxl::inst::write && r.id == 1) to_1.push_back(r.address());
    if (r.instruction == dxl::inst::write && r.id == 3) to_3.push_back(r.address());
  }
  ASSERT_GE(to_1.size(), 2u);
  EXPECT_EQ(to_1[0], dxl::xreg::torque_enable);
  EXPECT_EQ(to_1[1], dxl::xreg::operating_mode);
  EXPECT_EQ(to_3,
            (std::vector<std::uint16_t>{dxl::xreg::torque_enable, dxl::xreg::operating_mode}));
  // The mode is set before the position is read (entering position mode
  // restarts a servo's count of turns).
  std::size_t mode_write = log.size(), position_read = log.size();
  for (std::size_t k = 0; k < log.size(); ++k) {
    if (log[k].id != 1) continue;
    if (log[k].instruction == dxl::inst::write && log[k].address() == dxl::xreg::operating_mode)
      mode_write = std::min(mode_write, k);
    if (log[k].instruction == dxl::inst::read && log[k].address() == dxl::xreg::present_position)
      position_read = std::min(position_read, k);
  }
  EXPECT_LT(mode_write, position_read);
  EXPECT_EQ(bus.mode_warning(),
            "id 1 (lf_hip) was in Operating Mode 5 (current-based position), set to 3 (position); "
            "id 3 (lf_ankle) was in Operating Mode 3 (position), set to 4 (extended position)");
}

TEST_F(DynamixelBusTest, FirstReadHasConfiguredPositionsEvenIfNobodyAnswers) {
  configured();
  for (std::uint8_t id = 1; id <= 3; ++id) set_fault(id, Fault::silent);
  std::vector<double> q(3, 99.0);
  bus_.read(q);
  EXPECT_DOUBLE_EQ(q[0], rad(0, 2048));
  EXPECT_DOUBLE_EQ(q[1], rad(1, 3072));
  EXPECT_DOUBLE_EQ(q[2], rad(2, 1500));
  EXPECT_DOUBLE_EQ(q[1], kPi / 2);
  EXPECT_EQ(status(0).timeouts, 1u);
}

TEST(DynamixelBus, ConfigureWarnsAboutASlowUsbLatencyTimer) {
  // The fake devices' pty behind a link named like a USB adapter, and a
  // fake sysfs tree that gives that adapter Linux's default 16 ms.
  FakeDevices fake(three_servos());
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("animrt_latency_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "sys/bus/usb-serial/devices/ttyUSB9");
  std::ofstream(dir / "sys/bus/usb-serial/devices/ttyUSB9/latency_timer") << "16\n";
  std::filesystem::create_symlink(fake.port(), dir / "ttyUSB9");
  const std::string port = (dir / "ttyUSB9").string();
  DynamixelBus bus(make_config(port), open_serial(port, 1'000'000));
  bus.set_sysfs_root((dir / "sys").string());
  bus.configure();
  EXPECT_NE(bus.latency_warning().find("latency timer is 16 ms"), std::string::npos)
      << bus.latency_warning();
  // At 1 ms nothing is said.
  std::ofstream(dir / "sys/bus/usb-serial/devices/ttyUSB9/latency_timer") << "1\n";
  bus.configure();
  EXPECT_EQ(bus.latency_warning(), "");
  std::filesystem::remove_all(dir);
}

TEST(DynamixelBus, ConfigureListsEveryMissingDeviceInOneError) {
  auto servos = three_servos();
  servos[2].fault = Fault::silent;
  servos[3].fault = Fault::silent;
  FakeDevices fake(servos);
  DynamixelBus bus(make_config(fake.port()), open_serial(fake.port(), 1'000'000));
  EXPECT_EQ(
      error_of([&] { bus.configure(); }),
      "bus legs (" + fake.port() + "): no answer to ping from id 2 (lf_knee), id 3 (lf_ankle)");
  // Each silent device was tried three times in each round.
  int pings_to_2 = 0;
  for (const auto& r : fake.log_of(dxl::inst::ping)) pings_to_2 += r.id == 2 ? 1 : 0;
  EXPECT_EQ(pings_to_2, DynamixelBus::kTries * kPingRounds);
}

TEST(DynamixelBus, ConfigureWaitsForAServoThatIsStillBooting) {
  // Servo 2 ignores more pings than one round's retries; the next round
  // finds it, and the others are not asked again.
  auto servos = three_servos();
  servos[2].booting_pings = DynamixelBus::kTries + 1;
  FakeDevices fake(servos);
  DynamixelBus bus(make_config(fake.port()), open_serial(fake.port(), 1'000'000));
  bus.configure();
  int pings_to_1 = 0, pings_to_2 = 0;
  for (const auto& r : fake.log_of(dxl::inst::ping)) {
    pings_to_1 += r.id == 1 ? 1 : 0;
    pings_to_2 += r.id == 2 ? 1 : 0;
  }
  EXPECT_EQ(pings_to_1, 1);
  EXPECT_EQ(pings_to_2, DynamixelBus::kTries + 2);
}

TEST(DynamixelBus, ConfigureReportsARejectedPositionRead) {
  auto servos = three_servos();
  servos[2].fault = Fault::error_number;
  FakeDevices fake(servos);
  DynamixelBus bus(make_config(fake.port()), open_serial(fake.port(), 1'000'000));
  EXPECT_EQ(error_of([&] { bus.configure(); }),
            "bus legs (" + fake.port() +
                "): cannot read Operating Mode of id 2 (lf_knee): status error 0x04 (data "
                "range error)");
}

TEST_F(DynamixelBusTest, ActivateWritesGoalEqualToPresentBeforeTorqueOn) {
  configured();
  bus_.activate();
  const auto log = fake_.log();
  ASSERT_EQ(log.size(), 6u);
  const std::int32_t present[] = {2048, 3072, 1500};
  for (std::size_t i = 0; i < 3; ++i) {
    const Received& goal = log[2 * i];
    const Received& torque = log[2 * i + 1];
    EXPECT_EQ(goal.id, i + 1);
    EXPECT_EQ(goal.instruction, dxl::inst::write);
    EXPECT_EQ(goal.address(), dxl::xreg::goal_position);
    EXPECT_EQ(static_cast<std::int32_t>(dxl::get_u32(&goal.params[2])), present[i]);
    EXPECT_EQ(torque.id, i + 1);
    EXPECT_EQ(torque.address(), dxl::xreg::torque_enable);
    EXPECT_EQ(torque.params[2], 1);
    EXPECT_EQ(fake_.servo(static_cast<std::uint8_t>(i + 1)).torque, 1);
  }
}

TEST_F(DynamixelBusTest, ActivateFailureNamesTheDeviceAndTurnsTorqueOff) {
  configured();
  set_fault(2, Fault::silent);
  EXPECT_EQ(
      error_of([&] { bus_.activate(); }),
      "bus legs (" + fake_.port() + "): cannot write goal position of id 2 (lf_knee): no answer");
  EXPECT_EQ(fake_.servo(1).torque, 0);
}

TEST_F(DynamixelBusTest, ActivateRefusesADeviceInHardwareError) {
  configured();
  fake_.edit([](auto& s) { s[3].hardware_error = 0x24; });
  EXPECT_EQ(error_of([&] { bus_.activate(); }),
            "bus legs (" + fake_.port() +
                "): cannot write goal position of id 3 (lf_ankle): device reports a hardware "
                "error (hardware error status 0x24: overheating, overload); once its cause is "
                "gone, a power cycle or `animrt servo " +
                fake_.port() + " --protocol dynamixel2 --id 3 --baud 1000000 reboot` clears it");
  EXPECT_EQ(fake_.servo(1).torque, 0);
  EXPECT_EQ(fake_.servo(2).torque, 0);
}

TEST_F(DynamixelBusTest, DeactivateTurnsTorqueOffEverywhereAndNeverThrows) {
  configured();
  bus_.activate();
  set_fault(2, Fault::silent);
  EXPECT_NO_THROW(bus_.deactivate());
  EXPECT_EQ(fake_.servo(1).torque, 0);
  EXPECT_EQ(fake_.servo(3).torque, 0);
}

TEST_F(DynamixelBusTest, ReadWithAllAnswering) {
  configured();
  set_present(1, 1024);
  set_present(2, 2048);
  set_present(3, 0);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_DOUBLE_EQ(q[0], -kPi / 2);
  EXPECT_DOUBLE_EQ(q[1], 0.0);
  EXPECT_DOUBLE_EQ(q[2], 1000.0 / kTicksPerRad);  // mirrored, zero at 1000
  const auto reads = fake_.log_of(dxl::inst::sync_read);
  ASSERT_EQ(reads.size(), 1u);
  EXPECT_EQ(reads[0].id, dxl::kBroadcastId);
  EXPECT_EQ(reads[0].params, (std::vector<std::uint8_t>{132, 0, 4, 0, 1, 2, 3}));
  for (std::size_t i = 0; i < 3; ++i) {
    expect_ok(i);
    EXPECT_EQ(cycles(i), 1u);
  }
}

TEST_F(DynamixelBusTest, SilentDeviceTimesOutAndKeepsItsPosition) {
  configured();
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  set_fault(2, Fault::silent);
  set_present(1, 1000);
  set_present(2, 1000);
  set_present(3, 1000);
  q[1] = 0.123;
  bus_.read(q);
  EXPECT_DOUBLE_EQ(q[0], rad(0, 1000));
  EXPECT_DOUBLE_EQ(q[1], 0.123);
  EXPECT_DOUBLE_EQ(q[2], 0.0);
  EXPECT_EQ(status(1).timeouts, 1u);
  EXPECT_EQ(status(1).health, DeviceHealth::timeout);
  EXPECT_EQ(cycles(1), 2u);
  expect_ok(0);
  expect_ok(2);

  // Back on the bus: healthy again, the timeout stays counted.
  set_fault(2, Fault::none);
  bus_.read(q);
  EXPECT_DOUBLE_EQ(q[1], rad(1, 1000));
  EXPECT_EQ(status(1).health, DeviceHealth::ok);
  EXPECT_EQ(status(1).timeouts, 1u);
}

TEST_F(DynamixelBusTest, CorruptedCrcIsCountedNotFatal) {
  configured();
  set_fault(2, Fault::bad_crc);
  set_present(1, 100);
  set_present(2, 200);
  set_present(3, 300);
  std::vector<double> q(3, 0.0);
  EXPECT_NO_THROW(bus_.read(q));
  EXPECT_EQ(status(1).crc_errors, 1u);
  EXPECT_EQ(status(1).health, DeviceHealth::protocol_error);
  EXPECT_DOUBLE_EQ(q[1], rad(1, 3072));  // from configure, not the corrupted answer
  EXPECT_DOUBLE_EQ(q[0], rad(0, 100));
  EXPECT_DOUBLE_EQ(q[2], rad(2, 300));
  expect_ok(0);
  expect_ok(2);
}

TEST_F(DynamixelBusTest, StrayBytesBeforeTheHeaderAreSkipped) {
  configured();
  set_fault(1, Fault::stray_prefix);
  set_fault(3, Fault::stray_prefix);
  set_present(1, 111);
  set_present(3, 333);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_DOUBLE_EQ(q[0], rad(0, 111));
  EXPECT_DOUBLE_EQ(q[2], rad(2, 333));
  for (std::size_t i = 0; i < 3; ++i) expect_ok(i);
}

TEST_F(DynamixelBusTest, JunkHeaderIsCountedAndTheRealAnswerStillTaken) {
  configured();
  set_fault(2, Fault::junk_header);
  set_present(2, 2222);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_DOUBLE_EQ(q[1], rad(1, 2222));
  EXPECT_EQ(status(1).protocol_errors, 1u);
  EXPECT_EQ(status(1).timeouts, 0u);
  EXPECT_EQ(status(1).health, DeviceHealth::ok);
  expect_ok(0);
  expect_ok(2);
}

TEST_F(DynamixelBusTest, TruncatedLastAnswerIsAProtocolError) {
  configured();
  set_fault(3, Fault::truncate);
  set_present(3, 333);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_EQ(status(2).protocol_errors, 1u);
  EXPECT_EQ(status(2).timeouts, 0u);
  EXPECT_EQ(status(2).health, DeviceHealth::protocol_error);
  EXPECT_DOUBLE_EQ(q[2], rad(2, 1500));
  expect_ok(0);
  expect_ok(1);
}

TEST_F(DynamixelBusTest, TruncatedMiddleAnswerIsCountedNotFatal) {
  configured();
  set_fault(2, Fault::truncate);
  set_present(1, 100);
  std::vector<double> q(3, 0.0);
  EXPECT_NO_THROW(bus_.read(q));
  EXPECT_DOUBLE_EQ(q[0], rad(0, 100));
  EXPECT_DOUBLE_EQ(q[1], rad(1, 3072));
  EXPECT_GE(status(1).crc_errors + status(1).protocol_errors, 1u);
  EXPECT_NE(status(1).health, DeviceHealth::ok);
  expect_ok(0);
  // The next cycle is clean again.
  set_fault(2, Fault::none);
  bus_.read(q);
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(status(i).health, DeviceHealth::ok);
}

TEST_F(DynamixelBusTest, WrongIdIsAProtocolErrorOfTheExpectedDevice) {
  configured();
  set_fault(2, Fault::wrong_id);
  set_present(2, 1);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_EQ(status(1).protocol_errors, 1u);
  EXPECT_EQ(status(1).timeouts, 0u);
  EXPECT_EQ(status(1).health, DeviceHealth::protocol_error);
  EXPECT_DOUBLE_EQ(q[1], rad(1, 3072));
  expect_ok(0);
  expect_ok(2);
}

TEST_F(DynamixelBusTest, ErrorNumberIsAProtocolError) {
  configured();
  set_fault(1, Fault::error_number);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_EQ(status(0).protocol_errors, 1u);
  EXPECT_EQ(status(0).health, DeviceHealth::protocol_error);
  EXPECT_EQ(status(0).last_error_byte, 0x04);
  expect_ok(1);
  expect_ok(2);
}

TEST_F(DynamixelBusTest, AlertBitCountsAndReadsTheHardwareErrorRegisterOnce) {
  configured();
  fake_.edit([](auto& s) {
    s[2].hardware_error = 0x20;
    s[2].present = 2500;
  });
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  EXPECT_EQ(status(1).hardware_errors, 1u);
  EXPECT_EQ(status(1).health, DeviceHealth::hardware_error);
  EXPECT_EQ(status(1).last_error_byte, dxl::kAlertBit);
  EXPECT_EQ(status(1).hardware_error_status, 0x20);
  EXPECT_DOUBLE_EQ(q[1], rad(1, 2500));  // the data of an alert status is still valid
  auto reads = fake_.log_of(dxl::inst::read);
  ASSERT_EQ(reads.size(), 1u);
  EXPECT_EQ(reads[0].id, 2);
  EXPECT_EQ(reads[0].params, (std::vector<std::uint8_t>{70, 0, 1, 0}));

  // Still alerting: counted again, but the register is not read again.
  bus_.read(q);
  EXPECT_EQ(status(1).hardware_errors, 2u);
  EXPECT_EQ(fake_.log_of(dxl::inst::read).size(), 1u);
  expect_ok(0);
  expect_ok(2);
}

TEST_F(DynamixelBusTest, WriteSendsOneSyncWriteWithTicks) {
  configured();
  const std::vector<double> q = {0.0, kPi / 2, 0.5};
  bus_.write(q);
  std::vector<double> measured(3, 0.0);
  bus_.read(measured);  // the fake handles packets in order: the write is logged by now
  const auto writes = fake_.log_of(dxl::inst::sync_write);
  ASSERT_EQ(writes.size(), 1u);
  EXPECT_EQ(writes[0].id, dxl::kBroadcastId);
  const auto& p = writes[0].params;
  ASSERT_EQ(p.size(), 4u + 3u * 5u);
  EXPECT_EQ(dxl::get_u16(&p[0]), dxl::xreg::goal_position);
  EXPECT_EQ(dxl::get_u16(&p[2]), 4);
  const std::int32_t expected[] = {
      2048, 3072, static_cast<std::int32_t>(std::lround(1000 - 0.5 * kTicksPerRad))};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(p[4 + 5 * i], i + 1);
    EXPECT_EQ(static_cast<std::int32_t>(dxl::get_u32(&p[5 + 5 * i])), expected[i]) << i;
  }
  EXPECT_EQ(fake_.servo(3).goal, expected[2]);
}

TEST_F(DynamixelBusTest, WriteClampsToInt32AndHoldsOnNaN) {
  configured();
  bus_.write(std::vector<double>{1e300, -1e300, 0.0});
  bus_.write(std::vector<double>{0.0, std::nan(""), 0.0});
  std::vector<double> measured(3, 0.0);
  bus_.read(measured);
  const auto writes = fake_.log_of(dxl::inst::sync_write);
  ASSERT_EQ(writes.size(), 2u);
  const auto tick = [&](std::size_t w, std::size_t i) {
    return static_cast<std::int32_t>(dxl::get_u32(&writes[w].params[5 + 5 * i]));
  };
  EXPECT_GT(tick(0, 0), 2'000'000'000);
  EXPECT_LT(tick(0, 1), -2'000'000'000);
  EXPECT_EQ(tick(1, 1), tick(0, 1));  // NaN holds the last goal
}

TEST_F(DynamixelBusTest, FaultedDeviceIsLeftOutOfSyncReadAndSyncWrite) {
  configured();
  bus_.mark_faulted(1);
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  bus_.write(q);
  bus_.read(q);
  const auto reads = fake_.log_of(dxl::inst::sync_read);
  ASSERT_EQ(reads.size(), 2u);
  EXPECT_EQ(reads[0].params, (std::vector<std::uint8_t>{132, 0, 4, 0, 1, 3}));
  const auto writes = fake_.log_of(dxl::inst::sync_write);
  ASSERT_EQ(writes.size(), 1u);
  ASSERT_EQ(writes[0].params.size(), 4u + 2u * 5u);
  EXPECT_EQ(writes[0].params[4], 1);
  EXPECT_EQ(writes[0].params[9], 3);
  EXPECT_EQ(cycles(1), 0u);
  EXPECT_EQ(status(1).timeouts, 0u);
  expect_ok(0);
  expect_ok(2);
}

TEST_F(DynamixelBusTest, CycleNeverAllocates) {
  configured();
  bus_.activate();
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  bus_.write(q);
  // The failure paths too: a silent device, a corrupted answer, a new alert.
  // (Silent last: a corrupted answer is blamed on the device expected next.)
  set_fault(1, Fault::bad_crc);
  fake_.edit([](auto& s) { s[2].hardware_error = 0x01; });
  set_fault(3, Fault::silent);
  long allocations = 0;
  {
    test::AllocationCounter counter;  // this thread only: the fake device is not counted
    for (int i = 0; i < 3; ++i) {
      bus_.read(q);
      bus_.write(q);
    }
    allocations = counter.count();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(status(0).crc_errors, 3u);
  EXPECT_EQ(status(1).hardware_error_status, 0x01);
  EXPECT_EQ(status(2).timeouts, 3u);
}

TEST_F(DynamixelBusTest, WriteClampsIntoTheJointLimits) {
  auto config = make_config(fake_.port());
  config.actuators[0].min_position = -0.5;
  config.actuators[0].max_position = 0.25;
  config.actuators[2].min_position = -0.1;  // mirrored joint: limits swap in ticks
  config.actuators[2].max_position = 0.2;
  DynamixelBus bus(config, open_serial(fake_.port(), 1'000'000));
  // Every joint rests inside its limits (one outside: DynamixelBusOnSim).
  fake_.edit([&](auto& s) { s[3].present = config.actuators[2].to_ticks(0.0); });
  // The fake answers 0 to the limit registers, so configure writes them.
  bus.configure();
  fake_.clear_log();
  bus.write(std::vector<double>{3.0, 0.1, -3.0});
  bus.write(std::vector<double>{std::nan(""), 0.1, 0.0});
  std::vector<double> measured(3, 0.0);
  bus.read(measured);  // a round trip: the fake has handled the writes
  const auto writes = fake_.log_of(dxl::inst::sync_write);
  ASSERT_EQ(writes.size(), 2u);
  const auto tick = [&](std::size_t w, std::size_t i) {
    return static_cast<std::int32_t>(dxl::get_u32(&writes[w].params[5 + 5 * i]));
  };
  EXPECT_EQ(tick(0, 0), config.actuators[0].to_ticks(0.25));
  EXPECT_EQ(tick(0, 1), config.actuators[1].to_ticks(0.1));
  EXPECT_EQ(tick(0, 2), config.actuators[2].to_ticks(-0.1));
  EXPECT_EQ(tick(1, 0), tick(0, 0));  // NaN: the previous goal again
}

TEST_F(DynamixelBusTest, PositionLimitsAreWrittenWithTorqueOffOnlyWhenTheyDiffer) {
  auto config = make_config(fake_.port());
  config.actuators[0].min_position = -0.5;
  config.actuators[0].max_position = 0.25;
  DynamixelBus bus(config, open_serial(fake_.port(), 1'000'000));
  fake_.edit([](auto& s) { s[1].torque = 1; });
  bus.configure();
  const auto writes = fake_.log_of(dxl::inst::write);
  ASSERT_EQ(writes.size(), 3u);  // torque off, max, min; nothing for the unlimited joints
  EXPECT_EQ(writes[0].address(), dxl::xreg::torque_enable);
  EXPECT_EQ(writes[0].params[2], 0);
  EXPECT_EQ(writes[1].address(), dxl::xreg::max_position_limit);
  EXPECT_EQ(dxl::get_u32(&writes[1].params[2]),
            static_cast<std::uint32_t>(config.actuators[0].to_ticks(0.25)));
  EXPECT_EQ(writes[2].address(), dxl::xreg::min_position_limit);
  EXPECT_EQ(dxl::get_u32(&writes[2].params[2]),
            static_cast<std::uint32_t>(config.actuators[0].to_ticks(-0.5)));
  // Read back equal: the EEPROM is left alone.
  fake_.clear_log();
  bus.configure();
  EXPECT_TRUE(fake_.log_of(dxl::inst::write).empty());
}

TEST_F(DynamixelBusTest, UnpluggedLineCountsTimeoutsWithoutThrowingOrAllocating) {
  configured();
  bus_.activate();
  std::vector<double> q(3, 0.0);
  bus_.read(q);
  bus_.write(q);
  fake_.unplug();
  long allocations = 0;
  {
    test::AllocationCounter counter;
    for (int i = 0; i < 5; ++i) {
      EXPECT_NO_THROW(bus_.read(q));
      EXPECT_NO_THROW(bus_.write(q));
    }
    allocations = counter.count();
  }
  EXPECT_EQ(allocations, 0);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_GE(status(i).timeouts, 5u) << i;
    EXPECT_EQ(status(i).health, DeviceHealth::timeout) << i;
  }
  // Bringing the bus up again says why, once.
  const std::string error = error_of([&] { bus_.configure(); });
  EXPECT_NE(error.find("line is gone"), std::string::npos) << error;
}

TEST(DynamixelBus, RejectsBadBindings) {
  FakeDevices fake(three_servos());
  auto config = make_config(fake.port());
  config.actuators[1].device_id = 1;
  EXPECT_EQ(error_of([&] { DynamixelBus(config, open_serial(fake.port(), 1'000'000)); }),
            "bus legs: device id 1 (lf_knee) is used twice");
  config.actuators[1].device_id = 253;
  EXPECT_EQ(error_of([&] { DynamixelBus(config, open_serial(fake.port(), 1'000'000)); }),
            "bus legs: device id 253 (lf_knee) is outside 0..252");
}

TEST(MakeBus, BuildsADynamixelBusOnAPty) {
  FakeDevices fake(three_servos());
  auto bus = make_bus(make_config(fake.port()));
  bus->configure();
  std::vector<double> q(3, 0.0);
  bus->read(q);
  EXPECT_DOUBLE_EQ(q[1], kPi / 2);
  EXPECT_EQ(bus->devices()[1].health, DeviceHealth::ok);
}

TEST(MakeBus, UnknownProtocolIsADeviceError) {
  BusConfig config = make_config("/dev/null");
  config.protocol = "dynamixel1";
  config.where = Location{"robot.yaml", 12, 5};
  EXPECT_EQ(error_of([&] { make_bus(config); }),
            "bus legs: unknown protocol 'dynamixel1' (supported: dynamixel2, mit, cia402, maestro, "
            "modbus-tcp, modbus-rtu, feetech_sts, feetech_scs)");
}

TEST(MakeBus, MissingPortNamesTheBusAndThePort) {
  EXPECT_EQ(error_of([&] { make_bus(make_config("/dev/ttyUSB_animrt_missing")); }),
            "bus legs: cannot open serial port /dev/ttyUSB_animrt_missing: No such file or "
            "directory");
}

TEST(DeviceHealth, ToString) {
  EXPECT_STREQ(to_string(DeviceHealth::ok), "ok");
  EXPECT_STREQ(to_string(DeviceHealth::timeout), "timeout");
  EXPECT_STREQ(to_string(DeviceHealth::protocol_error), "protocol_error");
  EXPECT_STREQ(to_string(DeviceHealth::hardware_error), "hardware_error");
}

}  // namespace
}  // namespace animrt
