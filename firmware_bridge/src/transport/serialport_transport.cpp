// Real UARTs through libserialport. The line is opened and configured by the
// library; I/O then goes through its file descriptor so reads can wait with
// microsecond timeouts.

#include <fcntl.h>
#include <libserialport.h>

#include <cerrno>
#include <string>

#include "fd_transport.hpp"

namespace animrt::detail {
namespace {

// Turns a failed libserialport call into the reason for the message, and
// the errno for the hint (0 when not an OS error).
std::string sp_reason(sp_return r, const char* what, int& error) {
  error = 0;
  switch (r) {
    case SP_ERR_FAIL: {
      error = sp_last_error_code();
      char* m = sp_last_error_message();
      std::string reason = std::string(what) + ": " + (m != nullptr ? m : "unknown error");
      sp_free_error_message(m);
      return reason;
    }
    case SP_ERR_ARG:
      return std::string(what) + ": invalid argument";
    case SP_ERR_MEM:
      return std::string(what) + ": out of memory";
    case SP_ERR_SUPP:
      return std::string(what) + ": not supported by this device or driver";
    default:
      return std::string(what) + ": error " + std::to_string(static_cast<int>(r));
  }
}

class SerialPortTransport final : public FdTransport {
 public:
  SerialPortTransport(std::string port, sp_port* handle, int fd)
      : FdTransport(std::move(port), fd), handle_(handle) {}
  ~SerialPortTransport() override {
    sp_close(handle_);
    sp_free_port(handle_);
  }
  SerialPortTransport(const SerialPortTransport&) = delete;
  SerialPortTransport& operator=(const SerialPortTransport&) = delete;

 private:
  sp_port* handle_;
};

}  // namespace

std::unique_ptr<ByteTransport> open_libserialport(const std::string& port,
                                                  const std::string& device, int baud) {
  sp_port* handle = nullptr;
  int error = 0;
  // libserialport answers SP_ERR_ARG for a device it has no tty entry for.
  if (sp_return r = sp_get_port_by_name(device.c_str(), &handle); r != SP_OK) {
    if (r == SP_ERR_ARG) throw_open_error(port, "not a serial port");
    throw_open_error(port, sp_reason(r, "sp_get_port_by_name", error), error);
  }
  if (sp_return r = sp_open(handle, SP_MODE_READ_WRITE); r != SP_OK) {
    std::string reason = sp_reason(r, "sp_open", error);
    sp_free_port(handle);
    if (error == ENOTTY) reason = "not a serial port (" + reason + ")";
    throw_open_error(port, reason, error);
  }
  const auto fail = [&](sp_return r, const char* what) {
    std::string reason = sp_reason(r, what, error);
    sp_close(handle);
    sp_free_port(handle);
    throw_open_error(port, reason, error);
  };
  if (sp_return r = sp_set_baudrate(handle, baud); r != SP_OK) fail(r, "set baud rate");
  if (sp_return r = sp_set_bits(handle, 8); r != SP_OK) fail(r, "set data bits");
  if (sp_return r = sp_set_parity(handle, SP_PARITY_NONE); r != SP_OK) fail(r, "set parity");
  if (sp_return r = sp_set_stopbits(handle, 1); r != SP_OK) fail(r, "set stop bits");
  if (sp_return r = sp_set_flowcontrol(handle, SP_FLOWCONTROL_NONE); r != SP_OK) {
    fail(r, "set flow control");
  }
  int fd = -1;
  if (sp_return r = sp_get_port_handle(handle, &fd); r != SP_OK) fail(r, "get port handle");
  // Our reads poll and must not block; make sure whatever the library chose.
  const int flags = fcntl(fd, F_GETFL);
  if (flags < 0 || fcntl(fd, F_SETFL, flags | O_NONBLOCK) != 0) {
    error = errno;
    sp_close(handle);
    sp_free_port(handle);
    throw_open_error(port, "cannot make the line non-blocking", error);
  }
  return std::make_unique<SerialPortTransport>(port, handle, fd);
}

}  // namespace animrt::detail
