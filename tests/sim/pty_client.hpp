#pragma once
// A minimal Protocol 2.0 client for tests: raw termios on a pty slave, bytes
// out, status packets in (decoded with the codec). Independent of the
// runtime's transports on purpose.

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "animrt/bridge/dynamixel/protocol2.hpp"
#include "support/eventually.hpp"

namespace animrt::test {

using Bytes = std::vector<std::uint8_t>;

struct Status {
  std::uint8_t id = 0;
  std::uint8_t error = 0;
  Bytes data;
};

class PtyClient {
 public:
  // `baud` (0: leave it) is set on the line, as a host sets its adapter's.
  explicit PtyClient(const std::string& path, int baud = 0) {
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (fd_ < 0) throw std::runtime_error("cannot open " + path);
    termios tio{};
    ::tcgetattr(fd_, &tio);
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    if (baud != 0) set_speed(tio, baud);
    ::tcsetattr(fd_, TCSANOW, &tio);
    ::tcflush(fd_, TCIOFLUSH);
  }
  ~PtyClient() { ::close(fd_); }
  PtyClient(const PtyClient&) = delete;
  PtyClient& operator=(const PtyClient&) = delete;

  // Changes the line's baud, as a host does between scans.
  void set_baud(int baud) {
    termios tio{};
    ::tcgetattr(fd_, &tio);
    set_speed(tio, baud);
    ::tcsetattr(fd_, TCSANOW, &tio);
  }

  void send(const Bytes& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(fd_, bytes.data() + done, bytes.size() - done);
      if (n > 0) done += static_cast<std::size_t>(n);
    }
    bytes_sent_ += bytes.size();
  }
  // Every byte sent so far: a simulator that has read and handled as many
  // (its received_bytes) has answered all of them.
  std::uint64_t bytes_sent() const { return bytes_sent_; }

  // Raw bytes until `count` bytes arrived or `timeout` passed.
  Bytes read_raw(std::size_t count, std::chrono::milliseconds timeout = kTimeout) {
    Bytes out;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (out.size() < count) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd pfd{fd_, POLLIN, 0};
      if (::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) continue;
      std::array<std::uint8_t, 256> buf{};
      const ssize_t n = ::read(fd_, buf.data(), std::min(buf.size(), count - out.size()));
      if (n > 0) out.insert(out.end(), buf.begin(), buf.begin() + n);
    }
    return out;
  }

  // Status packets until `count` decoded or `timeout` passed.
  std::vector<Status> read_status(std::size_t count, std::chrono::milliseconds timeout = kTimeout) {
    std::vector<Status> out;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (out.size() < count) {
      dxl::Packet p;
      dxl::DecodeResult r;
      while (out.size() < count && (r = decoder_.next(p)) != dxl::DecodeResult::need_more) {
        if (r == dxl::DecodeResult::packet && p.instruction == dxl::inst::status) {
          out.push_back({p.id, p.params[0], Bytes(p.params.begin() + 1, p.params.end())});
        }
      }
      if (out.size() >= count) break;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
          deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) break;
      pollfd pfd{fd_, POLLIN, 0};
      if (::poll(&pfd, 1, static_cast<int>(left.count())) <= 0) continue;
      std::array<std::uint8_t, 512> buf{};
      const ssize_t n = ::read(fd_, buf.data(), buf.size());
      if (n > 0) decoder_.feed({buf.data(), static_cast<std::size_t>(n)});
    }
    return out;
  }

  // One instruction, one answer expected.
  Status transact(const Bytes& instruction) {
    send(instruction);
    auto answers = read_status(1);
    if (answers.empty()) throw std::runtime_error("no answer");
    return answers.front();
  }

  // Nothing arrives within `wait`.
  bool silent(std::chrono::milliseconds wait = std::chrono::milliseconds(100)) {
    return read_raw(1, wait).empty();
  }

  static constexpr std::chrono::milliseconds kTimeout{2000};

 private:
  static void set_speed(termios& tio, int baud) {
    const speed_t speed = baud == 9600        ? B9600
                          : baud == 38400     ? B38400
                          : baud == 57600     ? B57600
                          : baud == 115200    ? B115200
                          : baud == 500000    ? B500000
                          : baud == 1'000'000 ? B1000000
                          : baud == 2'000'000 ? B2000000
                          : baud == 3'000'000 ? B3000000
                          : baud == 4'000'000 ? B4000000
                                              : B0;
    if (speed == B0) throw std::invalid_argument("no termios speed for " + std::to_string(baud));
    ::cfsetispeed(&tio, speed);
    ::cfsetospeed(&tio, speed);
  }

  int fd_ = -1;
  std::uint64_t bytes_sent_ = 0;
  dxl::Decoder decoder_;
};

// Instruction builders over the codec.
inline Bytes ping(std::uint8_t id) {
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  return Bytes(buf.begin(), buf.begin() + dxl::encode_ping(id, buf));
}
inline Bytes read(std::uint8_t id, std::uint16_t address, std::uint16_t length) {
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  return Bytes(buf.begin(), buf.begin() + dxl::encode_read(id, address, length, buf));
}
inline Bytes write(std::uint8_t id, std::uint16_t address, const Bytes& data) {
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  return Bytes(buf.begin(), buf.begin() + dxl::encode_write(id, address, data, buf));
}
inline Bytes write_u32(std::uint8_t id, std::uint16_t address, std::uint32_t value) {
  Bytes data(4);
  dxl::put_u32(data.data(), value);
  return write(id, address, data);
}
inline Bytes packet(std::uint8_t id, std::uint8_t instruction, const Bytes& params) {
  std::array<std::uint8_t, dxl::kMaxPacket> buf{};
  return Bytes(buf.begin(), buf.begin() + dxl::encode_packet(id, instruction, params, buf));
}

// Whether `sim` (a simulated serial-servo bus) has read and handled every
// byte `client` sent, and so sent every answer to them, within eventually()'s
// limit: what a test waits for before a silence or a change of the line,
// however late a loaded machine runs the simulator's thread.
template <class Sim>
bool handled_all(const PtyClient& client, const Sim& sim) {
  return eventually([&] { return sim.stats().received_bytes == client.bytes_sent(); });
}

}  // namespace animrt::test
