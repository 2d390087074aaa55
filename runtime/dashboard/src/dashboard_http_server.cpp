// The dashboards' HTTP server (see dashboard_http_server.hpp).

#include "dashboard_http_server.hpp"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <functional>
#include <string>
#include <system_error>
#include <thread>

namespace animrt {

namespace {

using HttpClock = std::chrono::steady_clock;

// Set on the accepting thread while it answers a connection beyond the
// limit itself.
thread_local bool t_http_over_capacity = false;

// poll() for `events` up to `timeout` (negative: 0); whether they came.
bool http_wait_for(int sock, short events, HttpClock::duration timeout) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count();
  pollfd p{sock, events, 0};
  for (;;) {
    const int n = ::poll(&p, 1, static_cast<int>(std::clamp<long long>(ms, 0, 60'000)));
    if (n < 0 && errno == EINTR) continue;
    return n > 0 && (p.revents & events) != 0;
  }
}

void http_address_of(int sock, bool peer, std::string& ip, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  const int got = peer ? ::getpeername(sock, reinterpret_cast<sockaddr*>(&addr), &len)
                       : ::getsockname(sock, reinterpret_cast<sockaddr*>(&addr), &len);
  if (got != 0) return;
  std::array<char, NI_MAXHOST> host{};
  std::array<char, NI_MAXSERV> serv{};
  if (::getnameinfo(reinterpret_cast<sockaddr*>(&addr), len, host.data(), host.size(), serv.data(),
                    serv.size(), NI_NUMERICHOST | NI_NUMERICSERV) == 0) {
    ip = host.data();
    port = std::atoi(serv.data());
  }
}

}  // namespace

// One thread per connection, up to the limit; shutdown() waits for all of
// them (they use the server).
class DashboardHttpServer::ConnectionThreads : public httplib::TaskQueue {
 public:
  explicit ConnectionThreads(DashboardHttpServer& server) : server_(server) {
    std::lock_guard lock(server_.mutex_);
    server_.waking_ = false;
  }

  void enqueue(std::function<void()> fn) override {
    {
      std::lock_guard lock(mutex_);
      if (active_ < kMaxConnections) {
        ++active_;
        try {
          std::thread([this, fn]() mutable {
            fn();
            fn = nullptr;
            std::lock_guard done(mutex_);
            --active_;
            ended_.notify_all();
          }).detach();
          return;
        } catch (const std::system_error&) {
          --active_;  // no thread to be had: answered as over the limit
        }
      }
    }
    // A short answer written on this thread; it does not wait for the client.
    t_http_over_capacity = true;
    fn();
    t_http_over_capacity = false;
  }

  void shutdown() override {
    server_.wake_all();
    std::unique_lock lock(mutex_);
    ended_.wait(lock, [this] { return active_ == 0; });
  }

 private:
  DashboardHttpServer& server_;
  std::mutex mutex_;
  std::condition_variable ended_;
  int active_ = 0;
};

// A connection's socket for httplib's request handling: buffered reads that
// fail once the request's deadline has passed, writes that give up after the
// write timeout.
class DashboardHttpServer::ConnectionStream : public httplib::Stream {
 public:
  ConnectionStream(int sock, HttpClock::duration read_timeout, HttpClock::duration write_timeout)
      : sock_(sock), read_timeout_(read_timeout), write_timeout_(write_timeout) {}

  void start_request() {
    deadline_ = HttpClock::now() + kRequestTimeout;
    received_ = 0;
  }
  bool buffered() const { return begin_ < end_; }
  // A read failed: too late, silent, closed or broken. httplib answers such
  // a request 400 and would wait for the next; the connection ends instead.
  bool failed() const { return failed_; }

  bool is_readable() const override {
    return buffered() || http_wait_for(sock_, POLLIN, read_wait());
  }
  bool is_writable() const override {
    pollfd p{sock_, POLLOUT, 0};
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(write_timeout_).count();
    int n;
    while ((n = ::poll(&p, 1, static_cast<int>(ms))) < 0 && errno == EINTR) {
    }
    return n > 0 && (p.revents & POLLOUT) != 0 && (p.revents & (POLLERR | POLLHUP)) == 0;
  }

  ssize_t read(char* ptr, std::size_t size) override {
    if (!buffered()) {
      // Late (the whole request is overdue), too long, or silent for the
      // read timeout.
      if (HttpClock::now() >= deadline_ || received_ > kMaxRequestBytes ||
          !http_wait_for(sock_, POLLIN, read_wait())) {
        failed_ = true;
        return -1;
      }
      ssize_t n;
      while ((n = ::recv(sock_, buffer_.data(), buffer_.size(), 0)) < 0 && errno == EINTR) {
      }
      if (n <= 0) {
        failed_ = true;
        return n;
      }
      begin_ = 0;
      end_ = static_cast<std::size_t>(n);
      received_ += end_;
    }
    const std::size_t n = std::min(size, end_ - begin_);
    std::memcpy(ptr, buffer_.data() + begin_, n);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, std::size_t size) override {
    if (!is_writable()) return -1;
    ssize_t n;
    while ((n = ::send(sock_, ptr, size, MSG_NOSIGNAL)) < 0 && errno == EINTR) {
    }
    return n;
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    http_address_of(sock_, true, ip, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    http_address_of(sock_, false, ip, port);
  }
  socket_t socket() const override { return sock_; }

 private:
  // The read timeout, cut short by the request's deadline.
  HttpClock::duration read_wait() const {
    return std::min(read_timeout_, deadline_ - HttpClock::now());
  }

  int sock_;
  HttpClock::duration read_timeout_, write_timeout_;
  HttpClock::time_point deadline_ = HttpClock::now() + kRequestTimeout;
  std::size_t received_ = 0;  // bytes of this request read from the socket
  std::array<char, 4096> buffer_{};
  std::size_t begin_ = 0, end_ = 0;
  bool failed_ = false;
};

DashboardHttpServer::DashboardHttpServer() {
  new_task_queue = [this] { return new ConnectionThreads(*this); };
  set_payload_max_length(kMaxBody);
}

int DashboardHttpServer::connections() const {
  std::lock_guard lock(mutex_);
  return static_cast<int>(open_.size());
}

bool DashboardHttpServer::track(socket_t sock) {
  std::lock_guard lock(mutex_);
  if (waking_) return false;
  open_.insert(sock);
  return true;
}

void DashboardHttpServer::untrack(socket_t sock) {
  std::lock_guard lock(mutex_);
  open_.erase(sock);
}

void DashboardHttpServer::close_listener() {
  const socket_t sock = svr_sock_.exchange(INVALID_SOCKET);
  if (sock == INVALID_SOCKET) return;
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
}

void DashboardHttpServer::wake_all() {
  std::lock_guard lock(mutex_);
  waking_ = true;
  for (const socket_t sock : open_) ::shutdown(sock, SHUT_RDWR);
}

bool DashboardHttpServer::process_and_close_socket(socket_t sock) {
  if (t_http_over_capacity) {
    const std::string body = R"({"ok":false,"error":"too many connections to the server"})";
    const std::string busy =
        "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\n"
        "Content-Length: " +
        std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body;
    // The connection is new, so its send buffer is empty: this cannot wait.
    [[maybe_unused]] const ssize_t sent =
        ::send(sock, busy.data(), busy.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  } else if (track(sock)) {
    serve(sock);
    untrack(sock);
  }
  ::shutdown(sock, SHUT_RDWR);
  ::close(sock);
  return true;
}

void DashboardHttpServer::serve(socket_t sock) {
  const auto read_timeout =
      std::chrono::seconds(read_timeout_sec_) + std::chrono::microseconds(read_timeout_usec_);
  const auto write_timeout =
      std::chrono::seconds(write_timeout_sec_) + std::chrono::microseconds(write_timeout_usec_);
  ConnectionStream stream(sock, read_timeout, write_timeout);
  // RFC 9112 6.3: without Content-Length or Transfer-Encoding, no body.
  const auto empty_body = [](httplib::Request& req) {
    if (!req.has_header("Content-Length") && !req.has_header("Transfer-Encoding")) {
      req.set_header("Content-Length", "0");
    }
  };
  for (std::size_t left = keep_alive_max_count_; left > 0; --left) {
    // An idle keep-alive connection waits this long for its next request.
    if (!stream.buffered() &&
        !http_wait_for(sock, POLLIN, std::chrono::seconds(keep_alive_timeout_sec_))) {
      return;
    }
    stream.start_request();
    bool closed = false;
    if (!process_request(stream, left == 1, closed, empty_body) || closed || stream.failed()) {
      return;
    }
  }
}

}  // namespace animrt
