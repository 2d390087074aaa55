#pragma once
// The I/O half shared by both serial paths: once a line is open (through
// termios or libserialport) it is a non-blocking file descriptor, and reading
// and writing it is the same code.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <utility>

#include "animrt/bridge/byte_transport.hpp"

namespace animrt::detail {

class FdTransport : public ByteTransport {
 public:
  void write(std::span<const std::uint8_t> bytes) override;
  std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) override;
  void discard_input() override;
  const std::string& port() const override { return port_; }

 protected:
  // `fd` must be non-blocking; the derived class owns and closes it.
  FdTransport(std::string port, int fd) : port_(std::move(port)), fd_(fd) {}
  int fd() const { return fd_; }

 private:
  [[noreturn]] void line_gone(const char* what, int error) const;

  std::string port_;
  int fd_ = -1;
};

// "cannot open serial port PORT: REASON", with a hint for the usual causes.
[[noreturn]] void throw_open_error(const std::string& port, const std::string& reason,
                                   int error = 0);

// Whether `path` (already resolved) is a pseudo-terminal slave.
bool is_pseudo_terminal(const std::string& path);

std::unique_ptr<ByteTransport> open_pty(const std::string& port, const std::string& device,
                                        int baud);
std::unique_ptr<ByteTransport> open_libserialport(const std::string& port,
                                                  const std::string& device, int baud);

}  // namespace animrt::detail
