#include "animrt/sim/control_socket.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "animrt/core/error.hpp"

namespace animrt::sim {
namespace {

constexpr std::size_t kMaxLine = 256;  // longer lines are refused, never buffered
constexpr int kMaxClients = 16;

std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

template <typename T>
bool number(std::string_view text, T& out) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc{} && end == text.data() + text.size();
}

SimulatedBus* find_bus(const NamedBuses& buses, std::string_view name) {
  for (const auto& [n, bus] : buses) {
    if (n == name) return bus;
  }
  return nullptr;
}

std::string control_reply(const NamedBuses& buses, std::string_view line) {
  static constexpr char kVerbs[] = "(expected hand, hand-path, get, plug or unplug)";
  const std::vector<std::string_view> w = words(line);
  if (w.empty()) return std::string("error: empty command ") + kVerbs;
  const std::string_view verb = w[0];
  const bool hand = verb == "hand";
  const bool path = verb == "hand-path";
  const bool get = verb == "get";
  const bool plug = verb == "plug" || verb == "unplug";
  if (!hand && !path && !get && !plug) {
    return "error: unknown command '" + std::string(verb) + "' " + kVerbs;
  }
  const std::size_t arity = hand ? 4 : path ? 5 : 3;
  if (path ? w.size() < arity : w.size() != arity) {
    return std::string("error: usage: ") + (hand   ? "hand BUS ID TICKS"
                                            : path ? "hand-path BUS ID READS TICKS..."
                                            : get  ? "get BUS ID"
                                                   : std::string(verb) + " BUS INDEX");
  }
  SimulatedBus* bus = find_bus(buses, w[1]);
  if (bus == nullptr) return "error: no bus '" + std::string(w[1]) + "'";
  long index = 0;
  if (!number(w[2], index) || index < 0) {
    return "error: '" + std::string(w[2]) + "' is not " + (plug ? "an index" : "an id");
  }
  if (hand || path) {
    const std::size_t first = hand ? 3 : 4;
    int reads = 1;
    if (path && (!number(w[3], reads) || reads < 1)) {
      return "error: '" + std::string(w[3]) + "' is not a count of reads (1 or more)";
    }
    std::vector<std::int32_t> ticks(w.size() - first);
    for (std::size_t k = first; k < w.size(); ++k) {
      if (!number(w[k], ticks[k - first])) {
        return "error: '" + std::string(w[k]) + "' is not a tick count";
      }
    }
    if (hand) {
      bus->hand_move(static_cast<int>(index), ticks.front());
    } else {
      bus->hand_path(static_cast<int>(index), ticks, reads);
    }
    return "ok";
  }
  if (get) {
    const SimulatedBus::ServoReadout r = bus->servo_readout(static_cast<int>(index));
    std::ostringstream out;
    out << "ok ticks=" << r.ticks << " torque=" << (r.torque ? 1 : 0) << " id=" << r.id
        << " baud=" << r.baud;
    return out.str();
  }
  bus->set_device_plugged(static_cast<std::size_t>(index), verb == "plug");
  return "ok";
}

}  // namespace

std::string control_command(const NamedBuses& buses, std::string_view line) {
  try {
    return control_reply(buses, line);
  } catch (const std::exception& e) {
    return std::string("error: ") + e.what();
  }
}

ControlSocket::ControlSocket(std::string path, NamedBuses buses)
    : path_(std::move(path)), buses_(std::move(buses)) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path_.empty() || path_.size() >= sizeof(addr.sun_path)) {
    throw DeviceError("control socket '" + path_ + "': the path must be 1.." +
                      std::to_string(sizeof(addr.sun_path) - 1) + " characters");
  }
  std::memcpy(addr.sun_path, path_.c_str(), path_.size() + 1);
  auto fail = [&](const char* what) {
    const int error = errno;
    if (listen_fd_ >= 0) ::close(listen_fd_);
    for (int fd : wake_) {
      if (fd >= 0) ::close(fd);
    }
    throw DeviceError("control socket '" + path_ + "': " + what + ": " + std::strerror(error));
  };
  listen_fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) fail("socket");
  // A socket left by a process that was killed is replaced; anything else
  // at the path is not ours to remove (bind then fails and says so).
  if (struct stat st{}; ::lstat(path_.c_str(), &st) == 0 && S_ISSOCK(st.st_mode)) {
    ::unlink(path_.c_str());
  }
  if (::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) fail("bind");
  if (::listen(listen_fd_, kMaxClients) != 0) fail("listen");
  if (::pipe2(wake_.data(), O_CLOEXEC | O_NONBLOCK) != 0) fail("pipe");
  thread_ = std::thread([this] { serve(); });
}

ControlSocket::~ControlSocket() {
  const char wake = 1;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &wake, 1);
  if (thread_.joinable()) thread_.join();
  ::close(listen_fd_);
  ::close(wake_[0]);
  ::close(wake_[1]);
  ::unlink(path_.c_str());
}

void ControlSocket::serve() {
  struct Client {
    int fd;
    std::string pending;
  };
  std::vector<Client> clients;
  std::vector<pollfd> fds;
  for (;;) {
    fds.clear();
    fds.push_back({wake_[0], POLLIN, 0});
    fds.push_back({listen_fd_, POLLIN, 0});
    for (const Client& c : clients) fds.push_back({c.fd, POLLIN, 0});
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    if (fds[0].revents != 0) break;
    if ((fds[1].revents & POLLIN) && clients.size() < static_cast<std::size_t>(kMaxClients)) {
      const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (fd >= 0) clients.push_back({fd, {}});
    }
    for (std::size_t k = 0; k + 2 < fds.size(); ++k) {
      if (fds[k + 2].revents == 0) continue;
      Client& c = clients[k];
      char buffer[512];
      const ssize_t n = ::read(c.fd, buffer, sizeof(buffer));
      if (n <= 0) {
        if (n < 0 && errno == EINTR) continue;
        ::close(c.fd);
        c.fd = -1;
        continue;
      }
      c.pending.append(buffer, static_cast<std::size_t>(n));
      std::size_t eol;
      while ((eol = c.pending.find('\n')) != std::string::npos) {
        std::string reply = control_command(buses_, std::string_view(c.pending).substr(0, eol));
        c.pending.erase(0, eol + 1);
        reply += '\n';
        // Replies are short; a client that does not read them is dropped.
        if (::send(c.fd, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT) !=
            static_cast<ssize_t>(reply.size())) {
          ::close(c.fd);
          c.fd = -1;
          break;
        }
      }
      if (c.fd >= 0 && c.pending.size() > kMaxLine) {
        static constexpr char kTooLong[] = "error: line too long\n";
        [[maybe_unused]] const ssize_t w =
            ::send(c.fd, kTooLong, sizeof(kTooLong) - 1, MSG_NOSIGNAL | MSG_DONTWAIT);
        ::close(c.fd);
        c.fd = -1;
      }
    }
    std::erase_if(clients, [](const Client& c) { return c.fd < 0; });
  }
  for (const Client& c : clients) ::close(c.fd);
}

}  // namespace animrt::sim
