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
  void set_timeout(std::chrono::microseconds timeout) override { timeout_ = timeout; }
  bool write(std::span<const std::uint8_t> bytes) override;
  std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) override;
  void discard_input() override;
  const char* failure() const override { return failure_; }
  int failure_errno() const override { return failure_errno_; }
  std::uint64_t write_failures() const override { return write_failures_; }
  const std::string& port() const override { return port_; }
  void follow(std::shared_ptr<LockstepLine> line) override { line_ = std::move(line); }
  bool follows_line() const override { return line_ != nullptr; }

 protected:
  // `fd` must be non-blocking; the derived class owns and closes it.
  FdTransport(std::string port, int fd) : port_(std::move(port)), fd_(fd) {}
  int fd() const { return fd_; }

 private:
  // Marks the line failed (first reason kept); no allocation.
  void line_gone(const char* how, int error);
  // Reads queued bytes away until the lockstep line's device side has
  // nothing unread, or the deadline.
  void discard_lockstep(std::int64_t deadline_ns);
  bool write_all(std::span<const std::uint8_t> bytes, std::size_t& done);
  // `n` bytes read (> 0): counted on the lockstep line; returns n.
  std::size_t took(long n);

  std::string port_;
  int fd_ = -1;
  std::chrono::microseconds timeout_{1'000'000};
  const char* failure_ = nullptr;
  int failure_errno_ = 0;
  std::uint64_t write_failures_ = 0;
  std::shared_ptr<LockstepLine> line_;  // lockstep runs on simulated devices only
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
