// The plumbing the dashboards share (see dashboard_core.hpp).

#include "dashboard_core.hpp"

#include <arpa/inet.h>
#include <fmt/format.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <fstream>
#include <iterator>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

#include "animrt/core/error.hpp"
#include "animrt/runtime/dashboard.hpp"

namespace animrt {

using nlohmann::json;

std::string new_dashboard_token() {
  std::random_device device;  // /dev/urandom on Linux
  std::string token;
  for (int i = 0; i < 4; ++i) token += fmt::format("{:08x}", device());
  return token;
}

// Equal strings, in time that depends only on their lengths.
bool same_dashboard_token(const std::string& given, const std::string& token) {
  if (given.size() != token.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < token.size(); ++i) {
    diff |= static_cast<unsigned char>(given[i] ^ token[i]);
  }
  return diff == 0;
}

namespace {

bool loopback_address(const sockaddr* addr) {
  if (addr->sa_family == AF_INET) {
    const auto* v4 = reinterpret_cast<const sockaddr_in*>(addr);
    return (ntohl(v4->sin_addr.s_addr) >> 24) == 127;
  }
  if (addr->sa_family == AF_INET6) {
    const in6_addr& a = reinterpret_cast<const sockaddr_in6*>(addr)->sin6_addr;
    if (IN6_IS_ADDR_LOOPBACK(&a)) return true;
    return IN6_IS_ADDR_V4MAPPED(&a) && a.s6_addr[12] == 127;
  }
  return false;
}

bool ip_literal(const std::string& host) {
  in6_addr a{};
  return ::inet_pton(AF_INET, host.c_str(), &a) == 1 ||
         ::inet_pton(AF_INET6, host.c_str(), &a) == 1;
}

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!text.empty() && text.back() == '.') text.pop_back();  // "localhost." is localhost
  return text;
}

}  // namespace

// An IP literal is parsed, never looked up; "localhost" is resolved (from
// /etc/hosts) and every address it gives must be loopback. Any other name is
// refused even when it resolves to loopback today (127.0.0.1.nip.io does):
// its addresses come from DNS, whose owner can change them, and the
// dashboard accepts requests for the name it serves, so a page from that
// name could reach it after a rebinding.
bool is_loopback_host(const std::string& host) {
  const std::string name = lowercase(host);
  if (name != "localhost" && !ip_literal(name)) return false;
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = name == "localhost" ? 0 : AI_NUMERICHOST;
  addrinfo* found = nullptr;
  if (::getaddrinfo(name.c_str(), nullptr, &hints, &found) != 0 || found == nullptr) return false;
  bool all = true;
  for (const addrinfo* a = found; a != nullptr; a = a->ai_next)
    all = all && loopback_address(a->ai_addr);
  ::freeaddrinfo(found);
  return all;
}

bool dashboard_host_allowed(const std::string& host_header, const std::string& served_host,
                            int served_port, bool remote) {
  std::string name = host_header;
  std::string port;
  if (!name.empty() && name.front() == '[') {  // [v6]:port
    const auto close = name.find(']');
    if (close == std::string::npos) return false;
    port = name.substr(close + 1);
    name = name.substr(1, close - 1);
    if (!port.empty() && port.front() != ':') return false;
    if (!port.empty()) port.erase(0, 1);
  } else if (const auto colon = name.rfind(':'); colon != std::string::npos) {
    port = name.substr(colon + 1);
    name = name.substr(0, colon);
  }
  // Without a port the client means 80.
  if (port != (port.empty() && served_port == 80 ? "" : std::to_string(served_port))) return false;
  name = lowercase(name);
  if (name.empty()) return false;
  if (ip_literal(name) || name == "localhost" || name == lowercase(served_host)) return true;
  if (!remote) return false;
  std::array<char, 256> self{};
  if (::gethostname(self.data(), self.size() - 1) != 0) return false;
  const std::string machine = lowercase(self.data());
  return name == machine || name == machine + ".local";
}

std::pair<std::string, int> parse_host_port(const std::string& text) {
  const auto colon = text.rfind(':');
  const std::string expected =
      "expected HOST:PORT (e.g. 127.0.0.1:8080, port 0 for a free one), found " + quote(text);
  if (colon == std::string::npos || colon == 0) throw std::invalid_argument(expected);
  std::string host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  const std::string port_text = text.substr(colon + 1);
  if (port_text.empty() || port_text.size() > 5 ||
      !std::all_of(port_text.begin(), port_text.end(),
                   [](char c) { return c >= '0' && c <= '9'; })) {
    throw std::invalid_argument(expected);
  }
  const int port = std::stoi(port_text);
  if (port > 65535) throw std::invalid_argument(expected);
  return {host, port};
}

DashboardCore::DashboardCore(DashboardListen listen)
    : listen_(std::move(listen)), token_(new_dashboard_token()) {
  if (!listen_.remote && !is_loopback_host(listen_.host)) {
    throw std::invalid_argument("--dashboard " + listen_.host +
                                " is not a loopback address (127.0.0.1, [::1] or localhost); add "
                                "--dashboard-remote to serve other machines");
  }
  // A stream to a client that never reads gives up after this.
  server_.set_write_timeout(2, 0);
  // An idle keep-alive connection (a browser keeps some) holds up the
  // server's stop until it times out: 1 s, not httplib's 5 s, so the
  // program ends soon after its run.
  server_.set_keep_alive_timeout(1);
}

DashboardCore::~DashboardCore() { stop(); }

bool DashboardCore::authorized(const httplib::Request& req) const {
  const std::string header = req.get_header_value("Authorization");
  const std::string bearer = "Bearer ";
  if (header.rfind(bearer, 0) == 0)
    return same_dashboard_token(header.substr(bearer.size()), token_);
  return req.has_param("token") && same_dashboard_token(req.get_param_value("token"), token_);
}

void DashboardCore::publish(std::shared_ptr<const std::string> frame) {
  std::lock_guard lock(mutex_);
  frame_ = std::move(frame);
  ++generation_;
  changed_.notify_all();
}

std::shared_ptr<const std::string> DashboardCore::latest() const {
  std::lock_guard lock(mutex_);
  return frame_;
}

void DashboardCore::answer(httplib::Response& res, int status, const json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

void DashboardCore::error(httplib::Response& res, int status, const std::string& message) {
  answer(res, status, {{"ok", false}, {"error", message}});
}

std::optional<json> DashboardCore::object_body(const std::string& text, std::string& problem) {
  if (text.empty()) return json::object();
  // Keys seen in each object open around the parser (a key given twice
  // would otherwise be taken as its last value, silently).
  std::vector<std::set<std::string>> open;
  std::string twice;
  const json::parser_callback_t watch = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) open.emplace_back();
    if (event == json::parse_event_t::object_end && !open.empty()) open.pop_back();
    if (event == json::parse_event_t::key && !open.empty() && twice.empty() &&
        !open.back().insert(parsed.get<std::string>()).second) {
      twice = parsed.get<std::string>();
    }
    return true;
  };
  json body;
  try {
    body = json::parse(text, watch);
  } catch (const json::exception& e) {
    // A parse error or a number past a double's range, without the
    // library's "[json.exception.KIND.N] " prefix.
    const std::string what = e.what();
    const auto end = what.find("] ");
    problem = "the body is no JSON: " + (end == std::string::npos ? what : what.substr(end + 2));
    return std::nullopt;
  }
  if (!twice.empty()) {
    problem = "the key " + json(twice).dump() + " is given twice";
    return std::nullopt;
  }
  if (!body.is_object()) {
    problem = "expected a JSON object as the body";
    return std::nullopt;
  }
  return body;
}

void DashboardCore::control(const std::string& path,
                            std::function<void(const json&, httplib::Response&)> act) {
  server_.Post(path, [this, act](const httplib::Request& req, httplib::Response& res) {
    if (!authorized(req)) return error(res, 401, "a valid token is needed for controls");
    std::string problem;
    const std::optional<json> body = object_body(req.body, problem);
    if (!body) return error(res, 400, problem);
    act(*body, res);
  });
}

void DashboardCore::refuse(const std::string& path, const std::string& why) {
  server_.Post(path,
               [why](const httplib::Request&, httplib::Response& res) { error(res, 409, why); });
}

void DashboardCore::routes() {
  // No compression: on loopback it only costs CPU (brotli at its slowest
  // setting takes seconds for three.js), and the machine runs the loop.
  server_.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    // A page whose name was rebound to this machine's address reaches the
    // server with its own name as Host: refused before anything is served.
    const std::string host = req.get_header_value("Host");
    if (!dashboard_host_allowed(host, listen_.host, port_, listen_.remote)) {
      error(res, 403,
            fmt::format("Host \"{:.80}\" is not this dashboard's address (an IP address, "
                        "localhost{} with port {})",
                        host, listen_.remote ? ", this machine's name" : "", port_));
      return httplib::Server::HandlerResponse::Handled;
    }
    // The request object itself is not const; httplib passes it so.
    const_cast<httplib::Request&>(req).headers.erase("Accept-Encoding");
    return httplib::Server::HandlerResponse::Unhandled;
  });
  server_.Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
    const auto frame = latest();
    res.set_content(state_from_ ? state_from_(*frame) : *frame, "application/json");
  });
  route_stream();
  route_files();
}

// Server-sent events: each new frame to every open stream.
void DashboardCore::route_stream() {
  server_.Get("/api/stream", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-cache");
    auto seen = std::make_shared<std::uint64_t>(0);
    {
      std::lock_guard lock(mutex_);
      if (streams_ >= kMaxStreams) {
        return error(
            res, 503,
            fmt::format("too many open streams ({}); close one or read /api/state", kMaxStreams));
      }
      ++streams_;
    }
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, seen](std::size_t, httplib::DataSink& sink) {
          std::shared_ptr<const std::string> frame;
          {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] { return quit_ || generation_ != *seen; });
            if (generation_ == *seen) {
              sink.done();  // the last chunk: the client sees a complete stream
              return true;
            }
            *seen = generation_;
            frame = frame_;
          }
          const std::string event = "data: " + *frame + "\n\n";
          // A client that does not read makes this fail after the write
          // timeout; only this connection's thread waits for it.
          return sink.write(event.data(), event.size());
        },
        [this](bool) {
          {
            std::lock_guard lock(mutex_);
            --streams_;
          }
          changed_.notify_all();
        });
  });
}

void DashboardCore::route_files() {
  // The page, and Debian's three.js and Chart.js.
  // Browsers load ES modules only with a JavaScript type.
  server_.set_file_extension_and_mimetype_mapping("js", "text/javascript");
  server_.set_file_extension_and_mimetype_mapping("mjs", "text/javascript");
  if (!listen_.www_dir.empty()) server_.set_mount_point("/", listen_.www_dir);
  const std::string three = listen_.lib_dir + "/three";
  const std::string chart = listen_.lib_dir + "/chart.js";
  server_.set_mount_point("/lib/three", three);
  server_.set_mount_point("/lib/chart.js", chart);
  const auto file = [](const std::string& path) {
    return [path](const httplib::Request&, httplib::Response& res) {
      std::ifstream in(path, std::ios::binary);
      if (!in) return error(res, 404, path + " is not installed");
      res.set_content(std::string(std::istreambuf_iterator<char>(in), {}), "text/javascript");
    };
  };
  server_.Get("/lib/three.module.js", file(three + "/three.module.js"));
  server_.Get("/lib/chart.umd.js", file(chart + "/chart.min.js"));
}

void DashboardCore::start() {
  routes();
  if (listen_.port == 0) {
    port_ = server_.bind_to_any_port(listen_.host);
  } else {
    port_ = server_.bind_to_port(listen_.host, listen_.port) ? listen_.port : -1;
  }
  if (port_ <= 0) {
    throw std::runtime_error(
        fmt::format("dashboard: cannot listen on {}:{}", listen_.host, listen_.port));
  }
  listener_ = std::thread([this] { server_.listen_after_bind(); });
}

std::string DashboardCore::url() const {
  const std::string& host = listen_.host;
  const bool v6 = host.find(':') != std::string::npos;
  return fmt::format("http://{}:{}/?token={}", v6 ? "[" + host + "]" : host, port_, token_);
}

void DashboardCore::stop() {
  {
    std::unique_lock lock(mutex_);
    if (stopped_) return;
    stopped_ = true;
    quit_ = true;
    changed_.notify_all();
    // Open streams end with their last chunk before the server closes; a
    // client that does not read is not waited for long.
    changed_.wait_for(lock, std::chrono::seconds(1), [this] { return streams_ == 0; });
  }
  server_.close_listener();
  if (listener_.joinable()) listener_.join();
}

}  // namespace animrt
