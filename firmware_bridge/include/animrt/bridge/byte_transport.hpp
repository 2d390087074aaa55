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

class ByteTransport {
 public:
  virtual ~ByteTransport() = default;
  // Writes all bytes (blocking until handed to the driver). Throws DeviceError
  // if the line is gone.
  virtual void write(std::span<const std::uint8_t> bytes) = 0;
  // Reads what is available, waiting at most `timeout` for the first byte.
  // Returns the number of bytes read (0 on timeout). Never allocates.
  virtual std::size_t read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) = 0;
  // Drops bytes received but not yet read.
  virtual void discard_input() = 0;
  virtual const std::string& port() const = 0;
};

// Opens `port` at `baud` (8N1, no flow control). A pseudo-terminal
// (/dev/pts/N or a symlink to one) is opened through termios, anything else
// through libserialport. Throws DeviceError with the port and the reason.
std::unique_ptr<ByteTransport> open_serial(const std::string& port, int baud);

struct BusConfig;
// open_serial for a serial-line bus (its port and baud rate); the error
// names the bus.
std::unique_ptr<ByteTransport> open_bus_serial(const BusConfig& bus);

}  // namespace animrt
