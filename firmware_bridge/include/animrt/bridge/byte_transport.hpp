#pragma once
// A byte stream to a serial line. Real UARTs go through libserialport; a
// pseudo-terminal (which libserialport cannot open) goes through termios.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace animrt {

class LockstepLine;

class ByteTransport {
 public:
  virtual ~ByteTransport() = default;
  // Bounds write() and discard_input(); a bus sets its answer timeout here
  // when it is built. Until then one second.
  virtual void set_timeout(std::chrono::microseconds timeout) = 0;
  // Writes all bytes, waiting at most the timeout for the driver to take
  // them. False when the line stalled (nobody reads) or is gone. Never
  // throws, never allocates.
  virtual bool write(std::span<const std::uint8_t> bytes) = 0;
  // Reads what is available, waiting at most `timeout` for the first byte.
  // Returns the number of bytes read (0 on timeout, or at once when the line
  // is gone). Never throws, never allocates.
  virtual std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) = 0;
  // Drops bytes received but not yet read; stops after the timeout or
  // kMaxDiscard bytes, even if the other end keeps sending.
  virtual void discard_input() = 0;
  // nullptr while the line works; once it failed (hangup, EIO: the adapter
  // was unplugged) a fixed text saying how, and the line stays failed.
  virtual const char* failure() const = 0;
  // errno of that failure (0 when none, or none was given).
  virtual int failure_errno() const = 0;
  // Writes that did not complete (stalled or failed), since opening.
  virtual std::uint64_t write_failures() const = 0;
  virtual const std::string& port() const = 0;
  // In a lockstep run on simulated devices the transport follows the line
  // (lockstep_line.hpp): a read then waits, whatever its timeout, until
  // bytes come or the line has settled (a guard stops it on a hung device
  // side), so a read that returns nothing means the answer is missing.
  // Hardware has no such line; a transport that follows none waits its
  // timeouts.
  virtual void follow(std::shared_ptr<LockstepLine> line) { (void)line; }
  virtual bool follows_line() const { return false; }

  static constexpr std::size_t kMaxDiscard = 4096;
};

// "serial port PORT: HOW: STRERROR" for a failed transport (allocates; for
// lifecycle messages only).
std::string describe_failure(const ByteTransport& transport);

// Opens `port` at `baud` (8N1, no flow control). A pseudo-terminal
// (/dev/pts/N or a symlink to one) is opened through termios, anything else
// through libserialport. Throws DeviceError with the port and the reason.
std::unique_ptr<ByteTransport> open_serial(const std::string& port, int baud);

// False when `port` is a pseudo-terminal and `baud` is a rate termios has
// no code for: the pty would keep the rate it had, so a simulated device
// listening at that rate would answer as if this one were set.
bool carries_baud(const std::string& port, int baud);

struct BusConfig;
// open_serial for a serial-line bus (its port and baud rate); the error
// names the bus.
std::unique_ptr<ByteTransport> open_bus_serial(const BusConfig& bus);

}  // namespace animrt
